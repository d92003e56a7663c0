"""The information limit computed from the geometry: no training, no table (issue 10).

A bitmap pair is fully described by its key (LA, RA, LB, RB) (Prop. 2). The features
(x, y, g) producing a key form a convex polyhedron (:mod:`eyeviz.core.ambiguity`: eight
constraints linear in the centre and g jointly). The posterior given the key is
Algorithm 1's density restricted to that polyhedron. In polar (r, phi) and g it is

    p(r) * 1 / (g_max - r sin(gamma/2)) * 1 / (pi - 2 psi - 2 asin(g/r))

on r_min <= r, g in [r sin(gamma/2), g_max], phi in [psi + asin(g/r), pi - psi - asin(g/r)]
(steps 7-12; the rejections of Algorithm 1 only restrict the support), with p(r) = 1
("single") or p(r) proportional to r ("multi", Section 5); in (x, y, g) it gains the
Jacobian 1/r. For MAPE (Eq. 34) the best estimate any estimator can give from the bitmaps
is the 1/r-weighted posterior median of r and the 1/phi-weighted median of phi.

Integration (deterministic). Eye A's two tangent directions t- and t+ lie in sectors LA
and RA; the centre then lies on the ray from A at phi_A = (t- + t+)/2 with
g = rho sin(delta), delta = (t+ - t-)/2, rho the distance from A. Along that ray every
remaining constraint (eye B's four half-planes, the two BFV lines, g <= g_max) is linear
in rho and r_min <= r <= r_max, g >= r sin(gamma/2) are quadratic, so the feasible rho
form an interval found in closed form. The posterior is integrated with an n x n midpoint
grid over (t-, t+) in their sectors and K-point Gauss-Legendre in rho on each interval,
with the Jacobian rho^2 cos(delta) / 2 of (t-, t+, rho) -> (x, y, g). The weighted
medians interpolate the weighted CDF of the nodes.

Precision (measured, ``scripts/check_limit.py --precision``): with the default n = 12,
K = 6 (864 nodes per key) against n = 48, K = 16 on 400 distinct keys of a fresh
paper-design test set, the estimate of r differs by a median 1.1e-3 relative (99th
percentile 8e-3, max 9e-3) and phi by at most 3.4e-5 rad (99th percentile); the DD MAPE
of a 2*10^4-row test set moves by under 0.001 points between n = 12, K = 6 and
n = 24, K = 10 (the limit's own MAPE is about 7 %). Node arithmetic is float32. A key
whose polyhedron is a sliver the grid misses is retried on a 4n x 4n grid before it is
called empty; the feasible stretch of every ray is found before any node, so a key no
ray reaches (the prior cannot produce it) costs rays, never nodes. The 4n grid is tried
only when a ray of the 2n x 2n grid reaches the key: on the 91,240 distinct keys of
2*10^5 fresh paper-design rows (seed 31337), 5 keys had no feasible ray at n = 12, all 5
had one at 2n and at 4n, and none stayed empty; an impossible key then costs the rays of
the n and 2n grids (``scripts/bench_limit.py``: 1.6x a real key batched, 14x before).
The grid stays n = 12, K = 6: coarser ones measured past the bound above (n = 10, K = 4:
max 1.2e-2; n = 12, K = 4: 1.4e-2).

New keys are computed by :mod:`eyeviz.estimators.limit_solve` (issue 25): the same nodes
and medians with about half the work of the computation before issue 25 (per-design
trig tables, every ray quantity from one small matrix per key, nodes laid out for long
broadcasts, a 32-bit packed sort and a block-summed CDF for the medians;
``scripts/bench_limit.py`` measures both in one run). :func:`_reference_estimates`
keeps the straightforward computation (:func:`posterior_nodes`, :func:`weighted_median`);
the tests hold the two equal on ~11,000 keys from m = 8 to m = 2^20 up to float rounding,
and the precision table above comes out the same from either (``check_limit.py``: n =
12, K = 6 median 9.6e-4, p99 8.2e-3, max 9.0e-3 relative in r, p99 3.8e-5 rad in phi on
its 400 keys). Each key's answer is a function of that key alone, batched or not.
Keys the prior cannot produce (empty posterior, e.g. g = 5
beyond r = 1146, or a run touching the end of the half bitmap) are answered by analytic
triangulation and flagged in :attr:`LimitEstimator.last_flagged` /
:meth:`LimitEstimator.posterior` (``empty``).
"""

from __future__ import annotations

import functools
import math
from collections import OrderedDict
from dataclasses import dataclass

import numpy as np

from eyeviz.core.validation import check_int
from eyeviz.estimators import analytic, limit_solve
from eyeviz.estimators.base import PAPER_DOMAIN, Domain, Estimator
from eyeviz.estimators.limit_cache import _KeyCache
from eyeviz.estimators.limit_solve import interval_quadratic
from eyeviz.estimators.weighted import weighted_median

__all__ = ["LimitEstimator", "load", "PRIORS", "posterior_nodes", "posterior_samples"]

PRIORS = ("single", "multi")
_CACHE_SIZE = 1 << 18
#: largest grid size n and Gauss-Legendre order K a LimitEstimator takes
_MAX_N = 256
_MAX_K = 64


@dataclass(frozen=True)
class Nodes:
    """Quadrature nodes of the posterior for N keys: arrays (N, P)."""

    x: np.ndarray
    y: np.ndarray
    g: np.ndarray
    w: np.ndarray  # posterior weight (not normalised), 0 outside the support
    r: np.ndarray  # distance of the centre from the origin
    phi: np.ndarray  # azimuth of the centre


def _b_halfplanes(domain: Domain, LB, RB):
    """Eye B's constraints a . p + b g >= c as arrays (N, 4, 2), (4,), (N, 4)."""
    gam = 2.0 * math.pi / domain.m
    cx = domain.h
    idx = np.stack([LB, LB + 1, RB, RB + 1], axis=1).astype(np.float64)  # (N, 4)
    beta = idx * gam
    sign_g = np.array([1.0, 1.0, -1.0, -1.0])
    flip = np.array([1.0, -1.0, 1.0, -1.0])
    s, c = np.sin(beta), np.cos(beta)
    a = np.stack([-s, c], axis=-1) * flip[None, :, None]
    b = -flip * sign_g
    rhs = -flip[None, :] * cx * s
    return a, b, rhs


@dataclass(frozen=True)
class _Rays:
    """Eye A's rays for N keys, arrays (N, n*n): direction, sin/cos of the half angle
    delta, and the feasible interval [lo, hi] of the distance rho (``ok``: non-empty)."""

    cu: np.ndarray
    su: np.ndarray
    sd: np.ndarray
    cd: np.ndarray
    lo: np.ndarray
    hi: np.ndarray
    ok: np.ndarray


@functools.lru_cache(maxsize=16)
def _grid(n: int) -> tuple[np.ndarray, np.ndarray]:
    u = (np.arange(n) + 0.5) / n
    u1, u2 = (v.ravel() for v in np.meshgrid(u, u, indexing="ij"))
    u1.flags.writeable = False
    u2.flags.writeable = False
    return u1, u2


@functools.lru_cache(maxsize=16)
def _gauss(k: int) -> tuple[np.ndarray, np.ndarray]:
    gx, gw = np.polynomial.legendre.leggauss(k)
    gx, gw = gx.astype(np.float32), gw.astype(np.float32)
    gx.flags.writeable = False
    gw.flags.writeable = False
    return gx, gw


def _rays(keys: np.ndarray, domain: Domain, n: int) -> _Rays:
    """The feasible distance interval on each of the n x n rays of eye A (module docstring:
    eye B's half-planes and the BFV lines are linear in rho, the r and g bounds
    quadratic). Cheap next to the nodes: an empty key is found here without them."""
    LA, RA, LB, RB = keys.T
    gam = 2.0 * math.pi / domain.m
    s = math.sin(gam / 2)
    psi = math.asin(domain.l / domain.h)
    h = domain.h
    u1, u2 = _grid(n)
    tm = (LA[:, None] + u1[None, :]) * gam  # (N, n*n)
    tp = (RA[:, None] + u2[None, :]) * gam
    phiA = 0.5 * (tm + tp)
    delta = 0.5 * (tp - tm)
    ok = delta > 0
    cu, su = np.cos(phiA), np.sin(phiA)
    sd = np.sin(delta)
    # centre = (-h + rho cu, rho su), g = rho sd
    # the six linear constraints coef * rho >= rhs at once: eye B's four half-planes and
    # the two BFV lines (Prop. 4: the disc lies left of the line at psi and right of the
    # line at pi - psi)
    a, b, c = _b_halfplanes(domain, LB, RB)
    sp, cp = math.sin(psi), math.cos(psi)
    coef = np.empty((6, *phiA.shape))
    rhs = np.empty((6, *phiA.shape))
    for i in range(4):
        ax, ay = a[:, i, 0:1], a[:, i, 1:2]
        coef[i] = ax * cu + ay * su + b[i] * sd
        rhs[i] = c[:, i : i + 1] + ax * h
    coef[4] = -sp * cu + cp * su - sd
    rhs[4] = -sp * h
    coef[5] = sp * cu + cp * su - sd
    rhs[5] = sp * h
    with np.errstate(divide="ignore", invalid="ignore"):
        t = rhs / coef
    lo = np.maximum(np.max(np.where(coef > 0, t, -np.inf), axis=0), 0.0)
    hi = np.min(np.where(coef < 0, t, np.inf), axis=0)
    hi = np.where(((coef == 0) & (rhs > 0)).any(axis=0), -np.inf, hi)
    hi = np.minimum(hi, np.where(sd > 0, domain.g_max / np.maximum(sd, 1e-300), np.inf))
    # r^2 = rho^2 + 2 rho (A.u) + h^2 with A.u = -h cu
    au = -h * cu
    for rr, keep_above in ((domain.r_min, True), (domain.r_max, False)):
        disc = au * au - h * h + rr * rr
        # disc < 0 (eyes farther apart than rr, ray missing the circle): every point of
        # the ray is beyond rr, so r >= r_min holds everywhere and r <= r_max nowhere.
        # r <= r_max is rho in [near, far] (near > 0 only when h > r_max); r >= r_min is
        # rho >= far (plus rho <= near when h > r_min: that stretch beside eye A is left
        # out, a limitation for designs with the eyes farther apart than 2 r_min)
        sq = np.sqrt(np.maximum(disc, 0.0))
        if keep_above:
            lo = np.where(disc >= 0, np.maximum(lo, -au + sq), lo)
        else:
            hi = np.where(disc >= 0, np.minimum(hi, -au + sq), -np.inf)
            lo = np.where(disc >= 0, np.maximum(lo, -au - sq), lo)
    # g >= r sin(gamma/2):  (sd^2 - s^2) rho^2 - 2 s^2 (A.u) rho - s^2 h^2 >= 0
    qlo, qhi = interval_quadratic(
        sd * sd - s * s, -2 * s * s * au, np.full_like(au, -s * s * h * h)
    )
    lo = np.maximum(lo, qlo)
    hi = np.minimum(hi, qhi)
    ok &= np.isfinite(lo) & np.isfinite(hi) & (hi > lo)
    lo = np.where(ok, lo, 0.0)
    hi = np.where(ok, hi, 0.0)
    return _Rays(cu, su, sd, np.cos(delta), lo, hi, ok)


def _nodes(rays: _Rays, domain: Domain, prior: str, k: int) -> Nodes:
    """K Gauss-Legendre nodes in rho on each ray's feasible interval, with the posterior
    density (module docstring) times the Jacobian rho^2 cos(delta) / 2 as weight."""
    N = rays.cu.shape[0]
    s = math.sin(math.pi / domain.m)
    psi = math.asin(domain.l / domain.h)
    gx, gw = _gauss(k)
    f32 = np.float32  # node-level arithmetic in float32: 2x faster, rounding ~1e-7
    half = (0.5 * (rays.hi - rays.lo)).astype(f32)[..., None]
    rho = (0.5 * (rays.hi + rays.lo)).astype(f32)[..., None] + half * gx  # (N, n*n, k)
    x = f32(-domain.h) + rho * rays.cu.astype(f32)[..., None]
    y = rho * rays.su.astype(f32)[..., None]
    g = rho * rays.sd.astype(f32)[..., None]
    r = np.hypot(x, y)
    with np.errstate(divide="ignore", invalid="ignore"):
        width = f32(math.pi - 2 * psi) - f32(2) * np.arcsin(np.minimum(g / r, f32(1)))
        dens = (rho * rho) / (r * (f32(domain.g_max) - r * f32(s)) * width)
    if prior == "multi":
        dens *= r
    w = dens * (rays.cd.astype(f32)[..., None] * half) * gw
    w = np.where(rays.ok[..., None] & np.isfinite(w) & (w > 0), w, f32(0))
    phi = np.arctan2(y, x)
    return Nodes(*(v.reshape(N, -1) for v in (x, y, g, w, r, phi)))


def posterior_nodes(keys, domain: Domain, prior: str = "single", n: int = 12, k: int = 6) -> Nodes:
    """Quadrature nodes and weights of the posterior over (x, y, g) for keys (N, 4).

    Deterministic: n x n midpoints over eye A's tangent sectors, k Gauss-Legendre points
    in the distance from A on each ray (module docstring). Weights are zero where the
    prior gives no mass; an all-zero row is an empty posterior.
    """
    if prior not in PRIORS:
        raise ValueError(f"prior must be one of {PRIORS}, got {prior!r}")
    keys = np.asarray(keys, np.int64).reshape(-1, 4)
    return _nodes(_rays(keys, domain, n), domain, prior, k)


def limit_estimates(keys, domain: Domain, prior: str = "single", n: int = 12, k: int = 6):
    """(r, phi, empty) for keys (N, 4): MAPE-optimal estimates; NaN where ``empty``.

    A key none of whose rays has a feasible stretch is empty without computing nodes; a
    key the n x n grid finds empty is retried on a 4n x 4n grid (a sliver polyhedron can
    fall between the rays) when some ray of the 2n x 2n grid reaches it (module
    docstring), again nodes only where a ray is feasible. Computed by
    :func:`eyeviz.estimators.limit_solve.estimates` (the same nodes, organised for speed;
    equal to :func:`_reference_estimates` up to float rounding).
    """
    if prior not in PRIORS:
        raise ValueError(f"prior must be one of {PRIORS}, got {prior!r}")
    return limit_solve.estimates(keys, domain, prior, int(n), int(k))


def _reference_estimates(keys, domain: Domain, prior: str = "single", n: int = 12, k: int = 6):
    """:func:`limit_estimates` as computed before its fast path (kept as the reference
    the tests compare that path with): nodes through :func:`posterior_nodes`' own
    functions, medians by :func:`weighted_median`.

    A key none of whose rays has a feasible stretch is empty without computing nodes; a
    key the n x n grid finds empty is retried on a 4n x 4n grid (a sliver polyhedron can
    fall between the rays) when some ray of the 2n x 2n grid reaches it (module
    docstring), again nodes only where a ray is feasible.
    """
    if prior not in PRIORS:
        raise ValueError(f"prior must be one of {PRIORS}, got {prior!r}")
    keys = np.asarray(keys, np.int64).reshape(-1, 4)
    N = keys.shape[0]
    r_out = np.full(N, np.nan)
    p_out = np.full(N, np.nan)
    empty = np.ones(N, bool)
    step = max(1, 200_000 // (n * n * k))
    for s0 in range(0, N, step):
        rays = _rays(keys[s0 : s0 + step], domain, n)
        live = rays.ok.any(axis=1)
        if not live.any():
            continue
        if not live.all():
            rays = _Rays(*(a[live] for a in vars(rays).values()))
        nd = _nodes(rays, domain, prior, k)
        e = ~(nd.w.sum(axis=1) > 0)
        with np.errstate(divide="ignore", invalid="ignore"):
            wr = nd.w / np.where(nd.r > 0, nd.r, 1.0)
            wp = nd.w / np.where(nd.phi > 0, nd.phi, 1.0)
        if len(wr) <= 16:  # one call for both medians (rows are independent): less overhead
            both = weighted_median(np.concatenate([nd.r, nd.phi]), np.concatenate([wr, wp]))
            rr, pp = both[: len(wr)], both[len(wr) :]
        else:
            rr, pp = weighted_median(nd.r, wr), weighted_median(nd.phi, wp)
        idx = s0 + np.flatnonzero(live)
        r_out[idx] = np.where(e, np.nan, rr)
        p_out[idx] = np.where(e, np.nan, pp)
        empty[idx] = e
    # a sliver polyhedron can fall between the grid's rays: retry those keys on a 4x grid,
    # once a 2x grid's rays (a quarter of the 4x grid's) show that some ray reaches it
    again = np.flatnonzero(empty)
    if again.size and n < 48:
        again = again[_any_ray(keys[again], domain, 2 * n)]
    if again.size and n < 48:
        r2, p2, e2 = _reference_estimates(keys[again], domain, prior, 4 * n, k)
        r_out[again], p_out[again], empty[again] = r2, p2, e2
    return r_out, p_out, empty


def _any_ray(keys: np.ndarray, domain: Domain, n: int) -> np.ndarray:
    """Per key: does any ray of the n x n grid have a feasible stretch (no nodes)."""
    out = np.zeros(len(keys), bool)
    step = max(1, 40_000 // (n * n))  # ~40,000 rays a block: the six constraints in cache
    for s0 in range(0, len(keys), step):
        out[s0 : s0 + step] = _rays(keys[s0 : s0 + step], domain, n).ok.any(axis=1)
    return out


class LimitEstimator(Estimator):
    """MAPE-optimal posterior medians per key for any design and prior; cached per key.

    Predictions carry ``flagged`` (also ``last_flagged``): the rows answered by
    triangulation because the prior cannot produce their key (empty posterior); False on
    invalid rows.
    """

    name = "limit"

    def __init__(
        self,
        domain: Domain = PAPER_DOMAIN,
        prior: str = "single",
        n: int = 12,
        k: int = 6,
        cache_size: int = _CACHE_SIZE,
    ) -> None:
        if prior not in PRIORS:
            raise ValueError(f"prior must be one of {PRIORS}, got {prior!r}")
        super().__init__(domain, {"n_weights": 0, "train_seconds": 0.0, "prior": prior})
        self.prior = prior
        # the grid's n x n rays (4n x 4n on a retry) and K nodes per ray, bounded so a
        # key's nodes fit in memory; a cache of 0 keys keeps none
        self.n = check_int("n", n, ge=1, le=_MAX_N)
        self.k = check_int("k", k, ge=1, le=_MAX_K)
        self.cache_size = check_int("cache_size", cache_size, ge=0)
        w = self.domain.width
        # keys packed into one int64 while (m/2)^4 fits; tuples beyond (m > about 110,000),
        # where the packed code would overflow and make different keys share an answer
        self._packed = w**4 < 2**63
        self._cache: _KeyCache | OrderedDict[tuple, tuple[float, float, bool]] = (
            _KeyCache(self.cache_size) if self._packed else OrderedDict()
        )
        self.last_flagged = np.zeros(0, bool)
        self._parts: list[np.ndarray] = []
        self.hits = 0
        self.misses = 0

    def _solve(self, keys: np.ndarray):
        """(r, phi, empty) for distinct keys (M, 4); empty keys triangulated."""
        rr, pp, ee = limit_estimates(keys, self.domain, self.prior, self.n, self.k)
        if ee.any():
            e = keys[ee]
            fr, fp = analytic.estimate(e[:, 0], e[:, 1], e[:, 2], e[:, 3], self.domain)
            rr[ee], pp[ee] = fr, fp
        return rr, pp, ee

    def _predict_packed(self, LA, RA, LB, RB):
        w = self.domain.width
        code = ((LA * w + RA) * w + LB) * w + RB
        cache = self._cache
        assert isinstance(cache, _KeyCache)
        if code.size == 1:  # one row (a drag, one feature): the same answers, fewer calls
            return self._predict_one(cache, int(code[0]), LA, RA, LB, RB)
        vals, found, hits = cache.lookup(code)
        self.hits += hits
        if not found.all():
            miss = np.flatnonzero(~found)
            if miss.size == 1:  # one new row (np.unique costs more than the rest here)
                uniq, f, inv = code[miss], miss, np.zeros(1, np.intp)
            else:
                uniq, first, inv = np.unique(code[miss], return_index=True, return_inverse=True)
                f, inv = miss[first], inv.reshape(-1)
            keys = np.empty((f.size, 4), np.int64)
            for j, col in enumerate((LA, RA, LB, RB)):
                keys[:, j] = col[f]
            rr, pp, ee = self._solve(keys)
            new = np.empty((f.size, 3))
            new[:, 0], new[:, 1], new[:, 2] = rr, pp, ee
            vals[miss] = new[inv]
            cache.insert(uniq, new)
            self.misses += uniq.size
        return vals[:, 0], vals[:, 1], vals[:, 2] > 0

    def _predict_one(self, cache: _KeyCache, code: int, LA, RA, LB, RB):
        cache.tick += 1
        hit = cache.get(code)
        if hit is None:
            rr, pp, ee = self._solve(np.stack([LA, RA, LB, RB], axis=1))
            hit = (float(rr[0]), float(pp[0]), float(ee[0]))
            cache.insert_one(code, hit)
            self.misses += 1
        else:
            self.hits += 1
        return np.array(hit[:1]), np.array(hit[1:2]), np.array([hit[2] > 0])

    def _predict_tuples(self, LA, RA, LB, RB):
        rows = np.stack([LA, RA, LB, RB], axis=1)
        if len(rows) == 1:  # one row: np.unique(axis=0) costs more than the rest here
            uniq, inv = rows, np.zeros(1, np.intp)
        else:
            uniq, inv = np.unique(rows, axis=0, return_inverse=True)
            inv = inv.reshape(-1)
        codes = [tuple(k) for k in uniq.tolist()]
        cache = self._cache
        assert isinstance(cache, OrderedDict)
        nu = len(codes)
        out = np.empty((nu, 3))
        todo = []
        for j, c in enumerate(codes):
            hit = cache.get(c)
            if hit is None:
                todo.append(j)
            else:
                cache.move_to_end(c)
                out[j] = hit
        self.hits += nu - len(todo)
        self.misses += len(todo)
        if todo:
            t = np.asarray(todo)
            rr, pp, ee = self._solve(uniq[t])
            out[t] = np.stack([rr, pp, ee], axis=1)
            for j, a, b, e in zip(todo, rr.tolist(), pp.tolist(), ee.tolist(), strict=True):
                cache[codes[j]] = (a, b, e)
            while len(cache) > self.cache_size:
                cache.popitem(last=False)
        return out[inv, 0], out[inv, 1], out[inv, 2] > 0

    def _predict_intervals(self, LA, RA, LB, RB):
        LA, RA, LB, RB = (np.asarray(v, np.int64) for v in (LA, RA, LB, RB))
        if self._packed:
            r, phi, flagged = self._predict_packed(LA, RA, LB, RB)
        else:
            r, phi, flagged = self._predict_tuples(LA, RA, LB, RB)
        self.last_flagged = flagged
        self._parts.append(flagged)
        return r, phi

    def _with_flags(self, call, *args):
        self._parts = []
        p = call(*args)
        valid = np.atleast_1d(p.valid)
        flagged = np.zeros(valid.shape, bool)
        if self._parts:
            flagged[valid] = (
                self._parts[0] if len(self._parts) == 1 else np.concatenate(self._parts)
            )
        p.flagged = flagged[0] if np.ndim(p.valid) == 0 else flagged
        self.last_flagged = p.flagged
        return p

    def predict(self, omega_a, omega_b):
        """As :meth:`Estimator.predict`, plus ``flagged``: rows with an empty posterior,
        answered by analytic triangulation (also in :attr:`last_flagged`)."""
        return self._with_flags(super().predict, omega_a, omega_b)

    def predict_intervals(self, LA, RA, LB, RB):
        """As :meth:`Estimator.predict_intervals`, plus the ``flagged`` mask."""
        return self._with_flags(super().predict_intervals, LA, RA, LB, RB)

    def __repr__(self) -> str:
        d = self.domain
        return (
            f"<LimitEstimator h={d.h:g} l={d.l:g} m={d.m} r=[{d.r_min:g}, {d.r_max:g}] "
            f"g_max={d.g_max:g} prior={self.prior}>"
        )


def posterior_samples(
    key, domain: Domain = PAPER_DOMAIN, prior: str = "single", n: int = 24, k: int = 8
):
    """Weighted posterior points over the feature's ambiguity, for one key, Qt-free.

    ``key``: (LA, RA, LB, RB) or a pair of half bitmaps (omega_a, omega_b). Returns a dict
    with arrays ``x, y, g, weight`` (weights sum to 1; the points cover every g the key
    allows), the estimate ``r, phi`` (MAPE-optimal) and ``empty`` (True: the prior cannot
    produce the key; no points, and the estimate is the analytic triangulation).
    """
    if isinstance(key, tuple | list) and len(key) == 2:
        from eyeviz.estimators.base import bitmaps_to_intervals

        LA, RA, LB, RB, ok = bitmaps_to_intervals(
            np.atleast_2d(key[0]), np.atleast_2d(key[1]), domain.width
        )
        if not ok[0]:
            raise ValueError("the bitmaps are not one lit run per eye")
        key = (int(LA[0]), int(RA[0]), int(LB[0]), int(RB[0]))
    key = tuple(int(v) for v in key)
    if len(key) != 4:
        raise ValueError(f"key must be (LA, RA, LB, RB), got {key!r}")
    nd = posterior_nodes([key], domain, prior, n, k)
    w = nd.w[0]
    tot = w.sum()
    keep = w > 0
    est = LimitEstimator(domain, prior, n, k)
    pred = est.predict_intervals(*key)
    r, phi = np.atleast_1d(pred.r), np.atleast_1d(pred.phi)
    return {
        "x": nd.x[0][keep],
        "y": nd.y[0][keep],
        "g": nd.g[0][keep],
        "weight": (w[keep] / tot) if tot > 0 else w[keep],
        "r": float(r[0]),
        "phi": float(phi[0]),
        "empty": bool(pred.flagged),
    }


def load(domain: Domain = PAPER_DOMAIN, prior: str = "single", **kw) -> LimitEstimator:
    return LimitEstimator(domain, prior, **kw)
