"""What grades are worth: a Cramer-Rao bound on distance from graded responses (issue 34.5).

**The noise model.** Each lit facet counts photons: n_i ~ Poisson(N R_i(theta)), with
R_i the exact graded response (``eyes.responses``, docs/responses.md) of facet i of
either eye to the ball theta = (x, y, g) (planar) or (x, y, z, g), and N the photons a
facet catches at full coverage (a dark background: an unlit facet counts nothing). The
counts of different facets are independent. The Fisher information of theta is

    J(theta) = N sum_i grad R_i grad R_i^T / R_i        (over the facets with R_i > 0),

so the Cramer-Rao bound on an unbiased estimate of the distance r = |c - o| (o the
domain's origin) is var(r) >= grad r^T J^-1 grad r = C(theta) / N, C the bound at N = 1:
the relative error sqrt(C / N) / r falls as 1 / sqrt(N).

**The derivatives** are central differences of the exact responses, step h = 1e-6 r in
each coordinate (g included), computed again at h / 2: the two bounds' relative
difference is reported per model (their error is O(h^2) on a smooth piece). A step that
crosses a facet's edge, where a response has a kink, shows up there: a ball whose bound
changes by more than 1e-3 is done again at h / 64 and h / 128, and if it still has not
settled it keeps the larger bound of the two (less information: conservative) and is
counted. A facet whose
response is 0 at theta (tangency) adds nothing; one lit only by a step (its edge within
h of the ball) is dropped, which can only raise the bound.

**The binary limit** beside it: the relative RMS error of r of the best estimate from the
bitmaps the project has for that model, on the same balls: the planar information limit
(:mod:`eyeviz.estimators.limit`, the posterior's MAPE-optimal answer), limit3d for the
HEALPix eyes and for a measured pair (where limit3d refuses a measured pair, the
analytic triangulation, :func:`eyeviz.estimators.analytic3d.estimate_measured`, an upper
bound of the limit).

Grades beat the bitmaps, in RMS relative error over the balls, from
N* = mean(C / r^2) / (binary RMS)^2 photons a facet.

Caveats: the bound is local and for unbiased estimators (an efficient estimator reaches
it as N grows; at small N it is optimistic), it ignores the prior the binary limit uses
(which only helps the bitmaps), and it assumes the responses' kernel is the eye's.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from scipy import sparse

from eyeviz.reports.errors import N_BOOT

#: The photons a facet catches at full coverage (--photons): the report's default.
DEFAULT_PHOTONS = 1000
#: The relative step of the finite differences.
STEP = 1e-6
#: The largest relative change of sqrt(C) from h to h / 2 taken as converged.
FD_TOL = 1e-3

ResponseFn = Callable[[np.ndarray], sparse.csr_matrix]


@dataclass
class ModelResult:
    name: str
    description: str
    kind: str
    binary_name: str
    n_balls: int
    r: np.ndarray  # the balls' distances
    crb1: np.ndarray  # C(theta): the bound on var(r) at N = 1
    binary_rel: np.ndarray  # (r_hat - r) / r of the binary estimate
    fd_change: float  # median relative change of sqrt(C) from h to h / 2
    fd_change_max: float
    dropped: int = 0  # balls whose J is singular (fewer informative facets than unknowns)
    unresolved: int = 0  # balls whose finite differences did not settle (kept conservative)
    notes: list[str] = field(default_factory=list)

    @property
    def ok(self) -> np.ndarray:
        """The balls both sides answer (a finite bound and a binary estimate)."""
        return np.isfinite(self.crb1) & np.isfinite(self.binary_rel)

    @property
    def binary_rms(self) -> float:
        return float(np.sqrt(np.mean(self.binary_rel[self.ok] ** 2)))

    def graded_rms(self, photons: float) -> float:
        ok = self.ok
        return float(np.sqrt(np.mean(self.crb1[ok] / self.r[ok] ** 2) / photons))

    @property
    def binary_median(self) -> float:
        """The median |relative error| of the binary estimate."""
        return float(np.median(np.abs(self.binary_rel[self.ok])))

    def graded_median(self, photons: float) -> float:
        """The median |relative error| of an efficient estimate (Gaussian, at the bound)."""
        ok = self.ok
        return float(0.6745 * np.median(np.sqrt(self.crb1[ok] / photons) / self.r[ok]))

    @property
    def crossover_median(self) -> float:
        """N* in medians of |relative error|."""
        return self.graded_median(1.0) ** 2 / self.binary_median**2

    @property
    def crossover(self) -> float:
        """N*: the photons a facet from which grades beat the bitmaps (RMS)."""
        return self.graded_rms(1.0) ** 2 / self.binary_rms**2


def _csr(pair: tuple, m: int) -> sparse.csr_matrix:
    indptr, indices, values = pair
    n = len(indptr) - 1
    return sparse.csr_matrix((values, indices, indptr), shape=(n, m))


def planar_fn(eyes) -> ResponseFn:
    """theta (n, 3) = (x, y, g) -> responses of both eyes, (n, 2m) sparse."""

    def fn(t: np.ndarray) -> sparse.csr_matrix:
        a, b = eyes.responses(t[:, 0], t[:, 1], t[:, 2], kind="cell")
        return sparse.hstack([_csr(a, eyes.m), _csr(b, eyes.m)], format="csr")

    return fn


def measured_fn(pair, kind: str) -> ResponseFn:
    """theta (n, 4) = (x, y, z, g) -> responses of both eyes, (n, n_A + n_B) sparse."""
    na, nb = (int(k) for k in pair.facet_counts)

    def fn(t: np.ndarray) -> sparse.csr_matrix:
        a, b = pair.responses(t[:, 0], t[:, 1], t[:, 2], t[:, 3], kind=kind)
        return sparse.hstack([_csr(a, na), _csr(b, nb)], format="csr")

    return fn


def healpix_fn(pair) -> ResponseFn:
    """theta (n, 4) = (x, y, z, g) -> the HEALPix pair's exact ``cell`` responses of both
    eyes (each lit cell's share of its area inside the ball's cap), (n, 2 npix) sparse."""
    m = int(pair.npix)

    def fn(t: np.ndarray) -> sparse.csr_matrix:
        a, b = pair.responses(t[:, 0], t[:, 1], t[:, 2], t[:, 3], kind="cell")
        return sparse.hstack([_csr(a, m), _csr(b, m)], format="csr")

    return fn


def _information(fn: ResponseFn, theta: np.ndarray, h: np.ndarray) -> np.ndarray:
    """J(theta) / N for each ball: (n, P, P), by central differences of step h (n,)."""
    n, p = theta.shape
    base = fn(theta)
    grads = []
    for k in range(p):
        step = np.zeros_like(theta)
        step[:, k] = h
        d = (fn(theta + step) - fn(theta - step)).multiply(1.0 / (2 * h)[:, None]).tocsr()
        grads.append(d)
    # 1 / R on the facets lit at theta; 0 elsewhere (dropped: lit only by a step)
    inv = base.copy()
    inv.data = np.where(inv.data > 0, 1.0 / np.where(inv.data > 0, inv.data, 1.0), 0.0)
    J = np.zeros((n, p, p))
    for k in range(p):
        gk_inv = grads[k].multiply(inv)
        for j in range(k, p):
            v = np.asarray(gk_inv.multiply(grads[j]).sum(axis=1)).ravel()
            J[:, k, j] = J[:, j, k] = v
    return J


def _bounds(fn: ResponseFn, theta: np.ndarray, grad: np.ndarray, h: np.ndarray) -> np.ndarray:
    J = _information(fn, theta, h)
    bound = np.full(len(theta), np.inf)
    for i in range(len(theta)):
        with np.errstate(all="ignore"):
            if np.all(np.isfinite(J[i])) and np.linalg.cond(J[i]) < 1e14:
                bound[i] = float(grad[i] @ np.linalg.solve(J[i], grad[i]))
    return bound


def crb_distance(
    fn: ResponseFn, theta: np.ndarray, origin: np.ndarray, rel_step: float = STEP
) -> tuple[np.ndarray, np.ndarray, int]:
    """(C, change, unresolved): the Cramer-Rao bound on var(r) at N = 1 for balls theta
    (n, P) whose first P - 1 coordinates are the centre (inf where J is singular); the
    relative change of sqrt(C) from step h to h / 2; the balls still above FD_TOL after
    a retry at h / 64 and h / 128, which keep the larger (less informative) of the two."""
    c = theta[:, :-1] - origin
    r = np.linalg.norm(c, axis=1)
    grad = np.concatenate([c / r[:, None], np.zeros((len(r), 1))], axis=1)
    h = rel_step * r
    c1, c2 = _bounds(fn, theta, grad, h), _bounds(fn, theta, grad, h / 2)
    change = _change(c1, c2)
    bad = change > FD_TOL
    if bad.any():
        t, g, hb = theta[bad], grad[bad], h[bad] / 64
        d1, d2 = _bounds(fn, t, g, hb), _bounds(fn, t, g, hb / 2)
        c1[bad], c2[bad], change[bad] = d1, d2, _change(d1, d2)
    still = change > FD_TOL
    out = np.where(still, np.maximum(c1, c2), c2)
    return out, change, int(still.sum())


def _change(c1: np.ndarray, c2: np.ndarray) -> np.ndarray:
    with np.errstate(all="ignore"):
        ch = np.abs(np.sqrt(c2) / np.sqrt(c1) - 1)
    same = np.isinf(c1) & np.isinf(c2)
    return np.where(np.isfinite(c1) & np.isfinite(c2), ch, np.where(same, 0.0, np.inf))


def fd_check(change: np.ndarray) -> tuple[float, float]:
    """The median and the largest relative change of sqrt(C) from step h to h / 2 (balls
    with a finite bound)."""
    ok = np.isfinite(change)
    if not ok.any():
        return math.nan, math.nan
    return float(np.median(change[ok])), float(change[ok].max())


#: The statistics :func:`ball_bootstrap` gives errors for (graded ones at N = 1 photon;
#: the graded RMS and median scale as 1 / sqrt(N), their errors likewise).
STATS = ("binary_rms", "graded_rms", "binary_median", "graded_median", "crossover",
         "crossover_median")  # fmt: skip


def _stats(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """The six :data:`STATS` of resamples: a (k, n) squared binary relative errors, b (k, n)
    the bound's squared relative error at N = 1 (C / r^2), per row."""
    brms, grms = np.sqrt(a.mean(axis=1)), np.sqrt(b.mean(axis=1))
    bmed, gmed = np.sqrt(np.median(a, axis=1)), 0.6745 * np.sqrt(np.median(b, axis=1))
    return np.stack([brms, grms, bmed, gmed, grms**2 / brms**2, gmed**2 / bmed**2], axis=1)


@dataclass
class BallErrors:
    """Bootstrap errors over the balls of a :class:`ModelResult`'s figures: the balls both
    sides answer (``ModelResult.ok``) resampled with replacement ``n_boot`` times and every
    statistic recomputed on each resample. ``se`` is the standard deviation of the
    resampled statistic (graded ones at N = 1); ``low``/``high`` the 2.5 and 97.5
    percentiles (the interval given for the crossovers, whose spread is skewed)."""

    se: dict[str, float]
    low: dict[str, float]
    high: dict[str, float]

    def graded_rms_se(self, photons: float) -> float:
        return self.se["graded_rms"] / math.sqrt(photons)

    def graded_median_se(self, photons: float) -> float:
        return self.se["graded_median"] / math.sqrt(photons)


def ball_bootstrap(m: ModelResult, n_boot: int = N_BOOT, seed: int = 0) -> BallErrors:
    """:class:`BallErrors` of ``m`` from ``n_boot`` resamples of its balls (a fixed seed: a
    report is reproducible). NaN errors for fewer than two balls."""
    ok = m.ok
    a = m.binary_rel[ok] ** 2
    b = m.crb1[ok] / m.r[ok] ** 2
    n = a.size
    if n < 2:
        nan = dict.fromkeys(STATS, math.nan)
        return BallErrors(nan, dict(nan), dict(nan))
    rng = np.random.default_rng(seed)
    vals = np.empty((n_boot, len(STATS)))
    chunk = max(1, 2_000_000 // n)  # bounded memory
    for lo in range(0, n_boot, chunk):
        idx = rng.integers(0, n, size=(min(chunk, n_boot - lo), n))
        with np.errstate(all="ignore"):
            vals[lo : lo + len(idx)] = _stats(a[idx], b[idx])
    with np.errstate(all="ignore"):
        se = np.std(vals, axis=0, ddof=1)
        low, high = np.nanpercentile(vals, 2.5, axis=0), np.nanpercentile(vals, 97.5, axis=0)
    return BallErrors(
        {k: float(v) for k, v in zip(STATS, se, strict=True)},
        {k: float(v) for k, v in zip(STATS, low, strict=True)},
        {k: float(v) for k, v in zip(STATS, high, strict=True)},
    )


def crossover_curve(results: list[ModelResult], photons: np.ndarray) -> dict[str, np.ndarray]:
    """Each model's graded RMS relative error at each photon count."""
    return {m.name: np.array([m.graded_rms(float(n)) for n in photons]) for m in results}


def _result(name, description, kind, binary_name, theta, origin, fn, r_hat, rel_step):
    r = np.linalg.norm(theta[:, :-1] - origin, axis=1)
    c, change, unresolved = crb_distance(fn, theta, origin, rel_step)
    med, mx = fd_check(change)
    res = ModelResult(name, description, kind, binary_name, len(r), r, c, (r_hat - r) / r, med, mx)
    res.dropped = int((~np.isfinite(c)).sum())
    res.unresolved = unresolved
    return res


def measure_planar(n: int, seed: int, rel_step: float = STEP) -> ModelResult:
    """The paper's planar design (Tables 3, 4): Algorithm 1's features, ``cell`` responses,
    the planar information limit."""
    from eyeviz.core.domain import PAPER_DOMAIN
    from eyeviz.dataset import kinds
    from eyeviz.estimators import limit

    ds = kinds.sample(n, PAPER_DOMAIN, seed=seed)
    eyes = ds.eyes
    x, y = ds.r * np.cos(ds.phi), ds.r * np.sin(ds.phi)
    theta = np.stack([x, y, ds.g], axis=1)
    p = limit.load().predict_intervals(*eyes.intervals(x, y, ds.g))
    return _result(
        "planar",
        f"the paper's planar design (m = {eyes.m}, h = {eyes.h:g})",
        "cell",
        "information limit (limit)",
        theta,
        np.zeros(2),
        planar_fn(eyes),
        np.asarray(p[0], float),
        rel_step,
    )


def measure_measured(
    name: str, pair, n: int, seed: int, kind: str = "gaussian", rel_step: float = STEP
) -> ModelResult:
    """A measured pair at its own scale (domain_for), Algorithm 1 in 3D; the
    binary side is limit3d (the analytic triangulation where limit3d refuses the pair)."""
    from eyeviz import EyevizError
    from eyeviz.core.domain import domain_for
    from eyeviz.dataset import kinds
    from eyeviz.estimators import limit3d
    from eyeviz.estimators.analytic3d import estimate_measured

    dom = domain_for(pair)
    ds = kinds.sample(n, dom, seed=seed)
    theta = np.stack([ds.x, ds.y, ds.z, ds.g], axis=1)
    lit_a, lit_b = (ds.indptr_a, ds.indices_a), (ds.indptr_b, ds.indices_b)
    try:
        r_hat, binary = limit3d.load(dom).predict(lit_a, lit_b)[0], "information limit (limit3d)"
    except EyevizError:
        r_hat, binary = estimate_measured(dom, lit_a, lit_b)[0], "analytic triangulation"
    return _result(
        name,
        f"{name} ({pair.facet_counts[0] + pair.facet_counts[1]:,} facets), {kind} kernel",
        kind,
        binary,
        theta,
        np.asarray(dom.origin),
        measured_fn(pair, kind),
        np.asarray(r_hat, float),
        rel_step,
    )


def measure_healpix(nside: int, n: int, seed: int, rel_step: float = STEP) -> ModelResult:
    """The HEALPix pair at ``nside``: the binary side is limit3d on its cells; the graded
    side the pair's exact ``cell`` responses (:func:`healpix_fn`)."""
    from eyeviz.core.domain import domain_for
    from eyeviz.core.geometry3d import EyePair3D
    from eyeviz.dataset import kinds
    from eyeviz.estimators import limit3d

    dom = domain_for(EyePair3D(nside=nside))
    ds = kinds.sample(n, dom, seed=seed)
    theta = np.stack([ds.x, ds.y, ds.z, ds.g], axis=1)
    p = limit3d.load(dom).predict((ds.indptr_a, ds.indices_a), (ds.indptr_b, ds.indices_b))
    return _result(
        f"nside {nside}",
        f"HEALPix nside {nside} (exact cell responses)",
        "cell",
        "information limit (limit3d)",
        theta,
        np.zeros(3),
        healpix_fn(dom.eyes),
        np.asarray(p[0], float),
        rel_step,
    )
