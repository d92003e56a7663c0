"""The study tables' format and its one parser (planar and 3D).

What sets the planar table (:data:`PLANAR`, header :data:`~eyeviz.study.point.COLUMNS`)
apart from the 3D one (:data:`TABLE3D`, header
:data:`~eyeviz.study.point.COLUMNS3D`) is a :class:`TableFormat`: its columns, its
version, its point type and its bins. Everything else is shared (docs/study/README.md):
how a row is written (:func:`format_row`: repr floats that round-trip, nan as pandas reads
it) and how a line is read and checked (:func:`parse_fields`: field count, ASCII numbers,
the design through the point type's own checks, m = 4 nside for a 3D row, gamma = 2 pi /
m, count <= n, flagged <= count, finite non-negative errors, R^2 <= 1, the bin's name and
bounds), every failure one line naming the file and the line. The reader and the
appender of :mod:`eyeviz.study.table` use it for both kinds, so the runner's resume and
``eyeviz report study`` refuse the same edit in the same words.
"""

from __future__ import annotations

import csv
import io
import math
import re
from dataclasses import dataclass, fields
from typing import Any

from eyeviz import EyevizError
from eyeviz.core.bounds import MAX_BINS
from eyeviz.core.validation import num
from eyeviz.study.point import (
    BIN_WIDTH,
    COLUMNS,
    COLUMNS3D,
    EL_BINS,
    STUDY3D_VERSION,
    STUDY_VERSION,
    DesignPoint,
    DesignPoint3D,
)

__all__ = [
    "MAX_LINE_CHARS",
    "PLANAR",
    "TableFormat",
    "check_header",
    "decode_line",
    "format_row",
    "parse_fields",
    "split_fields",
]

#: Longest line of a study table (a planar row is about 250 characters, a 3D one 300).
MAX_LINE_CHARS = 4096
#: The largest error a study row may report (percent, or degrees): a distance answered
#: 10^10 times too far. ``dd_mape = 1e308`` passed and broke the report's axes ("arange:
#: cannot compute length", issue 36); an error above this is no measurement.
MAX_ERROR = 1e12
#: The most negative R^2 a row may report (R^2 = 1 - SS_res / SS_tot; below this the
#: answers are as far off as MAX_ERROR).
MIN_R2 = -1e30


@dataclass(frozen=True)
class TableFormat:
    """What sets one kind of study table apart; the parser of this module and the reader
    and appender of :mod:`eyeviz.study.table` are shared.

    Every kind has the columns version, h, l, m, gamma, r_min, r_max, prior, n, seed,
    bin, count, flagged and seconds, the bin's bounds (:attr:`bounds`), non-negative
    error metrics (:attr:`errors`) and R^2 columns (:attr:`r2`). Its bins are "all"
    (r_min to r_max), the distance bins of :data:`~eyeviz.study.point.BIN_WIDTH`
    (:attr:`r_bin` followed by the bin's number) and, when :attr:`el_bins` > 0, as many
    equal elevation bins of [-el_max, el_max] ("e" and the number).
    """

    #: "study table", "3D study table": how its messages name a file of this kind.
    name: str
    #: "study", "3D study": who wrote a version (the version column's message).
    study: str
    columns: tuple[str, ...]
    version: int
    #: The point type (a dataclass), built from the columns of its fields' names: its
    #: checks are the file's.
    point: type
    #: The columns that set the number of facets: "m", or "nside" (m = 4 nside).
    resolution: str
    ints: frozenset[str]
    strs: frozenset[str]
    errors: tuple[str, ...]
    r2: tuple[str, ...]
    bounds: tuple[str, str]
    r_bin: str = ""
    el_bins: int = 0
    #: Standard errors of error metrics: >= 0 and finite, or NaN (a bin of one element
    #: has no spread to measure).
    ses: tuple[str, ...] = ()
    #: The header's first columns, which tell another version of this kind from another
    #: kind of file.
    family: int = 4

    @property
    def design(self) -> tuple[str, ...]:
        """The columns that make a point: its type's fields, in order."""
        return tuple(f.name for f in fields(self.point))

    @property
    def metrics(self) -> frozenset[str]:
        """Columns a bin may leave empty (pandas writes NaN as an empty field)."""
        return frozenset(self.errors + self.r2 + self.ses)

    @property
    def header(self) -> bytes:
        return (",".join(self.columns) + "\n").encode("ascii")

    def bin_names(self) -> str:
        if self.el_bins:
            return f"'all', '{self.r_bin}<i>' or 'e<j>'"
        return "'all' or a bin number"

    def describe(self, point) -> str:
        """A point as messages name it: "h=40, l=20, m=180" or "..., nside=180"."""
        res = getattr(point, self.resolution)
        return f"h={num(point.h)}, l={num(point.l)}, {self.resolution}={res}"

    def rows_per_point(self, point) -> int:
        """How many rows a point has: "all", its distance bins and elevation bins."""
        return 1 + _distance_bins(point.r_min, point.r_max) + self.el_bins


#: The planar study's table (:mod:`eyeviz.study.point`).
PLANAR = TableFormat(
    name="study table",
    study="study",
    columns=COLUMNS,
    version=STUDY_VERSION,
    point=DesignPoint,
    resolution="m",
    ints=frozenset({"version", "m", "n", "seed", "count", "flagged"}),
    strs=frozenset({"prior", "bin"}),
    errors=("dd_mape", "ad_mape"),
    r2=("dd_r2", "ad_r2"),
    bounds=("r_lo", "r_hi"),
)

#: The 3D study's table (:mod:`eyeviz.study.point`).
TABLE3D = TableFormat(
    name="3D study table",
    study="3D study",
    columns=COLUMNS3D,
    version=STUDY3D_VERSION,
    point=DesignPoint3D,
    resolution="nside",
    ints=frozenset({"version", "nside", "m", "n", "seed", "count", "flagged"}),
    strs=frozenset({"prior", "estimator", "bin"}),
    errors=("dd_mape", "ad_mape", "el_mae_deg", "az_mae_deg"),
    r2=("dd_r2", "ad_r2", "el_r2"),
    bounds=("lo", "hi"),
    r_bin="r",
    el_bins=EL_BINS,
    ses=("dd_se", "el_se"),
)


def _fmt(value) -> str:
    if isinstance(value, bool):
        return str(int(value))
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        return repr(value)  # round-trips exactly; nan and inf as pandas reads them
    return str(value)


def format_row(row: dict, columns: tuple[str, ...] = COLUMNS) -> str:
    """One CSV line (no newline) of a study row, in ``columns`` order (the planar
    table's by default)."""
    buf = io.StringIO()
    csv.writer(buf, lineterminator="").writerow([_fmt(row[c]) for c in columns])
    return buf.getvalue()


def _distance_bins(r_min: float, r_max: float) -> int:
    """How many distance bins :func:`~eyeviz.study.point.distance_bins` makes (no arrays)."""
    return max(1, int(math.ceil((r_max - r_min) / BIN_WIDTH - 1e-9)))


#: A number as the study writes it: ASCII digits only (no "1_000", no Arabic-Indic or
#: full-width digits, which ``int`` and ``float`` accept), nan and inf as Python spells them.
_INT_TEXT = re.compile(r"[+-]?[0-9]{1,19}")
_FLOAT_TEXT = re.compile(
    r"[+-]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][+-]?[0-9]{1,4})?|[+-]?(?:nan|inf|infinity)",
    re.IGNORECASE,
)


def _number(where: str, name: str, text: str, integer: bool):
    if integer:
        if not _INT_TEXT.fullmatch(text):
            raise EyevizError(f"{where}: {name} must be an integer, got {text[:40]!r}")
        return int(text)
    if not _FLOAT_TEXT.fullmatch(text):
        raise EyevizError(f"{where}: {name} must be a number, got {text[:40]!r}")
    return float(text)


def _edge(lo: float, hi: float, k: int, i: int) -> float:
    """Edge i of ``numpy.linspace(lo, hi, k + 1)`` (the bins of
    :func:`~eyeviz.study.point.distance_bins` and
    :func:`~eyeviz.study.point.elevation_bins`), no arrays."""
    return hi if i == k else lo + i * ((hi - lo) / k)


def _bin_range(fmt: TableFormat, where: str, point, b: str) -> tuple[float, float]:
    """The bounds a row of bin ``b`` must carry; a bin name of another form, or beyond
    the point's bins, is refused."""
    if b == "all":
        return point.r_min, point.r_max
    k = _distance_bins(point.r_min, point.r_max)
    spans = [(fmt.r_bin, k, point.r_min, point.r_max, "[r_min, r_max]")]
    if fmt.el_bins:
        spans.append(("e", fmt.el_bins, -point.el_max, point.el_max, "[-el_max, el_max]"))
    for prefix, n, lo, hi, span in spans:
        digits = b[len(prefix) :]
        if b.startswith(prefix) and digits.isascii() and digits.isdigit() and len(digits) <= 6:
            i = int(digits)
            if b != f"{prefix}{i}":  # one spelling per bin: "r1", never "r01"
                break
            if i >= n:
                raise EyevizError(f"{where}: bin {b} beyond the {n} bins of {span}")
            return _edge(lo, hi, n, i), _edge(lo, hi, n, i + 1)
    raise EyevizError(f"{where}: bin must be {fmt.bin_names()}, got {b[:40]!r}")


def _check_values(fmt: TableFormat, where: str, row: dict, point) -> None:
    """What the report's figures rely on, for the runner and the report alike."""
    if row["m"] != point.m:  # a 3D row's m is 4 nside; a planar one's is the design's
        raise EyevizError(f"{where}: m = {row['m']} is not 4 nside = {point.m}")
    gamma = getattr(point, "gamma", None)  # a measured pair's: its interommatidial angle
    if gamma is not None:
        if not math.isclose(row["gamma"], gamma, rel_tol=1e-9):
            raise EyevizError(f"{where}: gamma = {row['gamma']:g} is not the eyes' {gamma:g}")
    elif not math.isclose(row["gamma"], 2 * math.pi / row["m"], rel_tol=1e-9):
        raise EyevizError(f"{where}: gamma = {row['gamma']:g} is not 2 pi / m for m = {row['m']}")
    count = row["count"]
    if count > row["n"]:
        raise EyevizError(f"{where}: count {count} exceeds n = {row['n']}")
    if row["flagged"] > count:
        raise EyevizError(f"{where}: flagged {row['flagged']} exceeds count = {count}")
    for col in (*fmt.errors, *fmt.ses, "seconds"):
        v = row[col]
        if not (math.isnan(v) or 0 <= v < math.inf) or (col == "seconds" and math.isnan(v)):
            raise EyevizError(f"{where}: column {col}: must be >= 0 and finite, got {v:g}")
        if col != "seconds" and v > MAX_ERROR:
            raise EyevizError(
                f"{where}: column {col}: {v:g} is no error a study measures (at most {MAX_ERROR:g})"
            )
    for col in fmt.r2:
        v = row[col]
        if not (math.isnan(v) or MIN_R2 <= v <= 1):
            raise EyevizError(
                f"{where}: column {col}: must be within [{MIN_R2:g}, 1] (an R^2), got {v:g}"
            )
    if count and any(math.isnan(row[col]) for col in fmt.errors):
        raise EyevizError(f"{where}: a bin with count > 0 needs {', '.join(fmt.errors)}")
    lo, hi = _bin_range(fmt, where, point, row["bin"])
    for col, want in zip(fmt.bounds, (lo, hi), strict=True):
        if not math.isclose(row[col], want, rel_tol=1e-9, abs_tol=1e-9):
            raise EyevizError(
                f"{where}: {col} = {row[col]:g} is not bin {row['bin']}'s edge {want:g}"
            )


def parse_fields(fmt: TableFormat, where: str, values: list[str]) -> tuple[dict, Any]:
    """One data line's fields as a typed row (with ``_key``) and its design point; every
    check the runner and the report rely on (the one parser of the study tables), raising
    one line naming ``where``."""
    row: dict = {}
    for name, text in zip(fmt.columns, values, strict=True):
        if name in fmt.strs:
            row[name] = text
        elif name in fmt.metrics and not text.strip():
            row[name] = math.nan  # pandas writes NaN as an empty field
        else:
            row[name] = _number(where, name, text, name in fmt.ints)
    if row["version"] != fmt.version:
        raise EyevizError(
            f"{where}: written by {fmt.study} version {row['version']}, this is version "
            f"{fmt.version}; the file was left as it is (write to another -o)"
        )
    for name in ("count", "flagged"):
        if row[name] < 0:
            raise EyevizError(f"{where}: {name} must be >= 0, got {row[name]}")
    try:
        point = fmt.point(*(row[c] for c in fmt.design))
    except (EyevizError, ValueError, TypeError) as exc:
        raise EyevizError(f"{where}: {exc}") from None
    if _distance_bins(point.r_min, point.r_max) > MAX_BINS:
        raise EyevizError(f"{where}: r_max - r_min gives more than {MAX_BINS} bins")
    _check_values(fmt, where, row, point)
    row["_key"] = point.key
    return row, point


def decode_line(name: str, i: int, raw: bytes) -> str:
    """Line ``i`` of file ``name`` as text (no newline): at most :data:`MAX_LINE_CHARS`
    bytes of UTF-8 without NUL, else one line naming file and line."""
    where = f"{name} line {i}"
    if len(raw) > MAX_LINE_CHARS:
        raise EyevizError(f"{where}: longer than {MAX_LINE_CHARS} characters")
    try:
        line = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise EyevizError(f"{where}: not UTF-8 text (byte {exc.start})") from None
    if line.endswith("\r"):
        line = line[:-1]
    if "\x00" in line:
        raise EyevizError(f"{where}: contains a NUL byte")
    return line


def split_fields(where: str, line: str) -> list[str]:
    """A line's CSV fields (csv's own errors as one line naming ``where``)."""
    try:
        return next(csv.reader([line]), [])
    except csv.Error as exc:  # e.g. a lone carriage return inside the line
        raise EyevizError(f"{where}: not a CSV line ({exc})") from None


def check_header(fmt: TableFormat, name: str, line: str) -> None:
    """Refuse, in one line, a first line other than ``fmt``'s header: another version of
    this kind (the same first :attr:`TableFormat.family` columns) or another file."""
    header = tuple(split_fields(f"{name} line 1", line))
    if header != fmt.columns:
        ours = header[: fmt.family] == fmt.columns[: fmt.family]
        what = f"another version of the {fmt.name}" if ours else f"not a {fmt.name}"
        raise EyevizError(
            f"{name}: {what} (its header is not version {fmt.version}'s); "
            "the file was left as it is (write to another -o)"
        )
