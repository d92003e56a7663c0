"""The law of the eye-design study (:mod:`eyeviz.reports.study`): its points and fitted C.

relative DD error = C * gamma * r / (2h) (gamma = 2 pi / m, Prop. 1). The fit of C: least
squares in log space with the slope fixed at 1, i.e. log C = mean(log y - log x), over bins
with at least :data:`MIN_COUNT` test elements, x = gamma r_mid / (2h) <= ``--law-max``
(beyond it the error saturates: the prior's range bounds it) and not the first or last bin
of a design (there the prior's bounds r_min, r_max truncate the posterior and lower the
error). Its spread is the standard deviation of the log residuals (a factor exp(sd)); a
free log-log slope is reported beside it.

Spherical eyes (:func:`law_points3d`; gamma = 2 pi / (4 nside), the equatorial facet
width): fitted are distance bins with at least :data:`MIN_COUNT` elements, at most
:data:`FLAG_MAX` of them flagged (the estimator fell back: diverging rays, an empty
posterior), not the first or last bin of a design (a design of one or two bins keeps
them), a relative error <= :data:`FIT_MAX` (where it saturates, the prior's range bounds
it) and, where the table states it, a sampling error of the bin's DD at most
:data:`REL_MAX` of the DD (issue 38.3); C is fitted with no ``--law-max``. Beside it a
free power law (:func:`fit_power`) and the fit's bootstrap spread (:func:`law_uncertainty`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from eyeviz.reports.study_design import MIN_COUNT, PAPER3D, Design3D

LAW_MAX = 0.25  # default upper end of gamma r / (2h) for the fit
#: Largest fraction of flagged answers in a fitted bin (3D).
FLAG_MAX = 0.05
#: Largest relative DD error (a fraction) of a bin used in the 3D fits.
FIT_MAX = 0.10
#: Largest sampling error of a fitted bin's DD relative to the DD (issue 38.3: 5 %).
REL_MAX = 0.05


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


def _precise(b: dict) -> bool:
    """Whether the bin's stated sampling error is at most :data:`REL_MAX` of its DD (a bin
    without a stated error, as in a version 1 table, passes: it has nothing to check)."""
    se = b.get("dd_se", math.nan)
    return not math.isfinite(se) or se <= REL_MAX * b["dd_mape"]


def law_points3d(designs: dict[tuple, Design3D]) -> list[LawPoint]:
    """Every distance bin as (x = gamma r_mid / (2h), y = relative DD error); ``fitted``
    as this module's docstring says. ``m`` holds 4 nside; ``r_mid`` is a merged band's
    own (:func:`merge_bins`), else the bin's middle."""
    out = []
    for d in designs.values():
        n = len(d.r_bins)
        for i, b in enumerate(d.r_bins):
            if b["count"] < MIN_COUNT or not (b["dd_mape"] > 0):
                continue
            r_mid = b.get("r_mid", 0.5 * (b["lo"] + b["hi"]))
            y = b["dd_mape"] / 100.0
            interior = n < 3 or 0 < i < n - 1
            few_flags = b["flagged"] <= FLAG_MAX * b["count"]
            fitted = interior and few_flags and y <= FIT_MAX and _precise(b)
            paper = d.key == PAPER3D
            out.append(
                LawPoint(
                    d.h,
                    d.l,
                    4 * d.nside,
                    r_mid,
                    d.gamma * r_mid / (2 * d.h),
                    y,
                    fitted,
                    paper,
                    b.get("dd_se", math.nan) / 100.0,
                )  # fmt: skip
            )
    return out


def fit_power(points: list[LawPoint]) -> dict | None:
    """relative DD = K gamma^a r^b h^c l^d, least squares in log space over the fitted
    points (a parameter that does not vary is left out and reported as None)."""
    use = [p for p in points if p.fitted]
    if len(use) < 3:
        return None
    gam = np.array([2 * math.pi / p.m for p in use])
    cols = {
        "gamma": gam,
        "r": np.array([p.r for p in use]),
        "h": np.array([p.h for p in use]),
        "l": np.array([p.l for p in use]),
    }
    names = [k for k, v in cols.items() if np.ptp(np.log(v)) > 0]
    a = np.column_stack([np.ones(len(use))] + [np.log(cols[k]) for k in names])
    y = np.log([p.y for p in use])
    if len(use) <= a.shape[1]:
        return None
    coef, *_ = np.linalg.lstsq(a, y, rcond=None)
    res = y - a @ coef
    out: dict = {"K": float(math.exp(coef[0])), "n": len(use)}
    for k in cols:
        out[f"exp_{k}"] = float(coef[1 + names.index(k)]) if k in names else None
    out["log_sd"] = float(res.std(ddof=a.shape[1]))
    return out


#: resamples of the law's bootstrap (:func:`law_uncertainty`)
LAW_BOOT = 1000


def law_uncertainty(points: list[LawPoint], n_boot: int = LAW_BOOT, seed: int = 0) -> dict:
    """The sampling spread of the fitted law, by a bootstrap over its fitted bins (each
    resample refits both forms of :func:`~eyeviz.reports.study_law.fit_law`): the
    standard deviation of log C (slope fixed at 1; ``C_factor_se`` = exp of it), of the
    free slope and of log C_free. Empty below 3 fitted bins."""
    use = [p for p in points if p.fitted]
    if len(use) < 3:
        return {}
    lx = np.log([p.x for p in use])
    ly = np.log([p.y for p in use])
    rng = np.random.default_rng(seed)
    idx = rng.integers(0, lx.size, size=(n_boot, lx.size))
    x, y = lx[idx], ly[idx]
    log_c = (y - x).mean(axis=1)
    xm, ym = x.mean(axis=1, keepdims=True), y.mean(axis=1, keepdims=True)
    sxx = ((x - xm) ** 2).sum(axis=1)
    ok = sxx > 0
    slope = ((x - xm) * (y - ym)).sum(axis=1)[ok] / sxx[ok]
    log_cf = ym[ok, 0] - slope * xm[ok, 0]
    return {
        "n_boot": n_boot,
        "C_factor_se": float(math.exp(log_c.std(ddof=1))),
        "free_slope_se": float(slope.std(ddof=1)),
        "C_free_factor_se": float(math.exp(log_cf.std(ddof=1))),
    }
