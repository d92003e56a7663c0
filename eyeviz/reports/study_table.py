"""The eye-design study table as typed rows for the report (issue 11).

The table is the CSV ``eyeviz study`` writes (:mod:`eyeviz.study.table`, whose bounded
reader parses it: one parser for the runner and the report, naming the first bad line,
refusing another version). On top of it the report checks what its figures rely on:
gamma = 2 pi / m, count <= n, a metric for every non-empty bin, at least one row.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

from eyeviz import EyevizError
from eyeviz.files.limits import MAX_STUDY_BYTES
from eyeviz.study.point import COLUMNS, STUDY_VERSION
from eyeviz.study.table import read_rows

__all__ = ["COLUMNS", "MAX_STUDY_BYTES", "STUDY_VERSION", "Row", "read_study"]


@dataclass(frozen=True)
class Row:
    """One row of the study table (one design point and one distance bin)."""

    line: int  # the file's line number (the header is line 1)
    h: float
    l: float  # noqa: E741  (the paper's name)
    m: int
    gamma: float
    r_min: float
    r_max: float
    g_max: float
    prior: str
    n: int
    seed: int
    bin: str  # "all" or "0", "1", ...
    r_lo: float
    r_hi: float
    count: int
    dd_mape: float
    ad_mape: float
    dd_r2: float
    ad_r2: float
    flagged: int
    seconds: float

    @property
    def design(self) -> tuple[float, float, int]:
        return (self.h, self.l, self.m)

    @property
    def run(self) -> tuple:
        """What identifies one evaluated design point (resume key of the study file)."""
        return (self.h, self.l, self.m, self.r_min, self.r_max, self.g_max, self.prior,
                self.n, self.seed)  # fmt: skip

    @property
    def r_mid(self) -> float:
        return 0.5 * (self.r_lo + self.r_hi)


_ROW_FIELDS = tuple(f.name for f in fields(Row) if f.name != "line")


def _checked(name: str, d: dict) -> Row:
    line = d["_line"]
    row = Row(line, *(d[c] for c in _ROW_FIELDS))
    where = f"study table {name!r}: line {line}"
    if not math.isclose(row.gamma, 2 * math.pi / row.m, rel_tol=1e-9):
        raise EyevizError(f"{where}: gamma = {row.gamma:g} is not 2 pi / m for m = {row.m}")
    if row.count > row.n:
        raise EyevizError(f"{where}: count {row.count} exceeds n = {row.n}")
    if row.count and (math.isnan(row.dd_mape) or math.isnan(row.ad_mape)):
        raise EyevizError(f"{where}: a bin with count > 0 needs dd_mape and ad_mape")
    for col in ("dd_mape", "ad_mape", "seconds"):
        v = getattr(row, col)
        if not (math.isnan(v) or 0 <= v < math.inf):
            raise EyevizError(f"{where}: column {col}: must be >= 0 and finite, got {v:g}")
    return row


def read_study(path, max_bytes: int | None = None) -> list[Row]:
    """The rows of a study table; EyevizError (naming the first bad line) otherwise.

    The file is refused unread when larger than ``max_bytes`` (default
    :data:`eyeviz.files.limits.MAX_STUDY_BYTES`, the bound ``eyeviz study`` writes under).
    """
    name = str(path)
    dicts, _ = read_rows(path, MAX_STUDY_BYTES if max_bytes is None else max_bytes)
    if not dicts:
        raise EyevizError(f"study table {name!r} has no rows (an empty file or a header only)")
    rows = [_checked(name, d) for d in dicts]
    return rows
