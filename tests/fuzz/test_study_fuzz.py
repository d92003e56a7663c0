"""Second campaign (issue 25): the study table, symlinked outputs and locks, huge m.

- Study table: mutated bytes and adversarial field edits (Unicode digits, underscores,
  1e308, inf, nan, signs) are read the same by the runner (StudyTable.open) and the
  report (read_study): both accept, or both refuse with the same one line naming the
  file; an accepted table takes one more point and still reads back; the input file is
  never changed by reading.
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
from eyeviz.reports.study_table import read_study
from eyeviz.study.point import COLUMNS, DesignPoint, evaluate
from eyeviz.study.table import StudyTable

from .conftest import assert_one_line, count, digest, fuzz_settings

P1 = DesignPoint(h=40, l=20, m=180, n=120, seed=1)
P2 = DesignPoint(h=20, l=10, m=360, n=120, seed=2)
P3 = DesignPoint(h=30, l=10, m=90, n=120, seed=3)
ROWS = {p.key: evaluate(p) for p in (P1, P2, P3)}


def _table_bytes() -> bytes:
    with tempfile.TemporaryDirectory() as d:
        p = Path(d) / "s.csv"
        t = StudyTable.open(p)
        t.append(ROWS[P1.key])
        t.append(ROWS[P2.key])
        return p.read_bytes()


TABLE = _table_bytes()
TABLE_LINES = TABLE.decode().splitlines()
NASTY = [
    "\u0661", "\u0663\u0660", "\uff11", "1_000", "1e308", "-1e308", "inf", "-inf", "nan",
    "-0", "+5", "0x10", " 7", "1e999", "", "9" * 25, "1.5", "-1", "all", "\u00b2", "0.0",
]  # fmt: skip


@st.composite
def edited_table(draw) -> bytes:
    lines = list(TABLE_LINES)
    for _ in range(draw(st.integers(1, 3))):
        i = draw(st.integers(1, len(lines) - 1))
        try:
            fields = next(csv.reader([lines[i]]))
        except csv.Error:  # an earlier edit put a line break in this line
            continue
        j = draw(st.integers(0, len(COLUMNS) - 1))
        fields[j] = draw(st.sampled_from(NASTY) | st.text(max_size=6))
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


def _read_both(path):
    out = []
    for read in (StudyTable.open, read_study):
        try:
            out.append(("ok", read(path)))
        except EyevizError as exc:
            out.append(("refused", str(exc)))
    return out


@fuzz_settings(60)
@given(edited_table())
def test_runner_and_report_read_an_edited_table_alike(data):
    with tempfile.TemporaryDirectory() as d:
        path = Path(d) / "s.csv"
        path.write_bytes(data)
        before = digest(path)
        (a, ra), (b, rb) = _read_both(path)
        assert digest(path) == before
        assert a == b, (ra, rb)
        if a == "refused":
            assert ra == rb
            assert_one_line(ra)
            assert str(path) in ra
            count("study table edits", "refused")
            return
        for row in rb:  # what the report draws from holds its invariants
            assert math.isclose(row.gamma, 2 * math.pi / row.m, rel_tol=1e-9)
            assert 0 <= row.count <= row.n and row.flagged <= row.count
            for v in (row.dd_mape, row.ad_mape, row.seconds):
                assert math.isnan(v) or 0 <= v < math.inf
            assert row.r_min <= row.r_lo < row.r_hi <= row.r_max
        if P3.key not in ra.keys:  # one more point: the file still reads back
            ra.append(ROWS[P3.key])
            assert P3.key in StudyTable.open(path).keys
            read_study(path)
        count("study table edits", "ok")


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
