"""The study table: one CSV row per design point and distance bin, appended atomically.

The header is :data:`~eyeviz.study.point.COLUMNS`; pandas reads the file as it is
(``pandas.read_csv(path)``). Rows are written by :func:`~eyeviz.study.point.evaluate`
(MAPE, Eq. 34; R^2, Eq. 35), a whole design point at a time: :meth:`StudyTable.append`
rewrites the file through :func:`eyeviz.files.atomic.atomic_output` (temporary file,
fsync, rename), so after Ctrl-C, a crash or a power loss at any moment the file holds
the points it held before or those plus the new one, never part of a point.

Reading never trusts the file: its size is bounded (:data:`MAX_STUDY_BYTES`), every line
is checked (field count, numbers, the design, the bins of each point) and the first bad
line is named. A file of another version (another header or version column) is refused
with one line and left as it is.
"""

from __future__ import annotations

import csv
import io
import math
import os
from collections.abc import Iterable
from dataclasses import dataclass, field
from pathlib import Path

from eyeviz import EyevizError
from eyeviz.core.bounds import MAX_BINS
from eyeviz.files.atomic import atomic_output
from eyeviz.files.limits import MAX_STUDY_BYTES, read_bounded
from eyeviz.study.point import BIN_WIDTH, COLUMNS, STUDY_VERSION, DesignPoint

__all__ = ["MAX_LINE_CHARS", "MAX_STUDY_BYTES", "StudyTable", "format_row", "read_rows"]

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


def _parse(where: str, values: list[str]) -> dict:
    row: dict = {}
    for name, text in zip(COLUMNS, values, strict=True):
        if name in _STR:
            row[name] = text
            continue
        if name in _METRICS and not text.strip():
            row[name] = math.nan  # pandas writes NaN as an empty field
            continue
        try:
            row[name] = int(text) if name in _INT else float(text)
        except ValueError:
            kind = "an integer" if name in _INT else "a number"
            raise EyevizError(f"{where}: {name} must be {kind}, got {text[:40]!r}") from None
    if row["version"] != STUDY_VERSION:
        raise EyevizError(
            f"{where}: written by study version {row['version']}, this is version "
            f"{STUDY_VERSION}; the file was left as it is (write to another -o)"
        )
    if row["bin"] != "all" and not (row["bin"].isdigit() and len(row["bin"]) <= 6):
        raise EyevizError(f"{where}: bin must be 'all' or a bin number, got {row['bin'][:40]!r}")
    for name in ("count", "flagged"):
        if row[name] < 0:
            raise EyevizError(f"{where}: {name} must be >= 0, got {row[name]}")
    try:
        point = DesignPoint(*(row[c] for c in _DESIGN))
    except (EyevizError, ValueError) as exc:
        raise EyevizError(f"{where}: {exc}") from None
    if _n_bins(point.r_min, point.r_max) > MAX_BINS:
        raise EyevizError(f"{where}: r_max - r_min gives more than {MAX_BINS} bins")
    row["_key"] = point.key
    return row


def read_rows(path, max_bytes: int = MAX_STUDY_BYTES) -> tuple[list[dict], list[str]]:
    """Parse a study table: its rows (typed, with a ``_key`` entry) and its raw lines.

    Raises a one-line :class:`EyevizError` naming the file and the first bad line: a
    header other than :data:`COLUMNS`, another version, a wrong field count, a
    non-number, an invalid design, a duplicate or incomplete design point.
    """
    name = str(path)
    data = read_bounded(path, max_bytes, "study table")
    if not data:
        return [], []
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        bad = data[: exc.start].count(b"\n") + 1
        raise EyevizError(f"{name} line {bad}: not UTF-8 text (byte {exc.start})") from None
    lines = text.split("\n")
    if lines and lines[-1] == "":
        lines.pop()
    lines = [s[:-1] if s.endswith("\r") else s for s in lines]
    if len(lines[0]) > MAX_LINE_CHARS:
        raise EyevizError(f"{name} line 1: not a study table (a line of {len(lines[0])} chars)")
    header = next(csv.reader([lines[0]]), [])
    if tuple(header) != COLUMNS:
        what = "another version of the study table" if "version" in header else "not a study table"
        raise EyevizError(
            f"{name}: {what} (its header is not version {STUDY_VERSION}'s); "
            "the file was left as it is (write to another -o)"
        )
    rows: list[dict] = []
    first_line: dict[tuple, int] = {}
    bins: dict[tuple, set[str]] = {}
    for i, line in enumerate(lines[1:], start=2):
        where = f"{name} line {i}"
        if len(line) > MAX_LINE_CHARS:
            raise EyevizError(f"{where}: longer than {MAX_LINE_CHARS} characters")
        if "\x00" in line:
            raise EyevizError(f"{where}: contains a NUL byte")
        values = next(csv.reader([line]), [])
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
        rows.append(row)
    for key, seen in bins.items():
        k = _n_bins(key[3], key[4])
        if seen != {"all", *map(str, range(k))}:
            raise EyevizError(
                f"{name} line {first_line[key]}: design point h={key[0]:g}, l={key[1]:g}, "
                f"m={key[2]} has {len(seen)} of its {k + 1} rows (an incomplete point)"
            )
    return rows, lines[1:]


@dataclass
class StudyTable:
    """A study table on disk and the points it holds; :meth:`append` adds one point."""

    path: Path
    lines: list[str] = field(default_factory=list)
    keys: set[tuple] = field(default_factory=set)

    @classmethod
    def open(cls, path) -> StudyTable:
        """Read ``path`` if it exists (checked, see :func:`read_rows`), else start empty.

        The folder must exist; nothing is written until the first :meth:`append`.
        """
        p = Path(path)
        d = p.parent if str(p.parent) else Path(".")
        if not d.is_dir():
            raise EyevizError(f"output directory does not exist: {str(d)!r}")
        if not os.path.lexists(p):
            return cls(p)
        rows, lines = read_rows(p)
        return cls(p, lines, {r["_key"] for r in rows})

    @property
    def finished(self) -> set[tuple]:
        """The :attr:`DesignPoint.key` of every point in the table."""
        return set(self.keys)

    def __contains__(self, point: DesignPoint) -> bool:
        return point.key in self.keys

    def append(self, rows: Iterable[dict]) -> None:
        """Add one design point's rows (from :func:`evaluate`): the whole file is
        rewritten to a temporary file, flushed to disk and renamed over the table."""
        rows = list(rows)
        if not rows:
            raise EyevizError("a design point without rows (a bug)")
        key = DesignPoint(*(rows[0][c] for c in _DESIGN)).key
        if any(DesignPoint(*(r[c] for c in _DESIGN)).key != key for r in rows):
            raise EyevizError("rows of several design points appended at once (a bug)")
        if key in self.keys:
            raise EyevizError(f"design point {key} is already in {self.path} (a bug)")
        new = [format_row(r) for r in rows]
        lines = self.lines + new
        with atomic_output(self.path) as tmp, open(tmp, "w", encoding="utf-8", newline="") as f:
            f.write(",".join(COLUMNS) + "\n")
            for line in lines:
                f.write(line + "\n")
            f.flush()
            os.fsync(f.fileno())
        self.lines = lines
        self.keys.add(key)
