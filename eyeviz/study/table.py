"""The study tables on disk: one CSV row per design point and bin, appended in place.

Both studies keep their results in a table of this one kind, read and written here for
both: a :class:`~eyeviz.study.table_format.TableFormat` says what sets the planar table
(:data:`PLANAR`, :class:`StudyTable`) apart from the 3D one (:data:`TABLE3D`,
:class:`StudyTable3D`; its header is :data:`~eyeviz.study.point.COLUMNS3D`, so neither
reader takes the other's file, and :func:`is_table3d` tells them apart from the first
line), and :mod:`eyeviz.study.table_format` holds the one parser of their lines
(docs/study/README.md). pandas reads either file as it is (``pandas.read_csv(path)``).

Rows are written a whole design point at a time (:func:`~eyeviz.study.point.evaluate`,
MAPE Eq. 34, R^2 Eq. 35; :func:`~eyeviz.study.point.evaluate3d`):
:meth:`StudyTable.append` writes the first point with its header through
:func:`eyeviz.files.atomic.atomic_output` and appends each later point's lines to the
file (one write, fsync), cutting the file back to its former size should the write fail
or be interrupted; so after Ctrl-C or a full disk the file holds the points it held before
or those plus the new one, never part of a point (a power loss in the middle of one write
can leave a torn last point, which the reader names as an incomplete point). A symlinked
table is written through (the link stays a link) and a hard-linked one stays one file.

Reading never trusts the file: its size is bounded (:data:`MAX_STUDY_BYTES`), it is read
one line at a time and every line is checked by the one parser
(:func:`~eyeviz.study.table_format.parse_fields`); the first bad line is named. The runner
and the report use the same reader, and every line is put through the parser before it
is written: a study never writes a table its own reader refuses. A file of another
version (another header or version column) is refused with one line and left as it is.
"""

from __future__ import annotations

import contextlib
import os
import stat
from collections.abc import Iterable, Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, ClassVar

from eyeviz import EyevizError
from eyeviz.files.atomic import atomic_output, full_disk_error
from eyeviz.files.limits import MAX_STUDY_BYTES, check_file_size
from eyeviz.study.table_format import (
    MAX_LINE_CHARS,
    PLANAR,
    TABLE3D,
    TableFormat,
    check_header,
    decode_line,
    format_row,
    parse_fields,
    split_fields,
)

__all__ = [
    "MAX_LINE_CHARS",
    "MAX_STUDY_BYTES",
    "PLANAR",
    "StudyTable",
    "StudyTable3D",
    "TABLE3D",
    "TableFormat",
    "format_row",
    "format_row3d",
    "is_table3d",
    "iter_rows",
    "iter_rows3d",
    "read_rows",
    "read_rows3d",
]


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
                check_header(fmt, name, decode_line(name, 1, head))
                continue
            line = decode_line(name, i, raw[:-1] if raw.endswith(b"\n") else raw)
            where = f"{name} line {i}"
            values = split_fields(where, line)
            if len(values) != width:
                raise EyevizError(f"{where}: {len(values)} fields, expected {width}")
            row, point = parse_fields(fmt, where, values)
            key = row["_key"]
            if key not in points:
                points[key] = (i, set(), fmt.rows_per_point(point), fmt.describe(point))
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
    3D study's (:class:`StudyTable3D`) is this with another
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
            row, point = parse_fields(fmt, where, split_fields(where, line))
            keys.add(row["_key"])
            seen.add(row["bin"])
            out.append(line + "\n")
        if len(keys) != 1:
            raise EyevizError("rows of several design points appended at once (a bug)")
        (key,) = keys
        if key in self.keys:
            raise EyevizError(f"design point {key} is already in {self.path} (a bug)")
        want = fmt.rows_per_point(point)
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
        if not fresh and not self._ends_with_newline():
            # a last line without its newline (an editor's save): the reader takes it, so
            # the point's lines must not go on at its end
            data = b"\n" + data
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

    def _ends_with_newline(self) -> bool:
        """Whether the file's last byte (at ``size - 1``, as read) is a newline."""
        try:
            with open(os.path.realpath(self.path), "rb") as f:
                f.seek(self.size - 1)
                return f.read(1) == b"\n"
        except OSError:
            return True  # _append_bytes names what is wrong with the file

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


class StudyTable3D(StudyTable):
    """A 3D study table on disk and the points it holds; :meth:`append` adds one point
    (:class:`StudyTable` with the 3D format)."""

    fmt = TABLE3D


def format_row3d(row: dict) -> str:
    """One CSV line (no newline) of a 3D study row, in :data:`COLUMNS3D` order."""
    return format_row(row, TABLE3D.columns)


def is_table3d(path) -> bool:
    """Whether the file at ``path`` starts with the 3D study table's header (any version's
    first column names; the reader then checks the version)."""
    try:
        if not stat.S_ISREG(os.stat(path).st_mode):  # a FIFO would block open() for good
            return False  # (the reader then says what the file is)
        with open(path, "rb") as f:
            first = f.read(len(TABLE3D.header))
    except OSError:
        return False
    return first.startswith((",".join(TABLE3D.columns[: TABLE3D.family]) + ",").encode("ascii"))


def iter_rows3d(path, max_bytes: int = MAX_STUDY_BYTES) -> Iterator[tuple[str, dict]]:
    """Stream a 3D study table (:func:`iter_rows` with :data:`TABLE3D`)."""
    return iter_rows(path, max_bytes, TABLE3D)


def read_rows3d(path, max_bytes: int = MAX_STUDY_BYTES) -> tuple[list[dict], list[str]]:
    """A whole 3D study table: its rows (typed, with ``_key`` and ``_line``) and raw lines.

    Raises a one-line :class:`EyevizError` naming the file and the first bad line.
    """
    return read_rows(path, max_bytes, TABLE3D)
