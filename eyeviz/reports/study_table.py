"""A bounded, validating reader of the eye-design study table (issue 11).

The table is the CSV ``eyeviz study`` writes: the header is exactly :data:`COLUMNS`, one
row per design point and distance bin (``bin = "all"`` then "0", "1", ...). The reader
refuses, with a one-line :class:`eyeviz.EyevizError` naming the first bad line: a file
larger than :data:`eyeviz.files.limits.MAX_STUDY_BYTES` (checked before reading), another
header, a row of another ``version``, a field that is not the number its column needs, a
duplicated row. (``eyeviz.study.table`` reads the same file for the runner; the reports
layer may not import it.)

The reports layer may not import :mod:`eyeviz.study` (sibling layers), so the columns and
the version are repeated here; ``tests/reports/test_study.py`` checks they stay equal to
:data:`eyeviz.study.point.COLUMNS` and :data:`eyeviz.study.point.STUDY_VERSION`.
"""

from __future__ import annotations

import csv
import io
import math
from dataclasses import dataclass
from pathlib import Path

from eyeviz import EyevizError
from eyeviz.files.limits import MAX_M, MAX_STUDY_BYTES, read_bounded

__all__ = ["COLUMNS", "MAX_STUDY_BYTES", "MAX_STUDY_ROWS", "STUDY_VERSION", "Row", "read_study"]

STUDY_VERSION = 1
COLUMNS = (
    "version", "h", "l", "m", "gamma", "r_min", "r_max", "g_max", "prior", "n", "seed",
    "bin", "r_lo", "r_hi", "count", "dd_mape", "ad_mape", "dd_r2", "ad_r2", "flagged",
    "seconds",
)  # fmt: skip
PRIORS = ("single", "multi")
#: Rows of a study table (design points x bins).
MAX_STUDY_ROWS = 1_000_000
#: Distance bins of one design point.
MAX_BINS = 10_000


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


def _num(line: int, col: str, text: str, *, positive=False, nan_ok=False, lo=None) -> float:
    if nan_ok and not text.strip():  # pandas and None write a missing value as ""
        return math.nan
    try:
        v = float(text)
    except ValueError:
        raise EyevizError(f"line {line}: column {col}: not a number: {text[:40]!r}") from None
    if math.isnan(v):
        if nan_ok:
            return v
        raise EyevizError(f"line {line}: column {col}: must be a number, got nan")
    if math.isinf(v):
        raise EyevizError(f"line {line}: column {col}: must be finite, got {text[:40]!r}")
    if positive and v <= 0:
        raise EyevizError(f"line {line}: column {col}: must be > 0, got {v:g}")
    if lo is not None and v < lo:
        raise EyevizError(f"line {line}: column {col}: must be >= {lo:g}, got {v:g}")
    return v


def _int(line: int, col: str, text: str, lo: int, hi: int) -> int:
    try:
        v = int(text)
    except ValueError:
        raise EyevizError(f"line {line}: column {col}: not an integer: {text[:40]!r}") from None
    if not lo <= v <= hi:
        raise EyevizError(f"line {line}: column {col}: must be in [{lo}, {hi}], got {v}")
    return v


def _row(line: int, f: dict[str, str]) -> Row:
    version = f["version"].strip()
    if version != str(STUDY_VERSION):
        raise EyevizError(
            f"line {line}: a study table of version {version[:20]!r}; this eyeviz reads "
            f"version {STUDY_VERSION} (re-run eyeviz study)"
        )
    prior = f["prior"].strip()
    if prior not in PRIORS:
        raise EyevizError(f"line {line}: column prior: {prior[:40]!r} is not one of {PRIORS}")
    b = f["bin"].strip()
    if b != "all":
        _int(line, "bin", b, 0, MAX_BINS - 1)
    m = _int(line, "m", f["m"], 4, MAX_M)
    h = _num(line, "h", f["h"], positive=True)
    l_ = _num(line, "l", f["l"], positive=True)
    if l_ >= h:
        raise EyevizError(f"line {line}: l = {l_:g} must be < h = {h:g}")
    r_min = _num(line, "r_min", f["r_min"], positive=True)
    r_max = _num(line, "r_max", f["r_max"], positive=True)
    r_lo = _num(line, "r_lo", f["r_lo"], positive=True)
    r_hi = _num(line, "r_hi", f["r_hi"], positive=True)
    if not (r_min < r_max and r_lo < r_hi):
        raise EyevizError(f"line {line}: r_min < r_max and r_lo < r_hi must hold")
    row = Row(
        line=line,
        h=h,
        l=l_,
        m=m,
        gamma=_num(line, "gamma", f["gamma"], positive=True),
        r_min=r_min,
        r_max=r_max,
        g_max=_num(line, "g_max", f["g_max"], positive=True),
        prior=prior,
        n=_int(line, "n", f["n"], 1, 10**12),
        seed=_int(line, "seed", f["seed"], 0, 2**63),
        bin=b,
        r_lo=r_lo,
        r_hi=r_hi,
        count=_int(line, "count", f["count"], 0, 10**12),
        dd_mape=_num(line, "dd_mape", f["dd_mape"], nan_ok=True, lo=0.0),
        ad_mape=_num(line, "ad_mape", f["ad_mape"], nan_ok=True, lo=0.0),
        dd_r2=_num(line, "dd_r2", f["dd_r2"], nan_ok=True),
        ad_r2=_num(line, "ad_r2", f["ad_r2"], nan_ok=True),
        flagged=_int(line, "flagged", f["flagged"], 0, 10**12),
        seconds=_num(line, "seconds", f["seconds"], nan_ok=True, lo=0.0),
    )
    if not math.isclose(row.gamma, 2 * math.pi / m, rel_tol=1e-9):
        raise EyevizError(f"line {line}: gamma = {row.gamma:g} is not 2 pi / m for m = {m}")
    if row.count > row.n:
        raise EyevizError(f"line {line}: count {row.count} exceeds n = {row.n}")
    if row.count and (math.isnan(row.dd_mape) or math.isnan(row.ad_mape)):
        raise EyevizError(f"line {line}: a bin with count > 0 needs dd_mape and ad_mape")
    return row


def read_study(path, max_bytes: int | None = None) -> list[Row]:
    """The rows of a study table; EyevizError (naming the first bad line) otherwise.

    The file is refused unread when larger than ``max_bytes`` (default
    :data:`eyeviz.files.limits.MAX_STUDY_BYTES`, the bound ``eyeviz study`` writes under).
    """
    max_bytes = MAX_STUDY_BYTES if max_bytes is None else max_bytes
    name = str(Path(path))
    raw = read_bounded(path, max_bytes, "study table")
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        line = raw[: exc.start].count(b"\n") + 1
        raise EyevizError(f"study table {name!r}: line {line}: not UTF-8 text") from None
    if "\x00" in text:
        line = text[: text.index("\x00")].count("\n") + 1
        raise EyevizError(f"study table {name!r}: line {line}: a NUL byte (binary file?)")
    reader = csv.reader(io.StringIO(text, newline=""), strict=True)
    rows: list[Row] = []
    seen: dict[tuple, int] = {}
    try:
        header = next(reader, None)
        if header is None:
            raise EyevizError(f"study table {name!r} is empty (no header)")
        if tuple(c.strip() for c in header) != COLUMNS:
            if "version" in header:
                raise EyevizError(
                    f"study table {name!r}: line 1: the columns of another version of the "
                    f"study table; this eyeviz reads version {STUDY_VERSION}: "
                    + ",".join(COLUMNS[:4])
                    + ",..."
                )
            raise EyevizError(
                f"study table {name!r}: line 1: not a study table (header must be "
                + ",".join(COLUMNS[:4])
                + ",...)"
            )
        for fields in reader:
            line = reader.line_num
            if not fields or all(not c.strip() for c in fields):
                continue
            if len(fields) != len(COLUMNS):
                raise EyevizError(
                    f"line {line}: {len(fields)} fields, the header has {len(COLUMNS)}"
                )
            if len(rows) >= MAX_STUDY_ROWS:
                raise EyevizError(f"line {line}: more than {MAX_STUDY_ROWS} rows")
            row = _row(line, dict(zip(COLUMNS, fields, strict=True)))
            key = (*row.run, row.bin)
            if key in seen:
                raise EyevizError(f"line {line}: the same design point and bin as line {seen[key]}")
            seen[key] = line
            rows.append(row)
    except csv.Error as exc:
        raise EyevizError(f"study table {name!r}: line {reader.line_num}: {exc}") from None
    except EyevizError as exc:
        msg = str(exc)
        if not msg.startswith("study table"):
            msg = f"study table {name!r}: {msg}"
        raise EyevizError(msg) from None
    if not rows:
        raise EyevizError(f"study table {name!r} has a header but no rows")
    return rows
