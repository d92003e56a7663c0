"""The two kinds of study the runner distributes: planar (h, l, m) and 3D (h, l, nside).

:mod:`eyeviz.study.runner` is one resumable Dask runner for both; what differs per kind
is here: the point type, its table (:class:`~eyeviz.study.table.StudyTable` or
:class:`~eyeviz.study.table.StudyTable3D`: one appender and one parser, with a format
each, told apart by their headers), its columns and the function a worker evaluates. A
study's points are all of one kind.
"""

from __future__ import annotations

from collections.abc import Sequence

from eyeviz import EyevizError
from eyeviz.study.point import COLUMNS, COLUMNS3D, DesignPoint, DesignPoint3D, evaluate3d
from eyeviz.study.point_measured import (
    COLUMNS_MEASURED,
    DesignPointMeasured,
    StudyTableMeasured,
    is_table_measured,
)
from eyeviz.study.table import StudyTable, StudyTable3D, is_table3d

__all__ = ["POINT_TYPES", "Point", "columns_of", "evaluate3d", "open_table"]

POINT_TYPES = (DesignPoint, DesignPoint3D, DesignPointMeasured)
#: A point of either kind.
Point = DesignPoint | DesignPoint3D | DesignPointMeasured


def columns_of(point: Point) -> tuple[str, ...]:
    """The table columns of ``point``'s kind."""
    if isinstance(point, DesignPointMeasured):
        return COLUMNS_MEASURED
    return COLUMNS3D if isinstance(point, DesignPoint3D) else COLUMNS


def open_table(path, points: Sequence) -> StudyTable:
    """The table at ``path`` for ``points`` (all planar or all 3D; checked here)."""
    kinds = {type(p) for p in points}
    if len(kinds) > 1:
        raise EyevizError("a study's points must be all planar (m) or all 3D (nside), not both")
    if kinds == {DesignPoint3D}:
        return StudyTable3D.open(path)
    if kinds == {DesignPointMeasured}:
        return StudyTableMeasured.open(path)
    if is_table_measured(path):
        raise EyevizError(f"{path}: a measured study table (eyeviz study --eye); give another -o")
    if is_table3d(path):
        raise EyevizError(
            f"{path}: a 3D study table (eyeviz study --nside); the planar study (--m) "
            "writes its own: give another -o"
        )
    return StudyTable.open(path)
