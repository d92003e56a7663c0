"""One design point of the eye-design study: the information limit's AD and DD error.

A design point is an eye design (h, l, m; Table 3) with the object ranges (Table 4), a
prior ("single" or "multi" pass, Section 5), a test-set size n and a seed. Its test set
is drawn from that design's Algorithm 1 (:func:`eyeviz.dataset.algorithm1.iter_chunks`,
interval form, no bitmaps held), and every element is estimated by the information
limit (:class:`eyeviz.estimators.limit.LimitEstimator`): the MAPE-optimal posterior
median given the bitmaps, the best any estimator can do (issue 10). The errors are MAPE
(Eq. 34) and R^2 (Eq. 35, standard form, docs/conventions.md), overall and per distance bin.

Pure: the same point gives the same rows except ``seconds``. No dask here: workers call
:func:`evaluate` with the point (a few numbers), never with arrays.
"""

from __future__ import annotations

import math
import time
from dataclasses import asdict, dataclass

import numpy as np

from eyeviz import EyevizError
from eyeviz.core.domain import DEFAULTS, Domain
from eyeviz.core.validation import check_choice, check_int
from eyeviz.estimators.limit import PRIORS, LimitEstimator
from eyeviz.estimators.metrics import mape, r2

__all__ = [
    "BIN_WIDTH",
    "COLUMNS",
    "STUDY_VERSION",
    "DesignPoint",
    "distance_bins",
    "evaluate",
    "limit_curve",
]

#: Width of the distance bins of the per-bin rows (the paper's Figure 17 uses 1000).
BIN_WIDTH = 500.0
#: Version of the study table's columns; a file with another version is refused.
STUDY_VERSION = 1
#: The study table's columns, in order: one row per design point and bin ("all" first).
COLUMNS = (
    "version", "h", "l", "m", "gamma", "r_min", "r_max", "g_max", "prior", "n", "seed",
    "bin", "r_lo", "r_hi", "count", "dd_mape", "ad_mape", "dd_r2", "ad_r2", "flagged",
    "seconds",
)  # fmt: skip


@dataclass(frozen=True)
class DesignPoint:
    """One eye design and its test set: what a study worker receives (a few numbers)."""

    h: float = DEFAULTS["h"]
    l: float = DEFAULTS["l"]  # noqa: E741  (the paper's name)
    m: int = int(DEFAULTS["m"])
    r_min: float = DEFAULTS["r_min"]
    r_max: float = DEFAULTS["r_max"]
    g_max: float = DEFAULTS["g_max"]
    prior: str = "single"
    n: int = 100_000
    seed: int = 0

    def __post_init__(self) -> None:
        self.domain  # noqa: B018  (validates h, l, m and the ranges with named messages)
        check_choice("prior", self.prior, PRIORS)
        check_int("n", self.n, ge=1)
        check_int("seed", self.seed, ge=0)

    @property
    def domain(self) -> Domain:
        return Domain(self.h, self.l, self.m, self.r_min, self.r_max, self.g_max)

    @property
    def key(self) -> tuple:
        """What identifies a finished point in a study file (resume skips it)."""
        return (
            float(self.h),
            float(self.l),
            int(self.m),
            float(self.r_min),
            float(self.r_max),
            float(self.g_max),
            self.prior,
            int(self.n),
            int(self.seed),
        )

    def to_dict(self) -> dict:
        return asdict(self)


def distance_bins(r_min: float, r_max: float, width: float = BIN_WIDTH) -> np.ndarray:
    """Bin edges from r_min to r_max, about ``width`` apart (at least one bin)."""
    k = max(1, int(math.ceil((r_max - r_min) / width - 1e-9)))
    return np.linspace(r_min, r_max, k + 1)


def _errors(r, phi, r_hat, phi_hat) -> dict[str, float]:
    out = {"dd_mape": mape(r, r_hat), "ad_mape": mape(phi, phi_hat)}
    out["dd_r2"] = r2(r, r_hat) if r.size > 1 and np.ptp(r) > 0 else math.nan
    out["ad_r2"] = r2(phi, phi_hat) if phi.size > 1 and np.ptp(phi) > 0 else math.nan
    return out


def evaluate(point: DesignPoint, bin_width: float = BIN_WIDTH) -> list[dict]:
    """Rows of the study table for one design point: ``bin = "all"`` then one per bin.

    Each row carries the design, the prior, n, seed, the bin's [r_lo, r_hi), how many
    test elements fell in it (``count``), DD and AD MAPE (%) and R^2 of the information
    limit, how many answers came from triangulation because the prior cannot produce the
    key (``flagged``), and ``seconds`` (the whole point, on one core).
    """
    from eyeviz.dataset.algorithm1 import iter_chunks, make_params

    t0 = time.perf_counter()
    d = point.domain
    params = make_params(d, mode=point.prior, seed=point.seed)
    est = LimitEstimator(d, point.prior)
    parts: dict[str, list[np.ndarray]] = {k: [] for k in ("r", "phi", "rh", "ph", "fl")}
    for c in iter_chunks(point.n, params):
        p = est.predict_intervals(c.la, c.ra, c.lb, c.rb)
        if not np.all(p.valid):
            raise EyevizError("the limit could not answer a generated element (a bug)")
        for k, v in zip(parts, (c.r, c.phi, p.r, p.phi, p.flagged), strict=True):
            parts[k].append(np.asarray(v))
    r, phi, rh, ph, fl = (np.concatenate(v) for v in parts.values())
    seconds = time.perf_counter() - t0
    base = {"version": STUDY_VERSION, **point.to_dict(), "gamma": 2 * math.pi / point.m}
    rows = []
    edges = distance_bins(point.r_min, point.r_max, bin_width)
    sel_all = np.ones(r.size, bool)
    bins = [("all", point.r_min, point.r_max, sel_all)]
    for i in range(edges.size - 1):
        lo, hi = edges[i], edges[i + 1]
        last = i == edges.size - 2
        sel = (r >= lo) & ((r <= hi) if last else (r < hi))
        bins.append((str(i), lo, hi, sel))
    for name, lo, hi, sel in bins:
        row = {**base, "bin": name, "r_lo": float(lo), "r_hi": float(hi)}
        row["count"] = int(sel.sum())
        if row["count"]:
            row.update(_errors(r[sel], phi[sel], rh[sel], ph[sel]))
        else:
            row.update(dd_mape=math.nan, ad_mape=math.nan, dd_r2=math.nan, ad_r2=math.nan)
        row["flagged"] = int(fl[sel].sum())
        row["seconds"] = seconds
        rows.append({k: row[k] for k in COLUMNS})
    return rows


def limit_curve(
    domain: Domain,
    prior: str = "single",
    n: int = 4000,
    seed: int = 0,
    bin_width: float = BIN_WIDTH,
) -> dict[str, np.ndarray]:
    """DD and AD limit (MAPE %) against distance for one design: the app's Eye design dock.

    A small study point (n test elements); returns arrays ``r`` (bin centres),
    ``dd_mape``, ``ad_mape`` and ``count``.
    """
    p = DesignPoint(
        domain.h, domain.l, domain.m, domain.r_min, domain.r_max, domain.g_max, prior, n, seed
    )
    rows = [row for row in evaluate(p, bin_width) if row["bin"] != "all"]
    return {
        "r": np.array([0.5 * (row["r_lo"] + row["r_hi"]) for row in rows]),
        "dd_mape": np.array([row["dd_mape"] for row in rows]),
        "ad_mape": np.array([row["ad_mape"] for row in rows]),
        "count": np.array([row["count"] for row in rows]),
    }
