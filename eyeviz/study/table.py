"""The study table: one CSV row per design point and distance bin, appended in place.

The header is :data:`~eyeviz.study.point.COLUMNS`; pandas reads the file as it is
(``pandas.read_csv(path)``). Rows are written by :func:`~eyeviz.study.point.evaluate`
(MAPE, Eq. 34; R^2, Eq. 35), a whole design point at a time: :meth:`StudyTable.append`
writes the first point with its header through :func:`eyeviz.files.atomic.atomic_output`
and appends each later point's lines to the file (one write, fsync), cutting the file
back to its former size should the write fail or be interrupted; so after Ctrl-C or a
full disk the file holds the points it held before or those plus the new one, never part
of a point (a power loss in the middle of one write can leave a torn last point, which
the reader names as an incomplete point).

Reading never trusts the file: its size is bounded (:data:`MAX_STUDY_BYTES`), it is read
one line at a time, every line is checked by one parser (:func:`_parse`: field count,
ASCII numbers, the design, gamma = 2 pi / m, count <= n, finite non-negative metrics, the
bin's bounds) and the first bad line is named. The runner and the report use the same
parser, and every line is put through it before it is written: a study never writes a
table its own reader refuses. A file of another version (another header or version
column) is refused with one line and left as it is.
"""

from __future__ import annotations

import contextlib
import csv
import io
import math
import os
import re
from collections.abc import Iterable, Iterator
from dataclasses import dataclass, field
from pathlib import Path

from eyeviz import EyevizError
from eyeviz.core.bounds import MAX_BINS
from eyeviz.files.atomic import atomic_output, full_disk_error
from eyeviz.files.limits import MAX_STUDY_BYTES, check_file_size
from eyeviz.study.point import BIN_WIDTH, COLUMNS, STUDY_VERSION, DesignPoint

__all__ = [
    "MAX_LINE_CHARS",
    "MAX_STUDY_BYTES",
    "StudyTable",
    "format_row",
    "iter_rows",
    "read_rows",
]

#: Longest line of a study table (a row is about 250 characters).
MAX_LINE_CHARS = 4096

_INT = frozenset({"version", "m", "n", "seed", "count", "flagged"})
_STR = frozenset({"prior", "bin"})
_METRICS = frozenset({"dd_mape", "ad_mape", "dd_r2", "ad_r2"})
_DESIGN = ("h", "l", "m", "r_min", "r_max", "g_max", "prior", "n", "seed")


def _fmt(value) -> str:
    if isinstance(value, bool):
        return str(int(value))
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        return repr(value)  # round-trips exactly; nan and inf as pandas reads them
    return str(value)


def format_row(row: dict) -> str:
    """One CSV line (no newline) of a study row, in :data:`COLUMNS` order."""
    buf = io.StringIO()
    csv.writer(buf, lineterminator="").writerow([_fmt(row[c]) for c in COLUMNS])
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


def _number(where: str, name: str, text: str):
    if name in _INT:
        if not _INT_TEXT.fullmatch(text):
            raise EyevizError(f"{where}: {name} must be an integer, got {text[:40]!r}")
        return int(text)
    if not _FLOAT_TEXT.fullmatch(text):
        raise EyevizError(f"{where}: {name} must be a number, got {text[:40]!r}")
    return float(text)


def _edge(r_min: float, r_max: float, k: int, i: int) -> float:
    """Edge i of :func:`~eyeviz.study.point.distance_bins` (numpy's linspace, no arrays)."""
    return r_max if i == k else r_min + i * ((r_max - r_min) / k)


def _check_values(where: str, row: dict, point: DesignPoint) -> None:
    """What the report's figures rely on, for the runner and the report alike."""
    if not math.isclose(row["gamma"], 2 * math.pi / row["m"], rel_tol=1e-9):
        raise EyevizError(f"{where}: gamma = {row['gamma']:g} is not 2 pi / m for m = {row['m']}")
    count = row["count"]
    if count > row["n"]:
        raise EyevizError(f"{where}: count {count} exceeds n = {row['n']}")
    if row["flagged"] > count:
        raise EyevizError(f"{where}: flagged {row['flagged']} exceeds count = {count}")
    for col in ("dd_mape", "ad_mape", "seconds"):
        v = row[col]
        if not (math.isnan(v) or 0 <= v < math.inf) or (col == "seconds" and math.isnan(v)):
            raise EyevizError(f"{where}: column {col}: must be >= 0 and finite, got {v:g}")
    for col in ("dd_r2", "ad_r2"):
        v = row[col]
        if not (math.isnan(v) or -math.inf < v <= 1):
            raise EyevizError(f"{where}: column {col}: must be finite and <= 1, got {v:g}")
    if count and (math.isnan(row["dd_mape"]) or math.isnan(row["ad_mape"])):
        raise EyevizError(f"{where}: a bin with count > 0 needs dd_mape and ad_mape")
    k = _n_bins(point.r_min, point.r_max)
    if row["bin"] == "all":
        lo, hi = point.r_min, point.r_max
    else:
        i = int(row["bin"])
        if i >= k:
            raise EyevizError(f"{where}: bin {i} beyond the {k} bins of [r_min, r_max]")
        lo, hi = _edge(point.r_min, point.r_max, k, i), _edge(point.r_min, point.r_max, k, i + 1)
    for col, want in (("r_lo", lo), ("r_hi", hi)):
        if not math.isclose(row[col], want, rel_tol=1e-9, abs_tol=1e-9):
            raise EyevizError(
                f"{where}: {col} = {row[col]:g} is not bin {row['bin']}'s edge {want:g}"
            )


def _parse(where: str, values: list[str]) -> dict:
    """One data line's fields as a typed row; every check the runner and the report rely
    on (the one parser of the study table), raising one line naming ``where``."""
    row: dict = {}
    for name, text in zip(COLUMNS, values, strict=True):
        if name in _STR:
            row[name] = text
            continue
        if name in _METRICS and not text.strip():
            row[name] = math.nan  # pandas writes NaN as an empty field
            continue
        row[name] = _number(where, name, text)
    if row["version"] != STUDY_VERSION:
        raise EyevizError(
            f"{where}: written by study version {row['version']}, this is version "
            f"{STUDY_VERSION}; the file was left as it is (write to another -o)"
        )
    b = row["bin"]
    if b != "all" and not (b.isascii() and b.isdigit() and len(b) <= 6):
        raise EyevizError(f"{where}: bin must be 'all' or a bin number, got {b[:40]!r}")
    for name in ("count", "flagged"):
        if row[name] < 0:
            raise EyevizError(f"{where}: {name} must be >= 0, got {row[name]}")
    try:
        point = DesignPoint(*(row[c] for c in _DESIGN))
    except (EyevizError, ValueError) as exc:
        raise EyevizError(f"{where}: {exc}") from None
    if _n_bins(point.r_min, point.r_max) > MAX_BINS:
        raise EyevizError(f"{where}: r_max - r_min gives more than {MAX_BINS} bins")
    _check_values(where, row, point)
    row["_key"] = point.key
    return row


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


def _check_header(name: str, line: str) -> None:
    header = _fields(f"{name} line 1", line)
    if tuple(header) != COLUMNS:
        what = "another version of the study table" if "version" in header else "not a study table"
        raise EyevizError(
            f"{name}: {what} (its header is not version {STUDY_VERSION}'s); "
            "the file was left as it is (write to another -o)"
        )


def iter_rows(path, max_bytes: int = MAX_STUDY_BYTES) -> Iterator[tuple[str, dict]]:
    """Stream a study table: (raw line, typed row with ``_key`` and ``_line``) per data
    line, reading one line at a time (memory bounded by the longest line, not the file).

    Raises a one-line :class:`EyevizError` naming the file and the first bad line: a
    file larger than ``max_bytes``, a header other than :data:`COLUMNS`, another
    version, a wrong field count, a non-number, an invalid design or value (see
    :func:`_parse`), a duplicate or incomplete design point (checked at the end).
    """
    name = str(path)
    size = check_file_size(path, max_bytes, "study table")
    first_line: dict[tuple, int] = {}
    bins: dict[tuple, set[str]] = {}
    read = 0
    with open(path, "rb") as f:
        for i, raw in enumerate(iter(lambda: f.readline(MAX_LINE_CHARS + 2), b""), start=1):
            read += len(raw)
            if read > max(size, max_bytes):
                raise EyevizError(f"study table {name!r} is larger than {max_bytes} bytes")
            if i == 1:
                head = raw.rstrip(b"\n")
                if len(head) > MAX_LINE_CHARS:
                    raise EyevizError(
                        f"{name} line 1: not a study table (a line of {len(head)}+ chars)"
                    )
                _check_header(name, _line_of(name, 1, head))
                continue
            line = _line_of(name, i, raw[:-1] if raw.endswith(b"\n") else raw)
            where = f"{name} line {i}"
            values = _fields(where, line)
            if len(values) != len(COLUMNS):
                raise EyevizError(f"{where}: {len(values)} fields, expected {len(COLUMNS)}")
            row = _parse(where, values)
            key = row["_key"]
            seen = bins.setdefault(key, set())
            first_line.setdefault(key, i)
            if row["bin"] in seen:
                raise EyevizError(f"{where}: bin {row['bin']} of this design point appears twice")
            seen.add(row["bin"])
            row["_line"] = i
            yield line, row
    for key, seen in bins.items():
        k = _n_bins(key[3], key[4])
        if seen != {"all", *map(str, range(k))}:
            raise EyevizError(
                f"{name} line {first_line[key]}: design point h={key[0]:g}, l={key[1]:g}, "
                f"m={key[2]} has {len(seen)} of its {k + 1} rows (an incomplete point)"
            )


def read_rows(path, max_bytes: int = MAX_STUDY_BYTES) -> tuple[list[dict], list[str]]:
    """A whole study table: its rows (typed, with ``_key`` and ``_line``) and its raw
    data lines; the checks and errors of :func:`iter_rows`."""
    rows: list[dict] = []
    lines: list[str] = []
    for line, row in iter_rows(path, max_bytes):
        lines.append(line)
        rows.append(row)
    return rows, lines


@dataclass
class StudyTable:
    """A study table on disk and the points it holds; :meth:`append` adds one point.

    Holds the points' keys and the file's size, never its lines: appending writes only
    the new point's lines (memory bounded by one point)."""

    path: Path
    keys: set[tuple] = field(default_factory=set)
    size: int = 0
    max_bytes: int = MAX_STUDY_BYTES

    @classmethod
    def open(cls, path, max_bytes: int | None = None) -> StudyTable:
        """Read ``path`` if it exists (checked, see :func:`iter_rows`), else start empty.

        The folder must exist; nothing is written until the first :meth:`append`.
        ``max_bytes``: the bound for reading and for appending (default
        :data:`MAX_STUDY_BYTES`, the reader's).
        """
        if max_bytes is None:
            max_bytes = MAX_STUDY_BYTES
        p = Path(path)
        d = p.parent if str(p.parent) else Path(".")
        if not d.is_dir():
            raise EyevizError(f"output directory does not exist: {str(d)!r}")
        if not os.path.lexists(p):
            return cls(p, max_bytes=max_bytes)
        keys = {row["_key"] for _, row in iter_rows(p, max_bytes)}
        return cls(p, keys, os.stat(p).st_size, max_bytes)

    @property
    def finished(self) -> set[tuple]:
        """The :attr:`DesignPoint.key` of every point in the table."""
        return set(self.keys)

    def __contains__(self, point: DesignPoint) -> bool:
        return point.key in self.keys

    def _encoded(self, rows: list[dict]) -> tuple[tuple, bytes]:
        """The point's key and its lines, each checked by the table's own parser (a study
        never writes a line its reader refuses)."""
        key = DesignPoint(*(rows[0][c] for c in _DESIGN)).key
        if any(DesignPoint(*(r[c] for c in _DESIGN)).key != key for r in rows):
            raise EyevizError("rows of several design points appended at once (a bug)")
        if key in self.keys:
            raise EyevizError(f"design point {key} is already in {self.path} (a bug)")
        out = []
        seen = set()
        for r in rows:
            line = format_row(r)
            where = f"{self.path}: the new point's row for bin {str(r.get('bin', '?'))[:10]}"
            if len(line) > MAX_LINE_CHARS:
                raise EyevizError(f"{where} is longer than {MAX_LINE_CHARS} characters")
            row = _parse(where, next(csv.reader([line])))
            seen.add(row["bin"])
            out.append(line + "\n")
        k = _n_bins(key[3], key[4])
        if seen != {"all", *map(str, range(k))} or len(rows) != k + 1:
            raise EyevizError(f"{self.path}: the new point has not its {k + 1} bins (a bug)")
        return key, "".join(out).encode("utf-8")

    def append(self, rows: Iterable[dict]) -> None:
        """Add one design point's rows (from :func:`evaluate`), every line checked first.

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
        fresh = not os.path.lexists(self.path) or self.size == 0
        head = (",".join(COLUMNS) + "\n").encode("ascii") if fresh else b""
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
