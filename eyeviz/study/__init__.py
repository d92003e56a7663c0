"""The eye-design study (issue 11): the information limit over a grid of eye designs.

The paper's open question (Section 8): how do azimuth (AD) and distance (DD) accuracy
depend on the eye diameter l, the distance between the eyes h and the number of
ommatidia m? :mod:`eyeviz.study.point` evaluates one design (pure numpy, no dask);
the runner distributes design points as tasks on Dask. Importing this package does
not import dask.
"""

from eyeviz.study.point import (
    COLUMNS,
    STUDY_VERSION,
    DesignPoint,
    distance_bins,
    evaluate,
    limit_curve,
)

__all__ = ["COLUMNS", "STUDY_VERSION", "DesignPoint", "distance_bins", "evaluate", "limit_curve"]
