"""The 3D study table has the planar table's guarantees (issue 25 for issue 23's table):
it is appended in place (the inode and every byte before the append kept; an append
interrupted or out of disk is cut back), it is read by the planar table's streaming
parser core (the runner's resume and the report refuse the same hostile edit with the
same one line naming file and line), a point that would take it past its reader's bound
stops the study in one line leaving the file as it was, and a symlinked output is written
through while a hard link to a table under study is refused."""

import errno
import os

import pytest

from eyeviz import EyevizError
from eyeviz.study import run_study
from eyeviz.study import table as table_mod
from eyeviz.study.grid import design_grid3d
from eyeviz.study.point import COLUMNS3D, DesignPoint, DesignPoint3D, evaluate, evaluate3d
from eyeviz.study.table import StudyTable, StudyTable3D, read_rows3d

P1 = DesignPoint3D(h=20, l=10, nside=8, n=60, seed=1)
P2 = DesignPoint3D(h=40, l=10, nside=8, n=60, seed=2)
P3 = DesignPoint3D(h=20, l=10, nside=16, n=60, seed=3)


@pytest.fixture(scope="module")
def rows():
    return {p.key: evaluate3d(p) for p in (P1, P2, P3)}


def _one_point(path, rows, point=P1):
    t = StudyTable3D.open(path)
    t.append(rows[point.key])
    return t


def test_3d_appends_keep_the_inode_and_the_bytes_before_them(tmp_path, rows):
    path = tmp_path / "s3.csv"
    t = _one_point(path, rows)
    ino, first = os.stat(path).st_ino, path.read_bytes()
    t.append(rows[P2.key])
    t = StudyTable3D.open(path)  # a resumed table appends in place too
    t.append(rows[P3.key])
    data = path.read_bytes()
    assert os.stat(path).st_ino == ino and data.startswith(first) and len(data) > len(first)
    assert StudyTable3D.open(path).finished == {P1.key, P2.key, P3.key}
    assert not hasattr(t, "lines")  # keys and a size: memory does not grow with the file
    assert t.size == len(data)


@pytest.mark.parametrize("when", ["half-written", "fsync", "disk full"])
def test_an_interrupted_3d_append_is_cut_back(tmp_path, rows, when, monkeypatch):
    path = tmp_path / "s3.csv"
    t = _one_point(path, rows)
    ino, before = os.stat(path).st_ino, path.read_bytes()
    real_write = os.write

    def half_then(fd, data):  # half the point reaches the file, then it stops
        real_write(fd, bytes(data[: len(data) // 2]))
        if when == "disk full":
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
        raise KeyboardInterrupt

    def boom(*_a, **_k):
        raise KeyboardInterrupt

    if when == "fsync":
        monkeypatch.setattr(table_mod.os, "fsync", boom)
    else:
        monkeypatch.setattr(table_mod.os, "write", half_then)
    expected = EyevizError if when == "disk full" else KeyboardInterrupt
    with pytest.raises(expected) as err:
        t.append(rows[P2.key])
    monkeypatch.undo()
    if when == "disk full":
        msg = str(err.value)
        assert "\n" not in msg and str(path) in msg and "No space left" in msg
    assert path.read_bytes() == before and os.stat(path).st_ino == ino
    assert sorted(os.listdir(tmp_path)) == ["s3.csv"]  # no temporary file
    assert StudyTable3D.open(path).finished == {P1.key}
    t.append(rows[P2.key])  # the table object is still usable
    assert StudyTable3D.open(path).finished == {P1.key, P2.key}


# Line 2 is bin "all" (60 elements), lines 3-10 the distance bins r0-r7, 11-16 e0-e5.
HOSTILE = [
    (2, "gamma", "0.5", "gamma = 0.5 is not 2 pi / m"),
    (3, "count", "-1", "count must be >= 0, got -1"),
    (2, "dd_mape", "nan", "a bin with count > 0 needs"),
    (4, "el_mae_deg", "nan", "a bin with count > 0 needs"),
    (2, "nside", "7", "nside must be an even integer"),
    (2, "nside", "0", "nside must be an even integer"),
    (4, "lo", "-1e308", "lo = -1e+308 is not bin r1's edge"),
    (12, "hi", "1e308", "hi = 1e+308 is not bin e1's edge"),
    (11, "lo", "0.1", "lo = 0.1 is not bin e0's edge"),
    (2, "lo", "999", "lo = 999 is not bin all's edge"),
    (3, "count", "\u0663", "count must be an integer"),
    (2, "h", "2\u0660", "h must be a number"),
    (2, "nside", "\uff18", "nside must be an integer"),
    (5, "n", "6_0", "n must be an integer"),
    (2, "m", "33", "m = 33 is not 4 nside = 32"),
    (6, "el_mae_deg", "-0.5", "column el_mae_deg: must be >= 0"),
    (2, "az_mae_deg", "inf", "column az_mae_deg: must be >= 0 and finite"),
    (2, "dd_mape", "1e308", "column dd_mape: 1e+308 is no error a study measures"),
    (2, "az_mae_deg", "1e13", "column az_mae_deg: 1e+13 is no error a study measures"),
    (2, "dd_r2", "-1e308", "column dd_r2: must be within [-1e+30, 1]"),
    (2, "el_r2", "1.5", "column el_r2: must be within [-1e+30, 1]"),
    (2, "dd_r2", "-inf", "column dd_r2: must be within [-1e+30, 1]"),
    (2, "flagged", "61", "flagged 61 exceeds count"),
    (2, "count", "61", "count 61 exceeds n = 60"),
    (13, "bin", "e9", "bin e9 beyond the 6 bins"),
    (5, "bin", "r08", "bin must be 'all', 'r<i>' or 'e<j>'"),
    (13, "bin", "e\u0662", "bin must be 'all', 'r<i>' or 'e<j>'"),
    (2, "seconds", "nan", "column seconds: must be >= 0 and finite"),
    (2, "version", "1", "written by 3D study version 1"),
    (2, "dd_se", "-0.1", "column dd_se: must be >= 0"),
    (3, "el_se", "inf", "column el_se: must be >= 0 and finite"),
    (2, "dd_se", "1e13", "column dd_se: 1e+13 is no error a study measures"),
    (2, "el_max", "2.0", "el_max"),
    (2, "estimator", "no such", "estimator must be"),
]


@pytest.mark.parametrize(("line", "column", "value", "words"), HOSTILE)
def test_resume_and_report_refuse_the_same_3d_edit_in_the_same_line(
    tmp_path, rows, edit_field, line, column, value, words
):
    from eyeviz.reports.study import write_report

    path = tmp_path / "s3.csv"
    _one_point(path, rows)
    edit_field(path, line, COLUMNS3D, column, value)
    before = path.read_bytes()
    msgs = []
    for read in (
        StudyTable3D.open,  # the table object
        lambda p: run_study(p, [P1], workers=1, progress=False),  # the runner's resume
        lambda p: write_report(p, tmp_path / "figs"),  # eyeviz report study
    ):
        with pytest.raises(EyevizError) as err:
            read(path)
        msgs.append(str(err.value))
    for msg in msgs:
        assert "\n" not in msg and f"{path} line {line}:" in msg, msg
        assert words in msg, msg
    assert msgs[0] == msgs[1] == msgs[2]  # one parser
    assert path.read_bytes() == before
    assert not (tmp_path / "figs").exists()


@pytest.mark.parametrize("kind", ["planar", "3d"])
def test_a_point_past_the_readers_bound_is_refused_before_writing(tmp_path, rows, kind):
    path = tmp_path / "s.csv"
    if kind == "3d":
        table, first, second = StudyTable3D, rows[P1.key], rows[P2.key]
    else:
        a, b = (DesignPoint(h=40, l=20, m=m, n=200, seed=1) for m in (180, 360))
        table, first, second = StudyTable, evaluate(a), evaluate(b)
    t = table.open(path)
    t.append(first)
    size = t.size
    t = table.open(path, max_bytes=size + 100)  # room for less than one more point
    before = path.read_bytes()
    with pytest.raises(EyevizError) as err:
        t.append(second)
    msg = str(err.value)
    assert "\n" not in msg and str(path) in msg and f"past {size + 100} bytes" in msg
    assert "stopped with 1 point(s) kept" in msg
    assert path.read_bytes() == before
    table.open(path, max_bytes=size + 100)  # still readable under that bound


def test_a_3d_study_stops_before_its_table_passes_the_bound(tmp_path, monkeypatch):
    path = tmp_path / "s3.csv"
    points = design_grid3d("20", "10", "8,16", n=60, seed=1)
    run_study(path, points[:1], workers=1, progress=False)
    ino, before = os.stat(path).st_ino, path.read_bytes()
    monkeypatch.setattr(table_mod, "MAX_STUDY_BYTES", len(before) + 200)
    with pytest.raises(EyevizError) as err:
        run_study(path, points, workers=1, progress=False)
    msg = str(err.value)
    assert "\n" not in msg and str(path) in msg and "the most its reader accepts" in msg
    assert "stopped with 1 point(s) kept" in msg
    assert path.read_bytes() == before and os.stat(path).st_ino == ino
    assert StudyTable3D.open(path).finished == {points[0].key}


def test_a_symlinked_3d_output_is_written_through_in_place(tmp_path):
    real = tmp_path / "data" / "s3.csv"
    real.parent.mkdir()
    link = tmp_path / "link.csv"
    link.symlink_to(real)  # dangling: the study creates its target
    points = design_grid3d("20", "10", "8,16", n=60, seed=1)
    run_study(link, points[:1], workers=1, progress=False)
    assert link.is_symlink() and os.readlink(link) == str(real) and real.is_file()
    ino, first = os.stat(real).st_ino, real.read_bytes()
    s = run_study(link, points, workers=1, progress=False)
    assert (s.computed, s.skipped) == (1, 1)
    assert link.is_symlink() and os.stat(real).st_ino == ino
    assert real.read_bytes().startswith(first)
    assert StudyTable3D.open(real).finished == {p.key for p in points}
    assert not [p for p in tmp_path.rglob(".*")]  # no lock, no temporary file left


def test_a_hard_link_to_a_3d_table_under_study_is_refused_and_names_one_file(tmp_path, rows):
    from eyeviz.study.runner import _exclusive

    real = tmp_path / "s3.csv"
    _one_point(real, rows)
    (tmp_path / "other").mkdir()
    hard = tmp_path / "other" / "copy.csv"
    os.link(real, hard)
    before = real.read_bytes()
    with _exclusive(real):
        with pytest.raises(EyevizError, match="hard link") as err:
            run_study(hard, [P1, P2], workers=1, progress=False)
        assert "\n" not in str(err.value)
    assert real.read_bytes() == before
    StudyTable3D.open(hard).append(rows[P2.key])  # appended in place: both names see it
    assert os.path.samefile(real, hard)
    assert StudyTable3D.open(real).finished == {P1.key, P2.key}
    rows_back, _ = read_rows3d(real)
    assert len(rows_back) == 2 * 15


def test_a_3d_table_without_its_final_newline_takes_the_next_point_on_a_line_of_its_own(
    tmp_path, rows
):
    path = tmp_path / "s3.csv"
    _one_point(path, rows)
    path.write_bytes(path.read_bytes()[:-1])
    before = path.read_bytes()
    StudyTable3D.open(path).append(rows[P2.key])
    data = path.read_bytes()
    assert data.startswith(before) and data.endswith(b"\n")
    assert StudyTable3D.open(path).finished == {P1.key, P2.key}


def test_a_fifo_is_refused_without_opening_it(tmp_path):
    """is_table3d opened the path to read its header: at a FIFO, open() blocked for
    good, so `eyeviz report study` and the resume hung (the resume past SIGTERM)."""
    import threading

    from eyeviz.study.kinds import open_table
    from eyeviz.study.table import is_table3d

    fifo = tmp_path / "s.csv"
    os.mkfifo(fifo)
    out: list[bool] = []
    t = threading.Thread(target=lambda: out.append(is_table3d(fifo)), daemon=True)
    t.start()
    t.join(10)
    if t.is_alive():  # unblock it (a writer opens and goes), then fail
        os.close(os.open(fifo, os.O_WRONLY | os.O_NONBLOCK))
        t.join(10)
        pytest.fail("is_table3d blocked on a FIFO")
    assert out == [False]
    for table in (StudyTable, StudyTable3D):
        with pytest.raises(EyevizError, match="is not a regular file"):
            table.open(fifo)
    with pytest.raises(EyevizError, match="is not a regular file"):
        open_table(fifo, [P1])
