"""Second campaign (issue 25): the study table, symlinked outputs and locks, huge m.

- Study table: mutated bytes and adversarial field edits (Unicode digits, underscores,
  1e308, inf, nan, signs) are read the same by the runner (StudyTable.open) and the
  report (read_study): both accept, or both refuse with the same one line naming the
  file; an accepted table takes one more point and still reads back; the input file is
  never changed by reading. The same for the 3D study table (StudyTable3D.open and the
  3D report's read_study3d; nside, elevation bins and errors among the edits).
- Appends of either table stopped after any byte (an interruption or a full disk) are
  cut back: the file is byte for byte what it was, and the next append goes in.
- Symlinks: chains of absolute or relative links (dangling or not) are written through
  by atomic_output (every link stays a link, the final target gets the bytes) and a
  study lock held on the file refuses every alias (symlink or hard link).
- Huge m: `limit` on random designs up to m = 2^20 answers each row as it answers the
  row alone, finite, in any batch.
"""

from __future__ import annotations

import contextlib
import csv
import io
import math
import os
import tempfile
from pathlib import Path

import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from eyeviz import EyevizError
from eyeviz.reports.study_design import read_study3d
from eyeviz.reports.study_table import read_study
from eyeviz.study.point import COLUMNS, COLUMNS3D, DesignPoint, DesignPoint3D, evaluate, evaluate3d
from eyeviz.study.table import StudyTable, StudyTable3D

from .conftest import assert_one_line, count, digest, fuzz_settings

P1 = DesignPoint(h=40, l=20, m=180, n=120, seed=1)
P2 = DesignPoint(h=20, l=10, m=360, n=120, seed=2)
P3 = DesignPoint(h=30, l=10, m=90, n=120, seed=3)
ROWS = {p.key: evaluate(p) for p in (P1, P2, P3)}
Q1 = DesignPoint3D(h=20, l=10, nside=8, n=60, seed=1)
Q2 = DesignPoint3D(h=40, l=10, nside=8, n=60, seed=2)
Q3 = DesignPoint3D(h=20, l=10, nside=16, n=60, seed=3)
ROWS3D = {q.key: evaluate3d(q) for q in (Q1, Q2, Q3)}


def _table_bytes(table, rows) -> bytes:
    with tempfile.TemporaryDirectory() as d:
        p = Path(d) / "s.csv"
        t = table.open(p)
        for r in rows:
            t.append(r)
        return p.read_bytes()


TABLE = _table_bytes(StudyTable, [ROWS[P1.key], ROWS[P2.key]])
TABLE_LINES = TABLE.decode().splitlines()
TABLE3D_LINES = _table_bytes(StudyTable3D, [ROWS3D[Q1.key], ROWS3D[Q2.key]]).decode().splitlines()
NASTY = [
    "\u0661", "\u0663\u0660", "\uff11", "1_000", "1e308", "-1e308", "inf", "-inf", "nan",
    "-0", "+5", "0x10", " 7", "1e999", "", "9" * 25, "1.5", "-1", "all", "\u00b2", "0.0",
]  # fmt: skip
#: And what a 3D table's nside, bins and estimator columns may be given.
NASTY3D = [*NASTY, "7", "0", "8", "16", "e5", "e6", "r7", "r8", "r07", "e\u0661", "limit3d", "x"]
#: Columns whose edit may leave a 3D table valid (the metrics, counts and time).
FOCUS3D = ("dd_mape", "el_mae_deg", "az_mae_deg", "dd_r2", "el_r2", "flagged", "seconds")


@st.composite
def edited_table(draw, table_lines=TABLE_LINES, columns=COLUMNS, nasty=NASTY, focus=()) -> bytes:
    """1-3 fields of the table set to nasty values (``focus``: column names drawn more
    often, so that some edits keep the table valid), then perhaps a few bytes changed."""
    pick = st.integers(0, len(columns) - 1)
    if focus:
        pick = pick | st.sampled_from([columns.index(c) for c in focus])
    lines = list(table_lines)
    for _ in range(draw(st.integers(1, 3))):
        i = draw(st.integers(1, len(lines) - 1))
        try:
            fields = next(csv.reader([lines[i]]))
        except csv.Error:  # an earlier edit put a line break in this line
            continue
        j = draw(pick)
        fields[j] = draw(st.sampled_from(nasty) | st.text(max_size=6))
        buf = io.StringIO()
        csv.writer(buf, lineterminator="").writerow(fields)
        lines[i] = buf.getvalue()
    if draw(st.booleans()):
        b = bytearray("\n".join(lines).encode("utf-8", "surrogatepass") + b"\n")
        for _ in range(draw(st.integers(0, 3))):
            k = draw(st.integers(0, len(b) - 1))
            b[k] = draw(st.sampled_from(list(b"0123456789,.-+eE\n\x00\xffx")))
        return bytes(b)
    return ("\n".join(lines) + "\n").encode("utf-8", "surrogatepass")


def _read_alike(data: bytes, table, report, holds, more, category: str) -> None:
    """The runner (``table.open``) and the report (``report``) read ``data`` alike: both
    accept it, the report's rows hold ``holds``, and the table takes one more point
    (``more``: its key and rows) and still reads back; or both refuse it with the same
    one line naming the file. Reading never changes the file."""
    with tempfile.TemporaryDirectory() as d:
        path = Path(d) / "s.csv"
        path.write_bytes(data)
        before = digest(path)
        out = []
        for read in (table.open, report):
            try:
                out.append(("ok", read(path)))
            except EyevizError as exc:
                out.append(("refused", str(exc)))
        (a, ra), (b, rb) = out
        assert digest(path) == before
        assert a == b, (ra, rb)
        if a == "refused":
            assert ra == rb
            assert_one_line(ra)
            assert str(path) in ra
            count(category, "refused")
            return
        for row in rb:  # what the report draws from holds its invariants
            holds(row)
        key, rows = more
        if key not in ra.keys:  # one more point: the file still reads back
            ra.append(rows)
            assert key in table.open(path).keys
            report(path)
        count(category, "ok")


def _holds_planar(row) -> None:
    assert math.isclose(row.gamma, 2 * math.pi / row.m, rel_tol=1e-9)
    assert 0 <= row.count <= row.n and row.flagged <= row.count
    for v in (row.dd_mape, row.ad_mape, row.seconds):
        assert math.isnan(v) or 0 <= v < math.inf
    assert row.r_min <= row.r_lo < row.r_hi <= row.r_max


def _holds_3d(row: dict) -> None:
    assert row["m"] == 4 * row["nside"] and row["nside"] % 2 == 0
    assert math.isclose(row["gamma"], 2 * math.pi / row["m"], rel_tol=1e-9)
    assert 0 <= row["count"] <= row["n"] and 0 <= row["flagged"] <= row["count"]
    for k in ("dd_mape", "ad_mape", "el_mae_deg", "az_mae_deg"):
        v = row[k]
        assert (math.isnan(v) and not row["count"]) or 0 <= v < math.inf, (k, v)
    for k in ("dd_r2", "ad_r2", "el_r2"):
        assert math.isnan(row[k]) or row[k] <= 1
    assert 0 <= row["seconds"] < math.inf
    if row["bin"].startswith("e"):
        assert -row["el_max"] <= row["lo"] < row["hi"] <= row["el_max"]
    else:
        assert row["bin"] == "all" or row["bin"].startswith("r")
        assert row["r_min"] <= row["lo"] < row["hi"] <= row["r_max"]


@fuzz_settings(60)
@given(edited_table())
def test_runner_and_report_read_an_edited_table_alike(data):
    more = (P3.key, ROWS[P3.key])
    _read_alike(data, StudyTable, read_study, _holds_planar, more, "study table edits")


@fuzz_settings(60)
@given(edited_table(TABLE3D_LINES, COLUMNS3D, NASTY3D, FOCUS3D))
def test_runner_and_report_read_an_edited_3d_table_alike(data):
    more = (Q3.key, ROWS3D[Q3.key])
    _read_alike(data, StudyTable3D, read_study3d, _holds_3d, more, "3D study table edits")


@fuzz_settings(40)
@given(st.booleans(), st.integers(0, 10**6), st.sampled_from(["interrupt", "disk full"]))
def test_an_append_stopped_after_any_byte_is_cut_back(three_d, cut, how):
    import errno

    if three_d:
        table, rows, k1, k2 = StudyTable3D, ROWS3D, Q1.key, Q2.key
    else:
        table, rows, k1, k2 = StudyTable, ROWS, P1.key, P2.key
    with tempfile.TemporaryDirectory() as d:
        path = Path(d) / "s.csv"
        t = table.open(path)
        t.append(rows[k1])
        before = path.read_bytes()
        real_write = os.write

        def stop_after(fd, data):
            keep = cut % (len(data) + 1)  # 0 ... all of the point's bytes
            real_write(fd, bytes(data[:keep]))
            if how == "disk full":
                raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
            raise KeyboardInterrupt

        os.write = stop_after
        try:
            t.append(rows[k2])
        except KeyboardInterrupt:
            assert how == "interrupt"
        except EyevizError as exc:
            assert how == "disk full"
            assert_one_line(str(exc))
            assert str(path) in str(exc)
        else:
            raise AssertionError("the append was not stopped")
        finally:
            os.write = real_write
        assert path.read_bytes() == before
        assert sorted(p.name for p in Path(d).iterdir()) == ["s.csv"]
        t.append(rows[k2])
        assert table.open(path).finished == {k1, k2}
        count("appends stopped after any byte", "ok")


@st.composite
def link_chain(draw):
    depth = draw(st.integers(1, 4))
    relative = [draw(st.booleans()) for _ in range(depth)]
    exists = draw(st.booleans())
    subdirs = [draw(st.booleans()) for _ in range(depth + 1)]
    hard = draw(st.booleans())
    return depth, relative, exists, subdirs, hard


@fuzz_settings(40)
@given(link_chain(), st.binary(min_size=0, max_size=64))
def test_symlinked_outputs_and_locks_act_on_the_target(chain, payload):
    from eyeviz.files.atomic import atomic_output
    from eyeviz.study.runner import _exclusive

    depth, relative, exists, subdirs, hard = chain
    with tempfile.TemporaryDirectory() as d:
        root = Path(d)

        def place(i: int, name: str) -> Path:
            folder = root / f"d{i}" if subdirs[i] else root
            folder.mkdir(exist_ok=True)
            return folder / name

        target = place(0, "table.csv")
        if exists:
            target.write_bytes(b"old")
        prev = target
        links = []
        for i in range(depth):
            link = place(i + 1, f"link{i}.csv")
            dest = os.path.relpath(prev, link.parent) if relative[i] else str(prev)
            link.symlink_to(dest)
            links.append(link)
            prev = link
        with atomic_output(links[-1]) as tmp:
            tmp.write_bytes(payload)
        assert all(p.is_symlink() for p in links)
        assert target.read_bytes() == payload and links[-1].read_bytes() == payload
        aliases = list(links)
        if hard:
            h = place(depth, "hard.csv")
            if not h.exists():
                os.link(target, h)
                aliases.append(h)
        with _exclusive(target):
            for alias in aliases:
                try:
                    with _exclusive(alias):
                        raise AssertionError(f"{alias} was not refused")
                except EyevizError as exc:
                    assert_one_line(str(exc))
        with _exclusive(aliases[-1]):  # released: any alias takes it again
            pass
        leftovers = [p for p in root.rglob(".*") if p.name.endswith(".lock")]
        assert leftovers == []
        count("symlinked outputs and locks", "ok")


@fuzz_settings(25)
@given(
    st.sampled_from([1 << 20, (1 << 20) - 2, 220_000, 110_002])
    | st.integers(2, 1 << 19).map(lambda k: 2 * k),
    st.lists(st.tuples(st.floats(-0.6, 0.6), st.floats(1.0, 5.0), st.floats(0.02, 0.3)),
             min_size=1, max_size=4),
)  # fmt: skip
def test_limit_at_any_m_answers_each_row_alone(m, feats):
    from eyeviz import estimators
    from eyeviz.core.domain import Domain

    dom = Domain(m=m)
    x = np.array([f[0] for f in feats]) * 3000
    y = np.array([f[1] for f in feats]) * 1000
    g = np.array([f[2] for f in feats]) * 1000
    LA, RA, LB, RB = (np.asarray(v, np.int64) for v in dom.eyes.intervals(x, y, g))
    keep = (LA >= 0) & (RA < dom.width) & (LB >= 0) & (RB < dom.width) & (LA <= RA) & (LB <= RB)
    if not keep.any():
        count("limit at huge m", "refused")
        return
    LA, RA, LB, RB = LA[keep], RA[keep], LB[keep], RB[keep]
    with contextlib.suppress(EyevizError):
        both = estimators.load("limit", domain=dom).predict_intervals(LA, RA, LB, RB)
        for i in range(LA.size):
            one = estimators.load("limit", domain=dom).predict_intervals(
                LA[i : i + 1], RA[i : i + 1], LB[i : i + 1], RB[i : i + 1]
            )
            assert one.r[0] == both.r[i] or (np.isnan(one.r[0]) and np.isnan(both.r[i]))
            assert one.phi[0] == both.phi[i] or (np.isnan(one.phi[0]) and np.isnan(both.phi[i]))
            assert bool(one.flagged[0]) == bool(both.flagged[i])
        assert np.all(np.isfinite(both.r[both.valid]))
        count("limit at huge m", "ok")
        return
    count("limit at huge m", "refused")
