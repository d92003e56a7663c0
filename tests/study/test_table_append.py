"""Issue 25 items 4 and 7: the study table is appended in place (never rewritten, no
lines held in memory), a point that would take it past the bound its reader accepts is
refused before anything is written (for both kinds of table:
test_table3d_append.py), and the runner and the report read it through one parser that
refuses every edit the report used to choke on, naming file and line."""

import math
import os

import pytest

from eyeviz import EyevizError
from eyeviz.reports.study_table import read_study
from eyeviz.study import table as table_mod
from eyeviz.study.point import COLUMNS, DesignPoint, evaluate
from eyeviz.study.table import StudyTable, format_row

P1 = DesignPoint(h=40, l=20, m=180, n=200, seed=1)
P2 = DesignPoint(h=20, l=10, m=360, n=200, seed=2)
P3 = DesignPoint(h=30, l=10, m=360, n=200, seed=3)


@pytest.fixture(scope="module")
def rows():
    return {p.key: evaluate(p) for p in (P1, P2, P3)}


def test_appends_keep_the_file_and_write_only_the_new_point(tmp_path, rows, monkeypatch):
    path = tmp_path / "s.csv"
    t = StudyTable.open(path)
    t.append(rows[P1.key])
    ino, first = os.stat(path).st_ino, path.read_bytes()

    def no_rewrite(*_a, **_k):
        raise AssertionError("the table was rewritten")

    monkeypatch.setattr(table_mod, "atomic_output", no_rewrite)
    t.append(rows[P2.key])
    t = StudyTable.open(path)
    t.append(rows[P3.key])
    data = path.read_bytes()
    assert os.stat(path).st_ino == ino and data.startswith(first)
    assert StudyTable.open(path).finished == {P1.key, P2.key, P3.key}
    assert not hasattr(t, "lines")  # keys and a size: memory does not grow with the file
    assert t.size == len(data)


@pytest.mark.parametrize(
    ("line", "column", "value", "words"),
    [
        (3, "gamma", "0.5", "gamma = 0.5 is not 2 pi / m"),
        (4, "count", "999999", "count 999999 exceeds n = 200"),
        (5, "dd_mape", "-1.5", "column dd_mape: must be >= 0"),
        (5, "ad_mape", "inf", "column ad_mape: must be >= 0 and finite"),
        (6, "r_lo", "-1e308", "r_lo = -1e+308 is not bin"),
        (6, "r_hi", "1e308", "r_hi = 1e+308 is not bin"),
        (2, "r_lo", "0", "r_lo = 0 is not bin all"),
        (2, "version", "\u0661", "version must be an integer"),
        (3, "m", "1_80", "m must be an integer"),
        (3, "h", "4\uff10", "h must be a number"),
        (4, "flagged", "201", "flagged 201 exceeds count"),
        (4, "dd_mape", "1e308", "column dd_mape: 1e+308 is no error a study measures"),
        (4, "ad_r2", "-1e308", "ad_r2: must be within [-1e+30, 1]"),
        (4, "dd_r2", "2.5", "dd_r2: must be within [-1e+30, 1]"),
        (4, "seconds", "nan", "seconds: must be >= 0 and finite"),
    ],
)
def test_runner_and_report_refuse_the_same_edit_naming_file_and_line(
    tmp_path, rows, edit_field, line, column, value, words
):
    path = tmp_path / "s.csv"
    StudyTable.open(path).append(rows[P1.key])
    edit_field(path, line, COLUMNS, column, value)
    before = path.read_bytes()
    msgs = []
    for read in (StudyTable.open, read_study):
        with pytest.raises(EyevizError) as err:
            read(path)
        msgs.append(str(err.value))
    for msg in msgs:
        assert "\n" not in msg and str(path) in msg and f"line {line}:" in msg, msg
        assert words in msg, msg
    assert msgs[0] == msgs[1]  # one parser
    assert path.read_bytes() == before


def test_a_point_the_reader_would_refuse_is_never_written(tmp_path, rows):
    path = tmp_path / "s.csv"
    t = StudyTable.open(path)
    t.append(rows[P1.key])
    before = path.read_bytes()
    bad = [dict(r) for r in rows[P2.key]]
    bad[0]["r_hi"] = 1e308
    with pytest.raises(EyevizError, match="row for bin all: r_hi"):
        t.append(bad)
    bad = [dict(r) for r in rows[P2.key]]
    bad[2]["gamma"] = math.pi
    with pytest.raises(EyevizError, match="gamma"):
        t.append(bad)
    assert path.read_bytes() == before
    t.append(rows[P2.key])
    assert StudyTable.open(path).finished == {P1.key, P2.key}


def test_formatted_rows_are_ascii(rows):
    for r in rows[P1.key]:
        assert format_row(r).isascii()


def test_a_lone_carriage_return_is_one_line_naming_it(tmp_path, rows):
    """Found by the second fuzz campaign: csv's own error escaped as a traceback."""
    path = tmp_path / "s.csv"
    StudyTable.open(path).append(rows[P1.key])
    lines = path.read_bytes().split(b"\n")
    lines[1] = b"\r" + lines[1][1:]
    path.write_bytes(b"\n".join(lines))
    for read in (StudyTable.open, read_study):
        with pytest.raises(EyevizError, match=r"line 2: not a CSV line"):
            read(path)


def test_a_study_stops_before_its_table_passes_the_bound(tmp_path, monkeypatch):
    """The runner appends through the same check: the study ends in one line, the table
    keeps the points that fit and still reads back."""
    from eyeviz.study import design_grid, run_study

    path = tmp_path / "s.csv"
    points = design_grid("20", "10", "8,16", n=100)
    run_study(path, points[:1], workers=1, progress=False)
    size = path.stat().st_size
    monkeypatch.setattr(table_mod, "MAX_STUDY_BYTES", size + 200)
    with pytest.raises(EyevizError) as err:
        run_study(path, points, workers=1, progress=False)
    msg = str(err.value)
    assert "\n" not in msg and "the most its reader accepts" in msg and str(path) in msg
    assert path.stat().st_size == size
    assert StudyTable.open(path).finished == {points[0].key}


@pytest.mark.parametrize("cut", ["last row", "header only"])
def test_a_table_without_its_final_newline_takes_the_next_point_on_a_line_of_its_own(
    tmp_path, rows, cut
):
    """An editor's save can drop the final newline; the reader takes such a table, so
    the next point's lines must not go on at the end of its last line (they did: the
    resumed table had a line of 41 fields, refused by its own reader)."""
    path = tmp_path / "s.csv"
    StudyTable.open(path).append(rows[P1.key])
    if cut == "header only":
        path.write_bytes(StudyTable.fmt.header)
    path.write_bytes(path.read_bytes()[:-1])
    before = path.read_bytes()
    t = StudyTable.open(path)
    t.append(rows[P2.key])
    data = path.read_bytes()
    assert data.startswith(before) and data.endswith(b"\n") and t.size == len(data)
    want = {P2.key} if cut == "header only" else {P1.key, P2.key}
    assert StudyTable.open(path).finished == want
    assert len(read_study(path)) == len(want) * len(rows[P2.key])
