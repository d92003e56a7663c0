"""One design point of the eye-design study, for every eye model: its rows of errors.

Planar eyes (:class:`DesignPoint`, :func:`evaluate`): a design point is an eye design
(h, l, m; Table 3) with the object ranges (Table 4), a prior ("single" or "multi" pass,
Section 5), a test-set size n and a seed. Its test set is drawn from that design's
Algorithm 1 (:func:`eyeviz.dataset.algorithm1.iter_chunks`, interval form, no bitmaps
held), and every element is estimated by the information limit
(:class:`eyeviz.estimators.limit.LimitEstimator`): the MAPE-optimal posterior median given
the bitmaps, the best any estimator can do (issue 10). The errors are MAPE (Eq. 34) and
R^2 (Eq. 35, standard form, docs/conventions.md), overall and per distance bin.

Eyes that see lit sets (:class:`DesignPoint3D` for the spherical eyes; the measured
pairs' point, :mod:`eyeviz.study.point_measured`; :func:`evaluate3d`): a design of the two
spherical eyes (h, l, nside; docs/spherical.md) with the object ranges (r, g and the
elevation band |el| <= el_max), a prior, a test-set size n, a seed and the *estimator*
whose error is measured. Its test set is drawn from the design's Algorithm 1 in 3D
(:func:`eyeviz.dataset.algorithm1_3d.iter_chunks3d`, sparse lit sets, no bitmaps held)
and every element is estimated from the two lit sets alone.

The estimator is a parameter of such a point (the ``estimator`` column of the table), an
estimator of the spherical eyes from the registry,
``registry.load(name, domain=Domain3D(...))``, whose ``predict(lit_a, lit_b)`` takes the
CSR lit sets ``(indptr, indices)`` per eye and answers (r, azimuth, elevation) with
``valid`` and ``flagged`` masks: ``"limit3d"`` (the exact posterior, the
accuracy limit the study is for), ``"analytic3d"`` (the default: the closest approach of
the rays along the two lit caps' mean directions, an upper bound on the limit's MAPE) or
``"learned3d"`` (for the design its weights were trained on).

The errors per row of the lit sets' table: DD and AD MAPE (%) and R^2 (Eqs. 34-35, as the
planar study), the mean absolute elevation and azimuth error in degrees (MAPE is no
measure for an elevation that crosses 0) and the elevation's R^2, with the sampling
errors of the DD and the elevation error (``dd_se``, ``el_se``: bootstrap standard errors
over the bin's rows, NaN for a bin of one row; version 2 of the table); overall (bin
``"all"``), per distance bin (``"r0"``, ``"r1"``, ... of :data:`BIN_WIDTH`) and per
elevation bin (``"e0"`` ... ``"e5"``: :data:`EL_BINS` equal bins of [-el_max, el_max]).
``gamma`` is the equatorial facet width 2 pi / (4 nside), the planar gamma of the z = 0
slice (the one the γ r / (2h) law is stated in).

Both kinds of point share the binning (:func:`_bins`) and the rows (:func:`_rows`): only
the test set's sampler, the estimator and the errors differ with the model.

Pure: the same point gives the same rows except ``seconds``. No dask here: workers call
:func:`evaluate` or :func:`evaluate3d` with the point (a few numbers), never with arrays.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

from eyeviz import EyevizError
from eyeviz.core.domain import DEFAULT_EL_MAX, DEFAULTS, Domain, Domain3D
from eyeviz.core.validation import check_choice, check_int
from eyeviz.estimators.limit import PRIORS, LimitEstimator
from eyeviz.estimators.metrics import bootstrap_se, mape, r2

__all__ = [
    "BIN_WIDTH",
    "COLUMNS",
    "COLUMNS3D",
    "DEFAULT_ESTIMATOR",
    "EL_BINS",
    "STUDY3D_VERSION",
    "STUDY_VERSION",
    "DesignPoint",
    "DesignPoint3D",
    "distance_bins",
    "elevation_bins",
    "evaluate",
    "evaluate3d",
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
    from eyeviz.dataset import kinds

    t0 = time.perf_counter()
    d = point.domain
    est = LimitEstimator(d, point.prior)
    parts: dict[str, list[np.ndarray]] = {k: [] for k in ("r", "phi", "rh", "ph", "fl")}
    for c in kinds.chunks(point.n, d, point.prior, point.seed):
        p = est.predict_intervals(c.la, c.ra, c.lb, c.rb)
        if not np.all(p.valid):
            raise EyevizError("the limit could not answer a generated element (a bug)")
        for k, v in zip(parts, (c.r, c.phi, p.r, p.phi, p.flagged), strict=True):
            parts[k].append(np.asarray(v))
    r, phi, rh, ph, fl = (np.concatenate(v) for v in parts.values())
    seconds = time.perf_counter() - t0
    base = {"version": STUDY_VERSION, **point.to_dict(), "gamma": 2 * math.pi / point.m}
    bins = [("all", point.r_min, point.r_max, np.ones(r.size, bool))]
    bins += _bins("", r, distance_bins(point.r_min, point.r_max, bin_width))

    def errors(sel):
        return _errors(r[sel], phi[sel], rh[sel], ph[sel])

    metrics = ("dd_mape", "ad_mape", "dd_r2", "ad_r2")
    return _rows(base, bins, errors, metrics, fl, seconds, COLUMNS, ("r_lo", "r_hi"))


def _bins(
    prefix: str, values: np.ndarray, edges: np.ndarray
) -> list[tuple[str, float, float, Any]]:
    """(name, lo, hi, the rows in it) of each bin of ``edges`` over ``values``: [lo, hi),
    the last bin closed; named ``prefix`` and its number."""
    out = []
    for i in range(edges.size - 1):
        lo, hi = float(edges[i]), float(edges[i + 1])
        last = i == edges.size - 2
        sel = (values >= lo) & ((values <= hi) if last else (values < hi))
        out.append((f"{prefix}{i}", lo, hi, sel))
    return out


def _rows(
    base: dict,
    bins: list[tuple[str, float, float, Any]],
    errors: Callable[[Any], dict[str, float]],
    metrics: tuple[str, ...],
    fl: np.ndarray,
    seconds: float,
    columns: tuple[str, ...],
    bounds: tuple[str, str] = ("lo", "hi"),
) -> list[dict]:
    """One table row per bin: the design (``base``), the bin and its ``bounds``, how many
    rows fell in it, their ``errors`` (NaN for each of ``metrics`` in an empty bin), how
    many were flagged, and the point's ``seconds``; in ``columns`` order."""
    rows = []
    for name, lo, hi, sel in bins:
        row = {**base, "bin": name, bounds[0]: float(lo), bounds[1]: float(hi)}
        row["count"] = int(sel.sum())
        row.update(errors(sel) if row["count"] else dict.fromkeys(metrics, math.nan))
        row["flagged"] = int(fl[sel].sum())
        row["seconds"] = seconds
        rows.append({k: row[k] for k in columns})
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


# --- eyes that see lit sets: the spherical (and, through point_measured, measured) eyes ---
#: Version of the 3D study table's columns; a file with another version is refused.
#: 2: the sampling errors dd_se and el_se per bin (issue 38.3)
STUDY3D_VERSION = 2
#: Equal elevation bins over [-el_max, el_max] (10 degrees each at the default 30).
EL_BINS = 6
#: The default estimator: the closest-approach triangulation of the lit caps' mean
#: directions (:mod:`eyeviz.estimators.analytic3d`), for any design.
DEFAULT_ESTIMATOR = "analytic3d"
#: The 3D study table's columns, in order: one row per design point and bin ("all" first,
#: then the distance bins "r0", "r1", ..., then the elevation bins "e0" ... "e5").
#: ``lo``/``hi``: the bin's range of r (rows "all" and "r*") or of the elevation in
#: radians (rows "e*").
COLUMNS3D = (
    "version",
    "h",
    "l",
    "nside",
    "m",
    "gamma",
    "r_min",
    "r_max",
    "g_max",
    "el_max",
    "prior",
    "n",
    "seed",
    "estimator",
    "bin",
    "lo",
    "hi",
    "count",
    "dd_mape",
    "dd_se",
    "ad_mape",
    "el_mae_deg",
    "el_se",
    "az_mae_deg",
    "dd_r2",
    "ad_r2",
    "el_r2",
    "flagged",
    "seconds",
)
_PRIORS = ("single", "multi")
_MAX_NAME = 40


@dataclass(frozen=True)
class DesignPoint3D:
    """One design of the spherical eyes, its test set and the estimator measured."""

    h: float = DEFAULTS["h"]
    l: float = DEFAULTS["l"]  # noqa: E741  (the paper's name)
    nside: int = int(DEFAULTS["m"]) // 4
    r_min: float = DEFAULTS["r_min"]
    r_max: float = DEFAULTS["r_max"]
    g_max: float = DEFAULTS["g_max"]
    el_max: float = DEFAULT_EL_MAX
    prior: str = "single"
    n: int = 20_000
    seed: int = 0
    estimator: str = DEFAULT_ESTIMATOR

    def __post_init__(self) -> None:
        from eyeviz.dataset.algorithm1_3d import make_params3d

        check_choice("prior", self.prior, _PRIORS)
        check_int("n", self.n, ge=1)
        check_int("seed", self.seed, ge=0)
        e = self.estimator
        if not (isinstance(e, str) and 0 < len(e) <= _MAX_NAME and e.isidentifier()):
            raise EyevizError(f"estimator must be an estimator's name, got {e!r}")
        make_params3d(self.domain, self.prior, self.seed)  # named messages: no ball fits

    @property
    def domain(self) -> Domain3D:
        return Domain3D(self.h, self.l, self.nside, self.r_min, self.r_max, self.g_max, self.el_max)

    @property
    def m(self) -> int:
        """Facets on the equator, 4 nside (the planar m of the z = 0 slice)."""
        return 4 * int(self.nside)

    @property
    def key(self) -> tuple:
        """What identifies a finished point in a 3D study file (resume skips it)."""
        return (
            float(self.h),
            float(self.l),
            int(self.nside),
            float(self.r_min),
            float(self.r_max),
            float(self.g_max),
            float(self.el_max),
            self.prior,
            int(self.n),
            int(self.seed),
            self.estimator,
        )

    def to_dict(self) -> dict:
        return asdict(self)


def elevation_bins(el_max: float, k: int = EL_BINS) -> np.ndarray:
    """Edges of ``k`` equal elevation bins over [-el_max, el_max] (radians)."""
    return np.linspace(-el_max, el_max, k + 1)


def _load(point: Any):
    """A ``predict(lit_a, lit_b) -> (r, azimuth, elevation, flagged)`` for the point."""
    d = point.domain
    from eyeviz.estimators import registry

    est = registry.load(point.estimator, domain=d)

    def predict(la, lb):
        p = est.predict(la, lb)
        flagged = getattr(p, "flagged", None)
        if hasattr(p, "r"):
            r, az, el = p.r, p.azimuth, p.elevation
        else:
            r, az, el = p[0], p[1], p[2]
        valid = getattr(p, "valid", None)
        if valid is not None and not np.all(valid):
            raise EyevizError(f"{point.estimator} could not answer a generated element")
        fl = np.zeros(np.shape(r), bool) if flagged is None else np.asarray(flagged, bool)
        return np.asarray(r, float), np.asarray(az, float), np.asarray(el, float), fl

    return predict


def _errors3d(r, az, el, rh, ah, eh) -> dict[str, float]:
    deg = 180.0 / math.pi
    el_abs = np.abs(eh - el) * deg
    out = {
        "dd_mape": mape(r, rh),
        # the sampling errors of the bin's DD and elevation error: bootstrap over its rows
        "dd_se": bootstrap_se(100.0 * np.abs(rh - r) / np.abs(r)),
        "ad_mape": mape(az, ah),
        "el_mae_deg": float(np.mean(el_abs)),
        "el_se": bootstrap_se(el_abs),
        "az_mae_deg": float(np.mean(np.abs(ah - az)) * deg),
    }
    for name, y, yh in (("dd_r2", r, rh), ("ad_r2", az, ah), ("el_r2", el, eh)):
        out[name] = r2(y, yh) if y.size > 1 and np.ptp(y) > 0 else math.nan
    return out


_METRICS = ("dd_mape", "dd_se", "ad_mape", "el_mae_deg", "el_se", "az_mae_deg", "dd_r2",
            "ad_r2", "el_r2")  # fmt: skip


def evaluate3d(point: Any, bin_width: float = BIN_WIDTH) -> list[dict]:
    """Rows of the 3D study table for one point: ``"all"``, the distance bins ``"r<i>"``,
    the elevation bins ``"e<j>"`` (see this module's docstring for the columns)."""
    from eyeviz.dataset import kinds

    t0 = time.perf_counter()
    d = point.domain
    predict = _load(point)
    keys = ("r", "az", "el", "rh", "ah", "eh", "fl")
    parts: dict[str, list[np.ndarray]] = {k: [] for k in keys}
    for c in kinds.chunks(point.n, d, point.prior, point.seed):
        out = predict((c.indptr_a, c.indices_a), (c.indptr_b, c.indices_b))
        for k, v in zip(keys, (c.r, c.azimuth, c.elevation, *out), strict=True):
            parts[k].append(np.asarray(v))
    r, az, el, rh, ah, eh, fl = (np.concatenate(v) for v in parts.values())
    seconds = time.perf_counter() - t0
    # a measured eyes' point (eyeviz.study.point_measured) has its own version, columns,
    # h and l (of the reshaped pair) and gamma (its interommatidial angle)
    base = {"version": getattr(point, "VERSION", STUDY3D_VERSION), "h": point.h, "l": point.l,
            **point.to_dict(), "m": point.m,
            "gamma": getattr(point, "gamma", 2 * math.pi / point.m)}  # fmt: skip
    bins = [("all", point.r_min, point.r_max, np.ones(r.size, bool))]
    bins += _bins("r", r, distance_bins(point.r_min, point.r_max, bin_width))
    bins += _bins("e", el, elevation_bins(point.el_max))

    def errors(sel):
        return _errors3d(r[sel], az[sel], el[sel], rh[sel], ah[sel], eh[sel])

    columns = getattr(point, "COLUMNS", COLUMNS3D)
    return _rows(base, bins, errors, _METRICS, fl, seconds, columns)
