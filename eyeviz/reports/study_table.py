"""The eye-design study table as typed rows for the report (issue 11).

The table is the CSV ``eyeviz study`` writes (:mod:`eyeviz.study.table`, whose bounded
reader parses it: one parser with one set of checks for the runner and the report, naming
the file and the first bad line, refusing another version; gamma = 2 pi / m, count <= n,
finite non-negative metrics, a metric for every non-empty bin and the bins' bounds
included). The report adds only: at least one row.
"""

from __future__ import annotations

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


def _row(d: dict) -> Row:
    return Row(d["_line"], *(d[c] for c in _ROW_FIELDS))


def read_study(path, max_bytes: int | None = None) -> list[Row]:
    """The rows of a study table; EyevizError (naming the first bad line) otherwise.

    The file is refused unread when larger than ``max_bytes`` (default
    :data:`eyeviz.files.limits.MAX_STUDY_BYTES`, the bound ``eyeviz study`` writes under).
    """
    name = str(path)
    dicts, _ = read_rows(path, MAX_STUDY_BYTES if max_bytes is None else max_bytes)
    if not dicts:
        raise EyevizError(f"study table {name!r} has no rows (an empty file or a header only)")
    return [_row(d) for d in dicts]
