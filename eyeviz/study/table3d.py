"""The 3D study table: one CSV row per 3D design point and bin, appended in place.

The study table of :mod:`eyeviz.study.table` with the 3D format :data:`TABLE3D`: its
header is :data:`~eyeviz.study.point3d.COLUMNS3D` (the planar table's header is another,
so neither reader takes the other's file, and :func:`is_table3d` tells them apart from
the first line); pandas reads it as it is. Rows are written by
:func:`~eyeviz.study.point3d.evaluate3d` a whole design point at a time, appended in
place as the planar table's are (one write and fsync, cut back on failure; a point that
would take the table past its reader's bound refused before writing).

The one parser of the study tables reads it, with the 3D columns: nside a valid HEALPix
nside (even, >= 2, with the rest of the design checked by
:class:`~eyeviz.study.point3d.DesignPoint3D`), m = 4 nside and gamma = 2 pi / m, count
<= n, flagged <= count, the DD and AD MAPE and the elevation and azimuth errors finite
and >= 0, every R^2 <= 1, the bins "all", "r0" ... (distance) and "e0" ... "e5"
(elevation) with their bounds; the first bad line is named.
"""

from __future__ import annotations

import os
import stat
from collections.abc import Iterator

from eyeviz.files.limits import MAX_STUDY_BYTES
from eyeviz.study.point3d import COLUMNS3D, EL_BINS, STUDY3D_VERSION, DesignPoint3D
from eyeviz.study.table import StudyTable, TableFormat, format_row, iter_rows, read_rows

__all__ = [
    "MAX_STUDY_BYTES",
    "TABLE3D",
    "StudyTable3D",
    "format_row3d",
    "is_table3d",
    "iter_rows3d",
    "read_rows3d",
]

#: The 3D study's table (:mod:`eyeviz.study.point3d`).
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


def format_row3d(row: dict) -> str:
    """One CSV line (no newline) of a 3D study row, in :data:`COLUMNS3D` order."""
    return format_row(row, COLUMNS3D)


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
    return first.startswith((",".join(COLUMNS3D[: TABLE3D.family]) + ",").encode("ascii"))


def iter_rows3d(path, max_bytes: int = MAX_STUDY_BYTES) -> Iterator[tuple[str, dict]]:
    """Stream a 3D study table (:func:`eyeviz.study.table.iter_rows` with :data:`TABLE3D`)."""
    return iter_rows(path, max_bytes, TABLE3D)


def read_rows3d(path, max_bytes: int = MAX_STUDY_BYTES) -> tuple[list[dict], list[str]]:
    """A whole 3D study table: its rows (typed, with ``_key`` and ``_line``) and raw lines.

    Raises a one-line :class:`EyevizError` naming the file and the first bad line.
    """
    return read_rows(path, max_bytes, TABLE3D)


class StudyTable3D(StudyTable):
    """A 3D study table on disk and the points it holds; :meth:`append` adds one point
    (the planar :class:`~eyeviz.study.table.StudyTable` with the 3D format)."""

    fmt = TABLE3D
