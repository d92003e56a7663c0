"""The 3D design study on the Dask runner (real LocalClusters, real subprocesses): a tiny
study runs and resumes; a study killed mid-way keeps whole points and, resumed, ends with
the rows of an uninterrupted study; the 3D table refuses what it cannot trust."""

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from eyeviz import EyevizError
from eyeviz.study import run_study
from eyeviz.study.grid import design_grid3d
from eyeviz.study.point import COLUMNS3D, STUDY3D_VERSION, evaluate3d
from eyeviz.study.table import StudyTable3D, read_rows3d

ROOT = Path(__file__).resolve().parents[2]
pytest.importorskip("distributed")


def rows_without_seconds(path):
    rows, _ = read_rows3d(path)
    return sorted(
        tuple((k, v) for k, v in r.items() if k not in ("seconds", "_line")) for r in rows
    )


@pytest.mark.slow
def test_a_tiny_3d_study_runs_and_resumes_skipping_finished_points(tmp_path):
    path = tmp_path / "s3.csv"
    first = design_grid3d("20,40", "10", "8,16", n=150, seed=2)
    s1 = run_study(path, first, workers=1, progress=False)
    assert (s1.computed, s1.skipped, s1.failures) == (4, 0, ())
    assert StudyTable3D.open(path).finished == {p.key for p in first}
    lines = path.read_text().splitlines()
    assert lines[0].startswith("version,h,l,nside,")
    assert len(lines) == 1 + 4 * 15  # all, 8 distance bins, 6 elevation bins per point
    more = design_grid3d("20,40", "10", "8,16,32", n=150, seed=2)
    s2 = run_study(path, more, workers=1, progress=False)
    assert (s2.computed, s2.skipped, s2.points) == (2, 4, 6)
    assert path.read_text().splitlines()[: len(lines)] == lines  # finished rows untouched
    # another estimator is another point in the same table (the key holds it)
    assert design_grid3d("20", "10", "8", n=150, seed=2, estimator="learned3d")[0].key not in (
        StudyTable3D.open(path).finished
    )


def test_planar_and_3d_points_and_tables_do_not_mix(tmp_path):
    from eyeviz.study.grid import design_grid

    path = tmp_path / "s3.csv"
    run_study(path, design_grid3d("20", "10", "8", n=50), workers=1, progress=False)
    before = path.read_bytes()
    with pytest.raises(EyevizError, match="a 3D study table") as err:
        run_study(path, design_grid("20", "10", "8", n=50), workers=1, progress=False)
    assert "\n" not in str(err.value)
    mixed = [*design_grid("20", "10", "8", n=50), *design_grid3d("20", "10", "8", n=50)]
    with pytest.raises(EyevizError, match="all planar .* or all 3D"):
        run_study(tmp_path / "x.csv", mixed, workers=1, progress=False)
    assert path.read_bytes() == before
    planar = tmp_path / "p.csv"
    run_study(planar, design_grid("20", "10", "8", n=50), workers=1, progress=False)
    with pytest.raises(EyevizError, match="not a 3D study table"):
        run_study(planar, design_grid3d("20", "10", "8", n=50), workers=1, progress=False)


@pytest.fixture(scope="module")
def table_lines(tmp_path_factory) -> tuple[str, ...]:
    """The lines of a whole 3D table of two points, computed once per module (per pytest
    worker): each test below edits a copy of them in its own file."""
    path = tmp_path_factory.mktemp("table3d") / "s3.csv"
    run_study(path, design_grid3d("20", "10", "8,16", n=60), workers=1, progress=False)
    return tuple(path.read_text().splitlines())


@pytest.mark.parametrize(
    ("edit", "words"),
    [
        (lambda ls: ls[:-1], ["has 14 of its 15 rows", "incomplete"]),
        (lambda ls: [ls[0].replace("version", "versio")] + ls[1:], ["not a 3D study table"]),
        (
            lambda ls: ls[:1] + [f"{STUDY3D_VERSION + 1}" + ls[1][1:]] + ls[2:],
            ["line 2", f"3D study version {STUDY3D_VERSION + 1}"],
        ),
        (lambda ls: ls[:2] + [ls[2].replace(",single,", ",sngle,")] + ls[3:], ["line 3", "prior"]),
        (
            lambda ls: ls[:2] + [ls[2] + ",1"] + ls[3:],
            ["line 3", f"{len(COLUMNS3D) + 1} fields, expected {len(COLUMNS3D)}"],
        ),
        (
            lambda ls: ls[:2] + [ls[2].replace(",64,", ",65,", 1)] + ls[3:],
            ["line 3", "m = 65 is not 4 nside = 64"],
        ),
        (lambda ls: ls + [ls[1]], ["line 32", "bin all of this design point appears twice"]),
    ],
)
def test_a_bad_3d_table_is_refused_naming_the_line_and_left_as_it_is(
    tmp_path, table_lines, edit, words
):
    path = tmp_path / "s3.csv"
    path.write_text("\n".join(edit(list(table_lines))) + "\n")
    before = path.read_bytes()
    with pytest.raises(EyevizError) as err:
        run_study(path, design_grid3d("20", "10", "8", n=60), workers=1, progress=False)
    msg = str(err.value)
    assert "\n" not in msg
    for w in words:
        assert w in msg, msg
    assert path.read_bytes() == before


def _start(path, extra=()):
    args = ["-o", path, "--h", "20,40,80", "--l", "10", "--nside", "32,64", "--n", "6000"]
    args += ["--seed", "4", *extra]
    proc = subprocess.Popen(
        [sys.executable, "-m", "eyeviz", "study", *map(str, args), "--workers", "1"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        cwd=ROOT,
        start_new_session=True,
    )
    return proc, args


@pytest.mark.slow
def test_a_3d_study_killed_mid_way_resumes_to_the_rows_of_an_uninterrupted_one(
    tmp_path, eyeviz_main
):
    path = tmp_path / "killed.csv"
    proc, args = _start(path)
    try:
        deadline = time.monotonic() + 240
        while time.monotonic() < deadline:
            if path.exists() and len(StudyTable3D.open(path).keys) >= 1:
                break
            assert proc.poll() is None, proc.communicate()
            time.sleep(0.05)
        else:
            raise AssertionError("the study never wrote a point")
        os.killpg(proc.pid, signal.SIGKILL)  # a crash: no clean-up at all
        proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
    kept = StudyTable3D.open(path).keys  # whole points only
    assert 1 <= len(kept) < 6, "the study finished before the kill: the test proved nothing"
    lines_before = path.read_text().splitlines()
    # the resume in this process (its rows are the point, the kill went to the other), on
    # one local worker (the default, one per CPU, started a nanny and a worker more)
    out = eyeviz_main("study", *args, "--workers", "1", "--no-progress")
    assert out.returncode == 0, out.stderr
    assert f"{6 - len(kept)} point(s) computed, {len(kept)} skipped" in out.stdout
    assert path.read_text().splitlines()[: len(lines_before)] == lines_before
    # the uninterrupted study's rows: each point evaluated here, in order, and appended to a
    # table of its own (what a worker computes and the runner writes, without a cluster)
    whole = StudyTable3D.open(tmp_path / "whole.csv")
    for p in design_grid3d("20,40,80", "10", "32,64", n=6000, seed=4):
        whole.append(evaluate3d(p))
    assert rows_without_seconds(path) == rows_without_seconds(tmp_path / "whole.csv")


def test_the_3d_command_line_refuses_mixed_options_in_one_line(tmp_path):
    for extra, words in (
        (["--nside", "16", "--m", "64"], "--m is the planar study's, --nside the 3D study's"),
        (["--el-max", "0.3"], "--el-max and --estimator belong to the 3D study"),
        (["--nside", "16", "--el-max", "2"], "el_max"),
    ):
        out = subprocess.run(
            [sys.executable, "-m", "eyeviz", "study", "-o", str(tmp_path / "s.csv"), *extra],
            capture_output=True,
            text=True,
            cwd=ROOT,
            timeout=120,
        )
        assert out.returncode == 2, out.stderr
        lines = out.stderr.strip().splitlines()
        assert len(lines) == 1 and words in lines[0], out.stderr
    assert os.listdir(tmp_path) == []


def test_a_point_that_would_pass_the_readers_bound_is_refused_before_writing(tmp_path, monkeypatch):
    from eyeviz.study import table

    path = tmp_path / "s3.csv"
    pts = design_grid3d("20", "10", "8,16", n=40)
    StudyTable3D.open(path).append(evaluate3d(pts[0]))
    before = path.read_bytes()
    monkeypatch.setattr(table, "MAX_STUDY_BYTES", len(before) + 100)  # the tables' one bound
    t = StudyTable3D.open(path)
    with pytest.raises(EyevizError, match="past .* bytes, the most its reader accepts") as err:
        t.append(evaluate3d(pts[1]))
    assert "\n" not in str(err.value)
    assert path.read_bytes() == before
    assert StudyTable3D.open(path).finished == {pts[0].key}
