"""The eye-design study (issue 11): the information limit over a grid of eye designs.

The paper's open question (Section 8): how do azimuth (AD) and distance (DD) accuracy
depend on the eye diameter l, the distance between the eyes h and the number of
ommatidia m? :mod:`eyeviz.study.point` evaluates one design (pure numpy, no dask),
:mod:`eyeviz.study.grid` builds the grid of designs, :mod:`eyeviz.study.table` keeps the
results (CSV, whole points appended in place, resumable; the 3D study's too) and
:mod:`eyeviz.study.runner` distributes design points as tasks on Dask. Importing this
package does not import dask: :func:`run_study` imports the runner when called.
"""

from __future__ import annotations

from eyeviz.study.grid import design_grid, parse_list
from eyeviz.study.point import (
    COLUMNS,
    STUDY_VERSION,
    DesignPoint,
    distance_bins,
    evaluate,
    limit_curve,
)
from eyeviz.study.table import StudyTable, read_rows

__all__ = [
    "COLUMNS",
    "STUDY_VERSION",
    "DesignPoint",
    "StudyTable",
    "design_grid",
    "distance_bins",
    "evaluate",
    "limit_curve",
    "parse_list",
    "read_rows",
    "run_study",
]


def run_study(path, points, workers=None, scheduler=None, progress=True, **kwargs):
    """Evaluate the design points not yet in the table at ``path`` on Dask; see
    :func:`eyeviz.study.runner.run_study` (imported here, with dask, on first call)."""
    from eyeviz.study.runner import run_study as _run

    return _run(path, points, workers=workers, scheduler=scheduler, progress=progress, **kwargs)
