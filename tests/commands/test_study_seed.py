"""`eyeviz study` seeds (issue 25): a new study draws a fresh seed and prints it (every row
carries it); a resume without --seed takes the table's; a given --seed is used as is."""

import re

import pytest

from eyeviz.study.table import StudyTable

pytest.importorskip("distributed")
ONE = ["--h", "20", "--l", "10", "--m", "8", "--n", "200", "--workers", "1", "--no-progress"]


@pytest.fixture
def study(eyeviz_main):
    """``eyeviz study ARGS`` in this process (its seeds and rows are the point, not its
    process; the study's worker processes are real): its stdout."""

    def run(*args):
        out = eyeviz_main("study", *args)
        assert out.returncode == 0, out.stderr
        return out.stdout

    return run


def seeds(path) -> set[int]:
    return {int(k[-1]) for k in StudyTable.open(path).keys}


@pytest.mark.slow
def test_new_study_draws_a_seed_and_a_resume_keeps_it(tmp_path, study):
    a, b = tmp_path / "a.csv", tmp_path / "b.csv"
    out_a = study("-o", a, *ONE)
    drawn = re.search(r"seed (\d+) \(drawn afresh; --seed \1 repeats", out_a)
    assert drawn, out_a
    seed_a = int(drawn.group(1))
    assert seeds(a) == {seed_a}
    out_b = study("-o", b, *ONE)
    seed_b = int(re.search(r"seed (\d+) \(drawn afresh", out_b).group(1))
    assert seed_b != seed_a and seeds(b) == {seed_b}  # two studies, two test sets
    # a resume (one more m) takes the table's seed: the finished point is skipped
    again = study("-o", a, *ONE[:5], "8,16", *ONE[6:])
    assert f"seed {seed_a} (the table's" in again, again
    assert "1 point(s) computed, 1 skipped" in again, again
    assert seeds(a) == {seed_a}


def test_a_given_seed_is_used(tmp_path, study):
    path = tmp_path / "s.csv"
    out = study("-o", path, *ONE, "--seed", "7")
    assert "drawn afresh" not in out and seeds(path) == {7}
