"""The study tables: one CSV row per design point and bin, appended in place.

Both studies keep their results in a table of this one kind; what sets the planar table
(:data:`PLANAR`, header :data:`~eyeviz.study.point.COLUMNS`) apart from the 3D one
(:data:`eyeviz.study.table3d.TABLE3D`, header
:data:`~eyeviz.study.point3d.COLUMNS3D`) is a :class:`TableFormat`: its columns, its
version, its point type and its bins. The reader, the checks and the appender here serve
both (docs/study/README.md). pandas reads either file as it is (``pandas.read_csv(path)``).

Rows are written a whole design point at a time (:func:`~eyeviz.study.point.evaluate`,
MAPE Eq. 34, R^2 Eq. 35; :func:`~eyeviz.study.point3d.evaluate3d`):
:meth:`StudyTable.append` writes the first point with its header through
:func:`eyeviz.files.atomic.atomic_output` and appends each later point's lines to the
file (one write, fsync), cutting the file back to its former size should the write fail
or be interrupted; so after Ctrl-C or a full disk the file holds the points it held before
or those plus the new one, never part of a point (a power loss in the middle of one write
can leave a torn last point, which the reader names as an incomplete point). A symlinked
table is written through (the link stays a link) and a hard-linked one stays one file.

Reading never trusts the file: its size is bounded (:data:`MAX_STUDY_BYTES`), it is read
one line at a time, every line is checked by one parser (:func:`_parse`: field count,
ASCII numbers, the design, gamma = 2 pi / m, count <= n, flagged <= count, finite
non-negative metrics, R^2 <= 1, the bin's name and bounds) and the first bad line is
named. The runner and the report use the same parser, and every line is put through it
before it is written: a study never writes a table its own reader refuses. A file of
another version (another header or version column) is refused with one line and left as
it is.
"""

from __future__ import annotations

import contextlib
import csv
import io
import math
import os
import re
from collections.abc import Iterable, Iterator
from dataclasses import dataclass, field, fields
from pathlib import Path
from typing import Any, ClassVar

from eyeviz import EyevizError
from eyeviz.core.bounds import MAX_BINS
from eyeviz.files.atomic import atomic_output, full_disk_error
from eyeviz.files.limits import MAX_STUDY_BYTES, check_file_size
from eyeviz.study.point import BIN_WIDTH, COLUMNS, STUDY_VERSION, DesignPoint

__all__ = [
    "MAX_LINE_CHARS",
    "MAX_STUDY_BYTES",
    "PLANAR",
    "StudyTable",
    "TableFormat",
    "format_row",
    "iter_rows",
    "read_rows",
]

#: Longest line of a study table (a planar row is about 250 characters, a 3D one 300).
MAX_LINE_CHARS = 4096


@dataclass(frozen=True)
class TableFormat:
    """What sets one kind of study table apart; the reader, its checks and the appender
    of this module are shared.

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
        return frozenset(self.errors + self.r2)

    @property
    def header(self) -> bytes:
        return (",".join(self.columns) + "\n").encode("ascii")

    def bin_names(self) -> str:
        if self.el_bins:
            return f"'all', '{self.r_bin}<i>' or 'e<j>'"
        return "'all' or a bin number"

    def n_bins(self, point) -> int:
        """How many rows a point has: "all", its distance bins and elevation bins."""
        return 1 + _n_bins(point.r_min, point.r_max) + self.el_bins


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


def _n_bins(r_min: float, r_max: float) -> int:
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
    :func:`~eyeviz.study.point3d.elevation_bins`), no arrays."""
    return hi if i == k else lo + i * ((hi - lo) / k)


def _bin_range(fmt: TableFormat, where: str, point, b: str) -> tuple[float, float]:
    """The bounds a row of bin ``b`` must carry; a bin name of another form, or beyond
    the point's bins, is refused."""
    if b == "all":
        return point.r_min, point.r_max
    k = _n_bins(point.r_min, point.r_max)
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
    if not math.isclose(row["gamma"], 2 * math.pi / row["m"], rel_tol=1e-9):
        raise EyevizError(f"{where}: gamma = {row['gamma']:g} is not 2 pi / m for m = {row['m']}")
    count = row["count"]
    if count > row["n"]:
        raise EyevizError(f"{where}: count {count} exceeds n = {row['n']}")
    if row["flagged"] > count:
        raise EyevizError(f"{where}: flagged {row['flagged']} exceeds count = {count}")
    for col in (*fmt.errors, "seconds"):
        v = row[col]
        if not (math.isnan(v) or 0 <= v < math.inf) or (col == "seconds" and math.isnan(v)):
            raise EyevizError(f"{where}: column {col}: must be >= 0 and finite, got {v:g}")
    for col in fmt.r2:
        v = row[col]
        if not (math.isnan(v) or -math.inf < v <= 1):
            raise EyevizError(f"{where}: column {col}: must be finite and <= 1, got {v:g}")
    if count and any(math.isnan(row[col]) for col in fmt.errors):
        raise EyevizError(f"{where}: a bin with count > 0 needs {', '.join(fmt.errors)}")
    lo, hi = _bin_range(fmt, where, point, row["bin"])
    for col, want in zip(fmt.bounds, (lo, hi), strict=True):
        if not math.isclose(row[col], want, rel_tol=1e-9, abs_tol=1e-9):
            raise EyevizError(
                f"{where}: {col} = {row[col]:g} is not bin {row['bin']}'s edge {want:g}"
            )


def _parse(fmt: TableFormat, where: str, values: list[str]) -> tuple[dict, Any]:
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
    if _n_bins(point.r_min, point.r_max) > MAX_BINS:
        raise EyevizError(f"{where}: r_max - r_min gives more than {MAX_BINS} bins")
    _check_values(fmt, where, row, point)
    row["_key"] = point.key
    return row, point


def _line_of(name: str, i: int, raw: bytes) -> str:
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


def _fields(where: str, line: str) -> list[str]:
    try:
        return next(csv.reader([line]), [])
    except csv.Error as exc:  # e.g. a lone carriage return inside the line
        raise EyevizError(f"{where}: not a CSV line ({exc})") from None


def _check_header(fmt: TableFormat, name: str, line: str) -> None:
    header = tuple(_fields(f"{name} line 1", line))
    if header != fmt.columns:
        ours = header[: fmt.family] == fmt.columns[: fmt.family]
        what = f"another version of the {fmt.name}" if ours else f"not a {fmt.name}"
        raise EyevizError(
            f"{name}: {what} (its header is not version {fmt.version}'s); "
            "the file was left as it is (write to another -o)"
        )


def _describe(fmt: TableFormat, point) -> str:
    res = getattr(point, fmt.resolution)
    return f"h={point.h:g}, l={point.l:g}, {fmt.resolution}={res}"


def iter_rows(
    path, max_bytes: int = MAX_STUDY_BYTES, fmt: TableFormat = PLANAR
) -> Iterator[tuple[str, dict]]:
    """Stream a study table of kind ``fmt`` (the planar one by default): (raw line, typed
    row with ``_key`` and ``_line``) per data line, reading one line at a time (memory
    bounded by the longest line, not the file).

    Raises a one-line :class:`EyevizError` naming the file and the first bad line: a
    file larger than ``max_bytes``, a header other than ``fmt.columns``, another
    version, a wrong field count, a non-number, an invalid design or value (see
    :func:`_parse`), a duplicate or incomplete design point (checked at the end).
    """
    name = str(path)
    size = check_file_size(path, max_bytes, fmt.name)
    width = len(fmt.columns)
    # per point: the line of its first row, its rows' bins, how many it must have, a name
    points: dict[tuple, tuple[int, set[str], int, str]] = {}
    read = 0
    with open(path, "rb") as f:
        for i, raw in enumerate(iter(lambda: f.readline(MAX_LINE_CHARS + 2), b""), start=1):
            read += len(raw)
            if read > max(size, max_bytes):
                raise EyevizError(f"{fmt.name} {name!r} is larger than {max_bytes} bytes")
            if i == 1:
                head = raw.rstrip(b"\n")
                if len(head) > MAX_LINE_CHARS:
                    raise EyevizError(
                        f"{name} line 1: not a {fmt.name} (a line of {len(head)}+ chars)"
                    )
                _check_header(fmt, name, _line_of(name, 1, head))
                continue
            line = _line_of(name, i, raw[:-1] if raw.endswith(b"\n") else raw)
            where = f"{name} line {i}"
            values = _fields(where, line)
            if len(values) != width:
                raise EyevizError(f"{where}: {len(values)} fields, expected {width}")
            row, point = _parse(fmt, where, values)
            key = row["_key"]
            if key not in points:
                points[key] = (i, set(), fmt.n_bins(point), _describe(fmt, point))
            seen = points[key][1]
            if row["bin"] in seen:
                raise EyevizError(f"{where}: bin {row['bin']} of this design point appears twice")
            seen.add(row["bin"])
            row["_line"] = i
            yield line, row
    # every bin named is one of the point's (_bin_range) and none twice: a point is
    # whole when it has as many rows as bins
    for first, seen, want, what in points.values():
        if len(seen) != want:
            raise EyevizError(
                f"{name} line {first}: design point {what} has {len(seen)} of its {want} "
                "rows (an incomplete point)"
            )


def read_rows(
    path, max_bytes: int = MAX_STUDY_BYTES, fmt: TableFormat = PLANAR
) -> tuple[list[dict], list[str]]:
    """A whole study table: its rows (typed, with ``_key`` and ``_line``) and its raw
    data lines; the checks and errors of :func:`iter_rows`."""
    rows: list[dict] = []
    lines: list[str] = []
    for line, row in iter_rows(path, max_bytes, fmt):
        lines.append(line)
        rows.append(row)
    return rows, lines


@dataclass
class StudyTable:
    """A study table on disk and the points it holds; :meth:`append` adds one point.

    Holds the points' keys and the file's size, never its lines: appending writes only
    the new point's lines (memory bounded by one point). The planar study's table; the
    3D study's (:class:`eyeviz.study.table3d.StudyTable3D`) is this with another
    :attr:`fmt`."""

    fmt: ClassVar[TableFormat] = PLANAR

    path: Path
    keys: set[tuple] = field(default_factory=set)
    size: int = 0
    max_bytes: int = MAX_STUDY_BYTES

    @classmethod
    def open(cls, path, max_bytes: int | None = None):
        """Read ``path`` if it exists (checked, see :func:`iter_rows`), else start empty.

        The folder must exist; nothing is written until the first :meth:`append`. A
        symlink is followed (a dangling one: an empty table, written at its target).
        ``max_bytes``: the bound for reading and for appending (default
        :data:`MAX_STUDY_BYTES`, the reader's).
        """
        if max_bytes is None:
            max_bytes = MAX_STUDY_BYTES
        p = Path(path)
        d = Path(os.path.realpath(p)).parent if p.is_symlink() else p.parent  # written there
        if not d.is_dir():
            raise EyevizError(f"output directory does not exist: {str(d)!r}")
        try:
            os.stat(p)
        except FileNotFoundError:  # no file, or a link to none yet
            return cls(p, max_bytes=max_bytes)
        except OSError:
            pass  # a loop of links, no permission...: the reader names it
        keys = {row["_key"] for _, row in iter_rows(p, max_bytes, cls.fmt)}
        return cls(p, keys, os.stat(p).st_size, max_bytes)

    @property
    def finished(self) -> set[tuple]:
        """The ``key`` of every point in the table."""
        return set(self.keys)

    def __contains__(self, point) -> bool:
        kind: Any = self.fmt.point
        return isinstance(point, kind) and point.key in self.keys

    def _encoded(self, rows: list[dict]) -> tuple[tuple, bytes]:
        """The point's key and its lines, each checked by the table's own parser (a study
        never writes a line its reader refuses)."""
        fmt = self.fmt
        out = []
        seen: set[str] = set()
        keys: set[tuple] = set()
        point = None
        for r in rows:
            line = format_row(r, fmt.columns)
            where = f"{self.path}: the new point's row for bin {str(r.get('bin', '?'))[:10]}"
            if len(line) > MAX_LINE_CHARS:
                raise EyevizError(f"{where} is longer than {MAX_LINE_CHARS} characters")
            row, point = _parse(fmt, where, _fields(where, line))
            keys.add(row["_key"])
            seen.add(row["bin"])
            out.append(line + "\n")
        if len(keys) != 1:
            raise EyevizError("rows of several design points appended at once (a bug)")
        (key,) = keys
        if key in self.keys:
            raise EyevizError(f"design point {key} is already in {self.path} (a bug)")
        want = fmt.n_bins(point)
        if len(seen) != want or len(rows) != want:
            raise EyevizError(f"{self.path}: the new point has not its {want} bins (a bug)")
        return key, "".join(out).encode("utf-8")

    def append(self, rows: Iterable[dict]) -> None:
        """Add one design point's rows, every line checked first.

        A new file is written whole (header and point) through ``atomic_output``; an
        existing one gets only the point's lines, appended in one write and flushed to
        disk. Should that fail (an interruption, a full disk), the file is cut back to
        its former size: it holds whole points only. A point that would take the file
        past ``max_bytes`` (the most its reader accepts) is refused with one line, before
        anything is written.
        """
        rows = list(rows)
        if not rows:
            raise EyevizError("a design point without rows (a bug)")
        key, data = self._encoded(rows)
        fresh = self.size == 0
        head = self.fmt.header if fresh else b""
        if self.size + len(head) + len(data) > self.max_bytes:
            raise EyevizError(
                f"{self.path}: the next point would take the table past {self.max_bytes} "
                f"bytes, the most its reader accepts; stopped with {len(self.keys)} "
                "point(s) kept (write further points to another -o)"
            )
        if fresh:
            with atomic_output(self.path) as tmp, open(tmp, "wb") as f:
                f.write(head + data)
                f.flush()
                os.fsync(f.fileno())
        else:
            self._append_bytes(data)
        self.size += len(head) + len(data)
        self.keys.add(key)

    def _append_bytes(self, data: bytes) -> None:
        target = os.path.realpath(self.path)
        fd = os.open(target, os.O_WRONLY | os.O_APPEND)
        try:
            end = os.fstat(fd).st_size
            if end != self.size:
                raise EyevizError(
                    f"{self.path} changed size while the study ran ({self.size} -> {end} "
                    "bytes); the point was not appended"
                )
            try:
                view = memoryview(data)
                while view:
                    view = view[os.write(fd, view) :]
                os.fsync(fd)
            except BaseException as exc:
                with contextlib.suppress(OSError):
                    os.ftruncate(fd, end)
                full = full_disk_error(self.path, exc) if isinstance(exc, OSError) else None
                if full is not None:
                    raise full from exc
                raise
        finally:
            os.close(fd)
