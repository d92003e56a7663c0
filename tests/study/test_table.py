"""The study table: pandas reads it, the reader names the first bad line, a foreign file is
refused untouched, and an append interrupted at any moment leaves only whole points."""

import math
import os

import pandas as pd
import pytest

from eyeviz import EyevizError
from eyeviz.study import table as table_mod
from eyeviz.study.point import COLUMNS, STUDY_VERSION, DesignPoint, evaluate
from eyeviz.study.table import StudyTable, format_row, read_rows

P1 = DesignPoint(h=40, l=20, m=180, n=300, seed=1)
P2 = DesignPoint(h=20, l=10, m=360, n=300, seed=2)


@pytest.fixture(scope="module")
def rows():
    return {P1.key: evaluate(P1), P2.key: evaluate(P2)}


def write(path, rows_by_key):
    t = StudyTable.open(path)
    for r in rows_by_key.values():
        t.append(r)
    return t


def test_round_trip_and_pandas(tmp_path, rows):
    path = tmp_path / "study.csv"
    write(path, rows)
    back, lines = read_rows(path)
    assert len(back) == len(lines) == 18  # 2 points x ("all" + 8 bins of 500 in [1000, 5000])
    expected = rows[P1.key] + rows[P2.key]
    for got, want in zip(back, expected, strict=True):
        for c in COLUMNS:
            w = want[c]
            assert got[c] == w or (isinstance(w, float) and math.isnan(w) and math.isnan(got[c]))
    assert StudyTable.open(path).finished == {P1.key, P2.key}
    assert P1 in StudyTable.open(path)

    df = pd.read_csv(path)
    assert tuple(df.columns) == COLUMNS
    assert len(df) == 18
    assert (df["version"] == STUDY_VERSION).all()
    assert df["m"].dtype.kind == "i" and df["dd_mape"].dtype.kind == "f"
    allrows = df[df["bin"] == "all"]
    assert sorted(allrows["m"]) == [180, 360]
    assert (allrows["count"] == 300).all()
    per_bin = df[df["bin"] != "all"].groupby(["h", "m"])["count"].sum()
    assert (per_bin == 300).all()  # the bins partition the test set
    assert allrows["dd_mape"].between(0, 100).all()


def test_nan_round_trips_and_inf_is_never_written(tmp_path, rows):
    r = [dict(x) for x in rows[P1.key]]
    r[3]["dd_r2"] = math.nan
    path = tmp_path / "s.csv"
    StudyTable.open(path).append(r)
    back, _ = read_rows(path)
    assert math.isnan(back[3]["dd_r2"])
    df = pd.read_csv(path)
    assert math.isnan(df["dd_r2"][3])
    # an infinite MAPE is refused by the reader, so the writer refuses it first (issue 25)
    r = [dict(x) for x in rows[P2.key]]
    r[4]["ad_mape"] = math.inf
    before = path.read_bytes()
    with pytest.raises(EyevizError, match=r"row for bin 3: column ad_mape: must be >= 0"):
        StudyTable.open(path).append(r)
    assert path.read_bytes() == before


def test_a_table_written_back_by_pandas_reads_the_same(tmp_path, rows):
    r = [dict(x) for x in rows[P1.key]]
    r[2]["dd_r2"] = math.nan
    path = tmp_path / "s.csv"
    StudyTable.open(path).append(r)
    back = tmp_path / "back.csv"
    pd.read_csv(path).to_csv(back, index=False)  # NaN becomes an empty field
    assert ",," in back.read_text()
    a, _ = read_rows(path)
    b, _ = read_rows(back)
    assert [x["_key"] for x in a] == [x["_key"] for x in b]
    assert math.isnan(b[2]["dd_r2"])
    assert [x["dd_mape"] for x in a] == [x["dd_mape"] for x in b]


def test_empty_file_is_an_empty_study(tmp_path):
    path = tmp_path / "s.csv"
    path.write_bytes(b"")
    assert StudyTable.open(path).finished == set()


@pytest.mark.parametrize(
    ("header", "words"),
    [
        (["version", *COLUMNS[1:-1]], ["another version", "left as it is"]),
        ([*COLUMNS, "extra"], ["another version"]),
        (["a", "b"], ["not a study table"]),
    ],
)
def test_another_header_is_refused_and_the_file_kept(tmp_path, rows, header, words):
    path = tmp_path / "s.csv"
    body = ",".join(header) + "\n" + format_row(rows[P1.key][0]) + "\n"
    path.write_text(body)
    before = path.read_bytes()
    for call in (lambda: StudyTable.open(path), lambda: read_rows(path)):
        with pytest.raises(EyevizError) as err:
            call()
        msg = str(err.value)
        assert "\n" not in msg and str(path) in msg
        for w in words:
            assert w in msg
    assert path.read_bytes() == before


def test_another_version_column_is_refused(tmp_path, rows):
    path = tmp_path / "s.csv"
    write(path, {P1.key: rows[P1.key]})
    text = path.read_text().splitlines()
    text[2] = "2" + text[2][1:]  # one row claims version 2
    path.write_text("\n".join(text) + "\n")
    before = path.read_bytes()
    with pytest.raises(EyevizError, match=r"line 3: written by study version 2, this is "):
        StudyTable.open(path)
    assert path.read_bytes() == before


def test_run_study_refuses_a_foreign_file_before_any_work(tmp_path):
    from eyeviz.study import run_study

    path = tmp_path / "s.csv"
    path.write_text("x,y\n1,2\n")
    with pytest.raises(EyevizError, match="not a study table"):
        run_study(path, [P1], workers=1, progress=False)
    assert path.read_text() == "x,y\n1,2\n"


def _table_lines(rows):
    return [",".join(COLUMNS)] + [format_row(r) for r in rows]


@pytest.mark.parametrize(
    ("edit", "words"),
    [
        (lambda ls: ls.__setitem__(3, ls[3] + ",1"), ["line 4", "22 fields, expected 21"]),
        (lambda ls: ls.__setitem__(2, ls[2].replace(",single,", ",x,")), ["line 3", "prior"]),
        (lambda ls: ls.__setitem__(5, "1,abc" + ls[5][ls[5].index(",", 2) :]), ["line 6", "h"]),
        (lambda ls: ls.__setitem__(2, ls[2].replace(",180,", ",181,")), ["line 3", "m"]),
        (lambda ls: ls.__delitem__(4), ["line 2", "8 of its 9 rows", "incomplete"]),
        (lambda ls: ls.__setitem__(4, ls[3]), ["line 5", "appears twice"]),
        (lambda ls: ls.__setitem__(4, ls[4] + "x" * 5000), ["line 5", "longer than"]),
        (lambda ls: ls.__setitem__(6, ls[6][:40]), ["line 7", "fields"]),
        (
            lambda ls: ls.__setitem__(6, ls[6].replace(",single,300,1,", ",single,-300,1,")),
            ["line 7", "n"],
        ),
        (lambda ls: ls.__setitem__(1, ls[1].replace(",all,", ",zz,")), ["line 2", "bin"]),
    ],
)
def test_the_reader_names_the_first_bad_line(tmp_path, rows, edit, words):
    lines = _table_lines(rows[P1.key])
    edit(lines)
    path = tmp_path / "s.csv"
    path.write_text("\n".join(lines) + "\n")
    with pytest.raises(EyevizError) as err:
        read_rows(path)
    msg = str(err.value)
    assert "\n" not in msg and str(path) in msg
    for w in words:
        assert w in msg, msg


def test_the_reader_bounds_what_the_file_controls(tmp_path, rows):
    path = tmp_path / "s.csv"
    write(path, {P1.key: rows[P1.key]})
    with pytest.raises(EyevizError, match="bytes, more than 100"):
        read_rows(path, max_bytes=100)
    bad = tmp_path / "b.csv"
    bad.write_bytes(b"\xff\xfe" + path.read_bytes())
    with pytest.raises(EyevizError, match="not UTF-8"):
        read_rows(bad)
    with pytest.raises(EyevizError, match="not a regular file"):
        StudyTable.open(tmp_path)
    with pytest.raises(EyevizError, match="output directory does not exist"):
        StudyTable.open(tmp_path / "nope" / "s.csv")


def test_far_ranges_in_a_file_allocate_nothing(tmp_path, rows):
    lines = _table_lines(rows[P1.key])
    lines[1] = lines[1].replace(",5000.0,500.0,", ",1e300,500.0,", 1)
    path = tmp_path / "s.csv"
    path.write_text("\n".join(lines) + "\n")
    with pytest.raises(EyevizError, match="line 2: r_max - r_min gives more than"):
        read_rows(path)


@pytest.mark.parametrize("when", ["fsync", "write", "replace"])
def test_an_append_interrupted_at_any_moment_keeps_whole_points(tmp_path, rows, when, monkeypatch):
    path = tmp_path / "s.csv"
    t = write(path, {P1.key: rows[P1.key]})
    before = path.read_bytes()

    def boom(*_a, **_k):
        raise KeyboardInterrupt

    if when == "fsync":
        monkeypatch.setattr(table_mod.os, "fsync", boom)
    elif when == "replace":  # appends no longer rename: half the point written, then stopped
        real_write = table_mod.os.write

        def half_then_boom(fd, data):
            real_write(fd, bytes(data[: len(data) // 2]))
            raise KeyboardInterrupt

        monkeypatch.setattr(table_mod.os, "write", half_then_boom)
    else:  # the third row of the new point is being written
        real = table_mod.format_row
        calls = []

        def format_then_boom(row, *columns):
            calls.append(row)
            if len(calls) == 3:
                raise KeyboardInterrupt
            return real(row, *columns)

        monkeypatch.setattr(table_mod, "format_row", format_then_boom)
    with pytest.raises(KeyboardInterrupt):
        t.append(rows[P2.key])
    monkeypatch.undo()
    assert path.read_bytes() == before
    assert sorted(os.listdir(tmp_path)) == ["s.csv"]  # no temporary file left
    assert StudyTable.open(path).finished == {P1.key}
    # the table object is still usable: the point goes in on the next try
    t.append(rows[P2.key])
    assert StudyTable.open(path).finished == {P1.key, P2.key}


def test_append_refuses_a_point_twice(tmp_path, rows):
    t = write(tmp_path / "s.csv", {P1.key: rows[P1.key]})
    with pytest.raises(EyevizError, match="already in"):
        t.append(rows[P1.key])
