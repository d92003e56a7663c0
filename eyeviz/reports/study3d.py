"""``eyeviz report study STUDY3D.csv -o DIR`` for a 3D study table (``eyeviz study --nside``).

The 3D table (:mod:`eyeviz.study.table`) holds, per design of the spherical eyes (h, l,
nside) and estimator, the DD and AD error (MAPE, Eq. 34) and the elevation and azimuth
error (mean absolute, degrees) overall, per distance bin and per elevation bin. This
report answers the 3D study's questions:

1. How does accuracy depend on h, l, nside, distance and elevation?
   ``study3d_design``: DD MAPE and elevation error (overall) against h, l and nside.
2. Does the planar law, relative DD error = C gamma r / (2h), carry over?
   ``study3d_dd``: DD MAPE against r, a panel per h, a curve per nside, each with its law
   line C gamma r / (2h) (gamma = 2 pi / (4 nside), the equatorial facet width; C fitted
   in 3D with the slope fixed at 1, as the planar report does); ``study3d_law``: every
   distance bin against gamma r / (2h) on log-log axes. ``summary3d.json`` adds a free
   power law, relative DD = K gamma^a r^b h^c l^d, fitted by least squares in log space:
   the planar law is a = b = 1, c = -1, d = 0.
3. How does the elevation error behave (the baseline is horizontal, so each eye alone sees
   the elevation)? ``study3d_elevation``: elevation and azimuth error against elevation
   and against r, a curve per nside, at the paper's h and l (or the nearest).

Fitted: distance bins with at least :data:`~eyeviz.reports.study_design.MIN_COUNT`
elements, at most :data:`FLAG_MAX` of them flagged (the estimator fell back: diverging
rays, an empty posterior), not the first or last bin of a design (the prior's bounds
truncate there; a design of one or two bins keeps them), a relative error <=
:data:`FIT_MAX` (where it saturates, the prior's range bounds it) and, where the table
states it, a sampling error of the bin's DD at most :data:`REL_MAX` of the DD (issue
38.3). ``band`` (``eyeviz report study --band W``) first merges the table's 500-wide
distance bins into bands W wide (:func:`merge_bins`), so that each holds enough balls for
that error; the figures, the fit and the summary then use the bands. The estimator is
named in every figure's title: only the limit is the accuracy limit (``limit3d``); any
other (``analytic3d``) is an upper bound on its MAPE.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from eyeviz import EyevizError
from eyeviz.core import paper
from eyeviz.reports.study_design import MIN_COUNT
from eyeviz.reports.study_law import LawFit, LawPoint, fit_law
from eyeviz.study.point import BIN_WIDTH
from eyeviz.study.table import iter_rows3d

__all__ = [
    "FIT_MAX",
    "PAPER3D",
    "REL_MAX",
    "Design3D",
    "band_designs",
    "bin_errors",
    "fit_power",
    "law_points3d",
    "merge_bins",
    "law_uncertainty",
    "read_study3d",
    "write_report3d",
]

#: The paper's eyes in 3D: h = 40, l = 20 and nside 180 (m = 720 on the equator).
PAPER3D = (paper.H, paper.L, paper.NSIDE)
#: Names of the accuracy limit (the posterior) in the estimator registry.
LIMITS = ("limit3d", "limit")
#: Largest fraction of flagged answers in a fitted bin.
FLAG_MAX = 0.05
#: Largest relative DD error (a fraction) of a bin used in the fits.
FIT_MAX = 0.10
#: Largest sampling error of a fitted bin's DD relative to the DD (issue 38.3: 5 %).
REL_MAX = 0.05


@dataclass
class Design3D:
    """One 3D design point's rows: overall, distance bins (by r), elevation bins (by el)."""

    h: float
    l: float  # noqa: E741
    nside: int
    gamma: float
    all: dict
    r_bins: list[dict]
    el_bins: list[dict]

    @property
    def key(self) -> tuple[float, float, int]:
        return (self.h, self.l, self.nside)


def choose_estimator(rows: list[dict]) -> str:
    """The limit (:data:`LIMITS`) when the table has it, else the estimator measured on
    the most designs (of those, the first by name)."""
    designs: dict[str, set] = {}
    for r in rows:
        designs.setdefault(r["estimator"], set()).add((r["h"], r["l"], r["nside"]))
    return min(designs, key=lambda e: (e not in LIMITS, -len(designs[e]), e))


def read_study3d(path) -> list[dict]:
    """The rows of a 3D study table, read by the study tables' one parser (the runner's
    checks and one-line errors naming the file and the first bad line,
    :mod:`eyeviz.study.table`); the report adds only: at least one row."""
    rows = [row for _, row in iter_rows3d(path)]
    if not rows:
        raise EyevizError(f"{path}: the 3D study table has no rows")
    return rows


def designs3d(rows: list[dict], estimator: str, prior: str) -> dict[tuple, Design3D]:
    """The rows of ``estimator`` and ``prior`` per design; of several runs the largest n."""
    runs: dict[tuple, list[dict]] = {}
    for r in rows:
        if r["estimator"] == estimator and r["prior"] == prior:
            runs.setdefault(r["_key"], []).append(r)
    if not runs:
        raise EyevizError(
            f"the 3D study table has no rows of estimator {estimator!r} and prior {prior!r}"
        )
    best: dict[tuple, list[dict]] = {}
    for rr in runs.values():
        k = (rr[0]["h"], rr[0]["l"], rr[0]["nside"])
        if k not in best or rr[0]["n"] > best[k][0]["n"]:
            best[k] = rr
    out = {}
    for k, rr in best.items():
        alls = [r for r in rr if r["bin"] == "all"]
        rb = sorted((r for r in rr if r["bin"].startswith("r")), key=lambda r: r["lo"])
        eb = sorted((r for r in rr if r["bin"].startswith("e")), key=lambda r: r["lo"])
        out[k] = Design3D(k[0], k[1], k[2], alls[0]["gamma"], alls[0], rb, eb)
    return out


_MERGED_MEANS = ("dd_mape", "ad_mape", "el_mae_deg", "az_mae_deg")


def merge_bins(bins: list[dict], width: float) -> list[dict]:
    """Consecutive distance bins (of :data:`~eyeviz.study.point.BIN_WIDTH`, in order of r)
    merged into bands ``width`` wide, a whole multiple of the bin width; empty bands are
    left out. The bins are disjoint sets of balls, so a band's mean errors (DD and AD
    MAPE, elevation and azimuth mean |error|) are its bins' means weighted by their
    counts, exactly the means over the band's balls, and a band's sampling error the
    stratified one: se = sqrt(sum (count_i se_i)^2) / sum count_i (``dd_se``, ``el_se``).
    ``r_mid`` is the mean of the bins' mid-distances weighted by their counts: the law's
    r for the band (its predicted DD is the mean of C gamma r / (2h) over the balls)."""
    k = width / BIN_WIDTH
    if not (math.isfinite(k) and k >= 1 and abs(k - round(k)) < 1e-9):
        raise EyevizError(
            f"--band must be a whole multiple of the table's {BIN_WIDTH:g}-wide bins, got {width!r}"
        )
    per = round(k)
    out = []
    for j, i in enumerate(range(0, len(bins), per)):
        part = [b for b in bins[i : i + per] if b["count"] > 0]
        n = sum(b["count"] for b in part)
        if not n:
            continue
        band = {"bin": f"r{j}", "lo": bins[i]["lo"], "hi": bins[min(i + per, len(bins)) - 1]["hi"]}
        band["count"], band["flagged"] = n, sum(b["flagged"] for b in part)
        for key in _MERGED_MEANS:
            band[key] = sum(b["count"] * b.get(key, math.nan) for b in part) / n
        for key in ("dd_se", "el_se"):
            band[key] = math.sqrt(sum((b["count"] * b.get(key, math.nan)) ** 2 for b in part)) / n
        band["r_mid"] = sum(b["count"] * 0.5 * (b["lo"] + b["hi"]) for b in part) / n
        out.append(band)
    return out


def band_designs(designs: dict[tuple, Design3D], width: float) -> dict[tuple, Design3D]:
    """The designs with their distance bins merged into bands ``width`` wide
    (:func:`merge_bins`); the overall and elevation rows as they are."""
    return {k: replace(d, r_bins=merge_bins(d.r_bins, width)) for k, d in designs.items()}


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


def bin_errors(designs: dict[tuple, Design3D]) -> list[dict]:
    """Every distance bin of every design with its DD, its sampling error (``dd_se``,
    bootstrap over the bin's rows) and that error relative to the DD."""
    out = []
    for d in sorted(designs.values(), key=lambda d: d.key):
        for b in d.r_bins:
            se = b.get("dd_se", math.nan)
            out.append({
                "h": d.h, "l": d.l, "nside": d.nside, "bin": b["bin"], "lo": b["lo"],
                "hi": b["hi"], "count": b["count"], "dd_mape": b["dd_mape"], "dd_se": se,
                "rel_se": se / b["dd_mape"] if b["dd_mape"] > 0 else math.nan,
            })  # fmt: skip
    return out


def _no_nan(v):
    """``v`` with every NaN float (a bin of one row has no standard error) as None."""
    if isinstance(v, dict):
        return {k: _no_nan(x) for k, x in v.items()}
    if isinstance(v, list):
        return [_no_nan(x) for x in v]
    return None if isinstance(v, float) and math.isnan(v) else v


def _nearest(values, want: float) -> float:
    return min(values, key=lambda v: (abs(math.log(v / want)), v))


# long: the report's sections written in order from one table
def write_report3d(
    path: Path,
    outdir: Path,
    prior: str | None = None,
    l_wanted: float = PAPER3D[1],
    estimator: str | None = None,
    band: float = BIN_WIDTH,
) -> list[Path]:
    """Read the 3D study table at ``path`` and write the figures and summary into
    ``outdir``, the distance bins merged into bands ``band`` wide (:func:`merge_bins`)."""
    import matplotlib

    from eyeviz.reports.study3d_figures import (
        dd_figure,
        design_figure,
        elevation_figure,
        law_figure3d,
    )
    from eyeviz.reports.study_figures import _rc, save
    from eyeviz.reports.study_summary import _write_text

    rows = read_study3d(path)
    if prior is None:
        have = sorted({r["prior"] for r in rows})
        prior = have[0] if len(have) == 1 else "single"
    est = estimator or choose_estimator(rows)
    designs = designs3d(rows, est, prior)
    if band != BIN_WIDTH:
        designs = band_designs(designs, band)
    points = law_points3d(designs)
    fit: LawFit = fit_law(points, x_max=math.inf)
    power = fit_power(points)
    hs = sorted({k[0] for k in designs})
    l_of = {h: _nearest([k[1] for k in designs if k[0] == h], l_wanted) for h in hs}
    h_star = _nearest(hs, PAPER3D[0])
    is_limit = est in LIMITS
    label = est if is_limit else f"{est} (an upper bound on the limit, not the limit)"
    outdir.mkdir(parents=True, exist_ok=True)
    written: list[Path] = []
    with matplotlib.rc_context(_rc()):
        for stem, fig in (
            ("study3d_design", design_figure(designs, l_of, h_star, label)),
            ("study3d_dd", dd_figure(designs, l_of, fit, label)),
            ("study3d_law", law_figure3d(points, fit, power, label)),
            ("study3d_elevation", elevation_figure(designs, h_star, l_of[h_star], label)),
        ):
            written += save(fig, outdir, stem)
    summary = {
        "table": str(path),
        "estimator": est,
        "is_the_limit": is_limit,
        "prior": prior,
        "law_slope_1": {
            "C": fit.C,
            "factor_1sd": fit.factor,
            "n": fit.n,
            "free_slope": fit.slope,
            "C_free": fit.C_free,
            **law_uncertainty(points),
        },
        "power_law": power,
        "band": band,
        "fit_rule": f"interior distance bins ({band:g} wide), >= {MIN_COUNT} elements, "
        f"<= {FLAG_MAX:.0%} flagged, relative DD error <= {FIT_MAX:g}, sampling error of "
        f"the DD <= {REL_MAX:.0%} of it where stated",
        "designs": [
            {
                "h": d.h,
                "l": d.l,
                "nside": d.nside,
                "gamma": d.gamma,
                "n": d.all["n"],
                **{
                    k: d.all[k]
                    for k in (
                        "dd_mape",
                        "dd_se",
                        "ad_mape",
                        "el_mae_deg",
                        "el_se",
                        "az_mae_deg",
                        "flagged",
                        "seconds",
                    )
                },
                "el_mae_over_gamma": d.all["el_mae_deg"] / math.degrees(d.gamma),
            }
            for d in sorted(designs.values(), key=lambda d: d.key)
        ],
        "bins": bin_errors(designs),
        "other_estimators": [  # the table's other estimators, overall, beside the drawn one
            {
                "estimator": r["estimator"],
                "h": r["h"],
                "l": r["l"],
                "nside": r["nside"],
                "n": r["n"],
                "seed": r["seed"],
                **{k: r[k] for k in ("dd_mape", "ad_mape", "el_mae_deg", "az_mae_deg")},
            }
            for r in rows
            if r["bin"] == "all" and r["estimator"] != est and r["prior"] == prior
        ],
    }
    text = json.dumps(_no_nan(summary), indent=1, allow_nan=False) + "\n"
    written.append(_write_text(outdir / "summary3d.json", text))
    return written
