"""The 3D study table: one CSV row per 3D design point and bin, appended atomically.

Its header is :data:`~eyeviz.study.point3d.COLUMNS3D` (the planar table's header is
another, so neither reader takes the other's file, and :func:`is_table3d` tells them
apart from the first line); pandas reads it as it is. Rows are written by
:func:`~eyeviz.study.point3d.evaluate3d` a whole design point at a time; :meth:`append`
writes the file through :func:`eyeviz.files.atomic.atomic_output` (temporary file, fsync,
rename), so after Ctrl-C, a crash or a power loss the file holds the points it held
before or those plus the new one, never part of a point. (A point is 21 rows at the
default ranges: even a 10^4-point study is a few MB.)

Reading never trusts the file: its size is bounded (:data:`MAX_STUDY_BYTES`), every line
is checked (field count, numbers, the design, gamma = 2 pi / (4 nside), m = 4 nside,
count <= n, finite non-negative errors, the bins of each point) and the first bad line
is named. A file of another version is refused with one line and left as it is.
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
from eyeviz.study.point import BIN_WIDTH
from eyeviz.study.point3d import COLUMNS3D, EL_BINS, STUDY3D_VERSION, DesignPoint3D

__all__ = ["MAX_STUDY_BYTES", "StudyTable3D", "expected_bins", "is_table3d", "read_rows3d"]

#: Longest line of a 3D study table (a row is about 300 characters).
MAX_LINE_CHARS = 4096
_HEADER = ",".join(COLUMNS3D)
_INT = frozenset({"version", "nside", "m", "n", "seed", "count", "flagged"})
_STR = frozenset({"prior", "estimator", "bin"})
_METRICS = ("dd_mape", "ad_mape", "el_mae_deg", "az_mae_deg", "dd_r2", "ad_r2", "el_r2")
_DESIGN = ("h", "l", "nside", "r_min", "r_max", "g_max", "el_max", "prior", "n", "seed",
           "estimator")  # fmt: skip


def expected_bins(r_min: float, r_max: float) -> list[str]:
    """The bins of one point, in order: "all", "r0" ... (distance), "e0" ... (elevation)."""
    k = max(1, int(math.ceil((r_max - r_min) / BIN_WIDTH - 1e-9)))
    return ["all", *(f"r{i}" for i in range(k)), *(f"e{j}" for j in range(EL_BINS))]


def _fmt(value) -> str:
    if isinstance(value, bool):
        return str(int(value))
    if isinstance(value, float):
        return repr(value)  # round-trips exactly; nan as pandas reads it
    return str(value)


def format_row3d(row: dict) -> str:
    """One CSV line (no newline) of a 3D study row, in :data:`COLUMNS3D` order."""
    buf = io.StringIO()
    csv.writer(buf, lineterminator="").writerow([_fmt(row[c]) for c in COLUMNS3D])
    return buf.getvalue()


def is_table3d(path) -> bool:
    """Whether the file at ``path`` starts with the 3D study table's header (any version's
    first column names; the reader then checks the version)."""
    try:
        with open(path, "rb") as f:
            first = f.read(len(_HEADER) + 2)
    except OSError:
        return False
    return first.startswith(b"version,h,l,nside,")


def _parse(where: str, values: list[str], points: dict) -> dict:
    row: dict = {}
    for name, text in zip(COLUMNS3D, values, strict=True):
        if name in _STR:
            row[name] = text
            continue
        if name in _METRICS and not text.strip():
            row[name] = math.nan
            continue
        try:
            row[name] = int(text) if name in _INT else float(text)
        except ValueError:
            kind = "an integer" if name in _INT else "a number"
            raise EyevizError(f"{where}: {name} must be {kind}, got {text[:40]!r}") from None
        if name not in _INT and not math.isfinite(row[name]) and name not in _METRICS:
            raise EyevizError(f"{where}: {name} must be finite, got {text[:40]!r}")
    if row["version"] != STUDY3D_VERSION:
        raise EyevizError(
            f"{where}: written by 3D study version {row['version']}, this is version "
            f"{STUDY3D_VERSION}; the file was left as it is (write to another -o)"
        )
    design = tuple(row[c] for c in _DESIGN)
    if design not in points:
        try:
            points[design] = DesignPoint3D(*design)
        except (EyevizError, ValueError, TypeError) as exc:
            raise EyevizError(f"{where}: {exc}") from None
    point = points[design]
    if row["m"] != point.m or not math.isclose(row["gamma"], 2 * math.pi / point.m):
        raise EyevizError(f"{where}: m and gamma must be 4 nside and 2 pi / m")
    for name in ("count", "flagged"):
        if not 0 <= row[name] <= point.n:
            raise EyevizError(f"{where}: {name} must be in [0, n], got {row[name]}")
    for name in _METRICS:
        v = row[name]
        if math.isnan(v):
            if row["count"] and not name.endswith("r2"):
                raise EyevizError(f"{where}: {name} is empty in a bin of {row['count']} elements")
        elif math.isinf(v) or (not name.endswith("r2") and v < 0):
            raise EyevizError(f"{where}: {name} must be a finite number >= 0, got {v!r}")
    if not row["lo"] <= row["hi"]:
        raise EyevizError(f"{where}: lo must be <= hi, got {row['lo']!r} > {row['hi']!r}")
    row["_key"] = point.key
    return row


def read_rows3d(path, max_bytes: int = MAX_STUDY_BYTES) -> tuple[list[dict], list[str]]:
    """Parse a 3D study table: its rows (typed, with ``_key`` and ``_line``) and raw lines.

    Raises a one-line :class:`EyevizError` naming the file and the first bad line.
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
    if lines[0] != _HEADER:
        what = (
            "another version of the 3D study table" if is_table3d(path) else "not a 3D study table"
        )
        raise EyevizError(
            f"{name}: {what} (its header is not version {STUDY3D_VERSION}'s); "
            "the file was left as it is (write to another -o)"
        )
    rows: list[dict] = []
    first_line: dict[tuple, int] = {}
    bins: dict[tuple, list[str]] = {}
    points: dict[tuple, DesignPoint3D] = {}
    for i, line in enumerate(lines[1:], start=2):
        where = f"{name} line {i}"
        if len(line) > MAX_LINE_CHARS:
            raise EyevizError(f"{where}: longer than {MAX_LINE_CHARS} characters")
        if "\x00" in line:
            raise EyevizError(f"{where}: contains a NUL byte")
        values = next(csv.reader([line]), [])
        if len(values) != len(COLUMNS3D):
            raise EyevizError(f"{where}: {len(values)} fields, expected {len(COLUMNS3D)}")
        row = _parse(where, values, points)
        key = row["_key"]
        first_line.setdefault(key, i)
        seen = bins.setdefault(key, [])
        if row["bin"] in seen:
            raise EyevizError(
                f"{where}: bin {row['bin'][:40]!r} of this design point appears twice"
            )
        seen.append(row["bin"])
        row["_line"] = i
        rows.append(row)
    for key, seen in bins.items():
        want = expected_bins(key[3], key[4])
        if len(want) > MAX_BINS + EL_BINS + 1 or sorted(seen) != sorted(want):
            raise EyevizError(
                f"{name} line {first_line[key]}: design point h={key[0]:g}, l={key[1]:g}, "
                f"nside={key[2]} has {len(seen)} rows, expected {len(want)} "
                "(all, r0..., e0...): an incomplete or foreign point"
            )
    return rows, lines[1:]


@dataclass
class StudyTable3D:
    """A 3D study table on disk and the points it holds; :meth:`append` adds one point."""

    path: Path
    lines: list[str] = field(default_factory=list)
    keys: set[tuple] = field(default_factory=set)

    @classmethod
    def open(cls, path) -> StudyTable3D:
        """Read ``path`` if it exists (checked, see :func:`read_rows3d`), else start empty."""
        p = Path(path)
        d = p.parent if str(p.parent) else Path(".")
        if not d.is_dir():
            raise EyevizError(f"output directory does not exist: {str(d)!r}")
        if not os.path.lexists(p):
            return cls(p)
        rows, lines = read_rows3d(p)
        return cls(p, lines, {r["_key"] for r in rows})

    @property
    def finished(self) -> set[tuple]:
        """The :attr:`DesignPoint3D.key` of every point in the table."""
        return set(self.keys)

    def __contains__(self, point) -> bool:
        return isinstance(point, DesignPoint3D) and point.key in self.keys

    def append(self, rows: Iterable[dict]) -> None:
        """Add one design point's rows (from :func:`evaluate3d`), atomically."""
        rows = list(rows)
        if not rows:
            raise EyevizError("a design point without rows (a bug)")
        keys = {DesignPoint3D(*(r[c] for c in _DESIGN)).key for r in rows}
        if len(keys) != 1:
            raise EyevizError("rows of several design points appended at once (a bug)")
        (key,) = keys
        if key in self.keys:
            raise EyevizError(f"design point {key} is already in {self.path} (a bug)")
        lines = self.lines + [format_row3d(r) for r in rows]
        size = len(_HEADER) + 1 + sum(len(line.encode("utf-8")) + 1 for line in lines)
        if size > MAX_STUDY_BYTES:  # never write a table the reader would refuse
            raise EyevizError(
                f"{self.path}: this point would make the 3D study table {size} bytes, more "
                f"than the {MAX_STUDY_BYTES} its reader accepts; write the rest to another -o"
            )
        with atomic_output(self.path) as tmp, open(tmp, "w", encoding="utf-8", newline="") as f:
            f.write(_HEADER + "\n")
            for line in lines:
                f.write(line + "\n")
            f.flush()
            os.fsync(f.fileno())
        self.lines = lines
        self.keys.add(key)
