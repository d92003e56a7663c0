"""The law of the eye-design study (:mod:`eyeviz.reports.study`): its points and fitted C.

relative DD error = C * gamma * r / (2h) (gamma = 2 pi / m, Prop. 1). The fit of C: least
squares in log space with the slope fixed at 1, i.e. log C = mean(log y - log x), over bins
with at least :data:`MIN_COUNT` test elements, x = gamma r_mid / (2h) <= ``--law-max``
(beyond it the error saturates: the prior's range bounds it) and not the first or last bin
of a design (there the prior's bounds r_min, r_max truncate the posterior and lower the
error). Its spread is the standard deviation of the log residuals (a factor exp(sd)); a
free log-log slope is reported beside it.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from eyeviz.reports.study_design import MIN_COUNT

LAW_MAX = 0.25  # default upper end of gamma r / (2h) for the fit


@dataclass
class LawPoint:
    h: float
    l: float  # noqa: E741
    m: int
    r: float
    x: float  # gamma r / (2h)
    y: float  # relative DD error (MAPE / 100)
    fitted: bool
    paper: bool
    y_se: float = math.nan  # the sampling error of y, where the table states it (3D)


@dataclass
class LawFit:
    """relative DD error = C * gamma r / (2h), C fitted in log space with slope 1."""

    C: float | None
    log_sd: float | None  # standard deviation of log(y / (C x)) over the fitted points
    n: int
    slope: float | None  # free least-squares slope of log y on log x (for comparison)
    C_free: float | None  # exp(intercept) of that free fit
    x_max: float
    method: str = (
        "least squares in log space with the slope fixed at 1: log C = mean(log y - log x)"
    )

    @property
    def factor(self) -> float | None:
        return None if self.log_sd is None else math.exp(self.log_sd)


def law_points(designs: dict, x_max: float = LAW_MAX) -> list[LawPoint]:
    out = []
    for d in designs.values():
        n = len(d.bins)
        for i, b in enumerate(d.bins):
            if b.count < MIN_COUNT or not (b.dd_mape > 0):
                continue
            x = d.all.gamma * b.r_mid / (2 * d.h)
            interior = n < 3 or 0 < i < n - 1
            out.append(
                LawPoint(
                    d.h,
                    d.l,
                    d.m,
                    b.r_mid,
                    x,
                    b.dd_mape / 100.0,
                    interior and x <= x_max,
                    d.is_paper,
                )
            )
    return out


def fit_law(points: Sequence[LawPoint], x_max: float = LAW_MAX) -> LawFit:
    """C of relative DD error = C gamma r / (2h) (the method: this module's docstring)."""
    use = [p for p in points if p.fitted]
    if len(use) < 2:
        return LawFit(None, None, len(use), None, None, x_max)
    lx = np.log([p.x for p in use])
    ly = np.log([p.y for p in use])
    res = ly - lx
    log_c = float(res.mean())
    sd = float(res.std(ddof=1))
    slope = c_free = None
    if np.ptp(lx) > 0:
        s, i = np.polyfit(lx, ly, 1)
        slope, c_free = float(s), float(math.exp(i))
    return LawFit(math.exp(log_c), sd, len(use), slope, c_free, x_max)
