"""The information limit of the spherical eyes: the posterior under the 3D Algorithm 1 prior.

The likelihood of a ball (x, y, z, g) given a key (the two eyes' lit sets) is 0/1: 1
exactly when ``EyePair3D.lit_csr`` of the ball gives both lit sets (docs/spherical.md,
3D Proposition 2). The posterior is the prior of :mod:`eyeviz.dataset.algorithm1_3d`
restricted to those balls. In (r, g, el, az) the single-pass prior's density is

    1 / (g_max - r sin(gamma/2)) * 1 / (pi - 2 az0(r, g, el))

on r in [r_min, r_max], g in [r sin(gamma/2), g_max], |el| <= el_max, az in
[az0, pi - az0] with cos(az0) = cos(psi + asin(g/r)) / cos(el) (steps 7-12; its
rejections, the 3D field test and Definition 1, only restrict the support). The multi-pass
prior has r^2 cos(el) / (g_max - r sin(gamma/2)) / (pi - 2 az0(r, g, el_max)) (its
segment quotas are treated as the r^2 density they approximate). In (x, y, z, g) both
gain the Jacobian 1 / (r^2 cos el).

**Proposal (importance sampling).** The posterior's support is a sliver: at nside 180 a
ball lighting 1,000 facets per eye is pinned to about a hundredth of a facet in
direction. So the proposal is built from each eye's feasible caps, as the planar limit
integrates over eye A's tangent sectors and then along the ray (:mod:`.limit`):

1. Per eye, the cells where the cap's edge can lie: the key's lit cells that a cap
   ``EDGE`` facet widths smaller than the lit set's cap (:func:`.analytic3d.cap_estimates`)
   does not light, and the unlit cells a cap as much larger lights. For each, its
   boundary point nearest the cap centre (``STEP`` points per edge) linearises its
   distance to a cap centre c near the estimate: dist(c) ~ d - t . delta (delta: c in
   gnomonic coordinates about the estimate). The cap (c, alpha) lights exactly the key's
   cells only if alpha > dist for every lit edge cell and alpha <= dist for every unlit
   one, so the feasible centres are where G(delta) = min_unlit - max_lit > 0 (concave),
   and alpha lies in (max_lit, min_unlit] there. Both are affine forms in delta (the
   unlit distances squared), one product and one reduction per evaluation.
2. Per eye: G on a grid about the estimate, the centre moved to its best point and the
   distances modelled again there (zooming grids); the box holding every centre with
   G >= -slack (bisection along ``NDIR`` directions). The slack is the search window's
   (0.002 facet widths) or, for a box far smaller than the window (a thin posterior),
   ``SLACK_SAFETY`` times the model's second-order error in the box, R^2 (1/alpha + 1).
3. Eye A's centre: uniform in (theta, phi) over the bounds of A's box, theta = atan2(z, y)
   (the angle of the plane through the baseline) cut to the bounds of B's box: a ball's
   centre and both caps' centres share one theta, so B bounds it too. Draws outside A's
   box are dropped (the model region lies in it).
4. Along the ray A + c_A / u the directions from B, c_A + (A - B) u, span a great circle,
   a line in B's gnomonic coordinates: the u where it lies in B's box is exact (each side
   linear in u), then narrowed to B's region G_B >= -slack (concave along the line: a
   grid, kept from the point before the first inside to the one after the last). u is
   uniform there; then g uniform where both eyes' modelled radii and the prior's g range
   allow it: rho_A sin[max_lit_A - slack, min_unlit_A + slack] intersected with B's.
5. A necessary condition on the edge cells' boundary samples (their true distances, the
   sampling gap bounded: :func:`_prefilter`) drops most draws that cannot match; the rest
   are checked exactly with ``EyePair3D.lit_csr`` (0/1 likelihood), against the prior's
   support and the exact field test ``in_bfv``, and weighted by prior x rho^4 sin(phi)
   (d(x, y, z, g) / d(u, theta, phi, g)) / the proposal's density (uniform in each box).

The slacks make the proposal's support cover the posterior's (the tests compare with
brute-force rejection sampling from the prior at nside 4), and the exact check makes the
likelihood exact whatever the linearisation's error; the price of a loose proposal is
fewer accepted samples, not bias. A key whose Monte-Carlo error of r exceeds
``MC_TARGET``, or whose effective sample size is below ``MIN_ESS``, gets ``TOPUP`` more
batches of draws. A key with no accepted sample is
drawn again, more times (``RETRY``: its posterior is a small part of the proposal; more
draws find it where wider windows did not); a key still empty is answered by the analytic
triangulation and ``flagged``.

**Estimates.** MAPE-optimal (Eq. 34): the 1/r-weighted posterior median of r and the
1/az-weighted median of the azimuth; the elevation crosses 0, where a relative error is
undefined, so its estimate is the posterior median (optimal for its mean absolute error).
Monte-Carlo error per key: ``mc_error`` (relative standard error of r's estimate,
1.2533 sd_w(r) / sqrt(ESS) / r, ESS = (sum w)^2 / sum w^2) and ``n_accepted`` travel with
the prediction. Draws are a function of the key alone (a counter-based hash of its lit
sets), so a row's answer never depends on the other rows.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from eyeviz.core import healpix
from eyeviz.core.domain3d import PAPER_DOMAIN3D, Domain3D
from eyeviz.estimators.analytic3d import cap_estimates, estimate
from eyeviz.estimators.base3d import Estimator3D, LitCSR, Prediction3D, as_csr, take_rows
from eyeviz.estimators.limit import weighted_median

__all__ = ["PRIORS", "Limit3DEstimator", "load", "posterior_samples3d", "prior_density"]

PRIORS = ("single", "multi")
#: facet widths inside and outside the estimated cap where the cap's edge is looked for
EDGE = 1.25
#: boundary points per cell edge for the nearest point of a cell
STEP = 6
#: the retries of keys with no accepted draw: (window and slack factor, batches of draws)
RETRY = ((1.0, 8), (2.5, 24), (1.0, 96))
#: facet widths the centre search may move: edge cells that cannot bind within them are
#: dropped before it
PRUNE = 0.25
#: zoom levels of the search for the centre (each grid a third as wide)
LEVELS = 4
#: grid points and rounds of the search along the ray for B's region
RAY_GRID = 8
RAY_ROUNDS = 2
#: the Monte-Carlo error of r a key's draws are topped up to (at most TOPUP more batches)
MC_TARGET = 0.01
TOPUP = 1
#: a key whose effective sample size is below this is topped up too (one or two accepted
#: draws give a Monte-Carlo error of 0 or none at all, not a small one)
MIN_ESS = 4.0
#: the largest ``samples`` and ``grid`` a Limit3DEstimator takes
MAX_SAMPLES = 1 << 14
MAX_GRID = 64
#: the per-key slack: this many times the model's second-order error in the box
SLACK_SAFETY = 4.0
#: directions of the bisection for the box of centres
NDIR = 8
#: keys processed together
_CHUNK = 8
#: The most facets per eye a key may light and still be sampled: each exact check of a
#: draw costs about its lit count, and a draw is checked up to (1 + TOPUP + sum of
#: RETRY's batches) x samples times. A key beyond it, or beyond what any ball of the
#: domain can light (:func:`max_lit`), gets no draws: its posterior is empty (or too
#: costly to find) and it is answered by analytic3d and flagged (issue 35: a row lighting
#: the whole eye took 33 s).
MAX_KEY_LIT = 1 << 20


def max_lit(domain: Domain3D) -> int:
    """An upper bound on the facets one eye of ``domain`` sees lit by any ball of its
    prior: the cap's half-angle is at most asin(g_max / (r_min - h)) (the ball's centre
    lies r_min or more from the origin, so r_min - h or more from an eye; pi/2 when that
    is not positive), its area a fraction (1 - cos alpha) / 2 of the sphere, and the cells
    on its rim at most 8 per facet width of its perimeter (generous: HEALPix cells are
    within a factor ~2 of square), plus 16."""
    d = domain
    near = d.r_min - d.h
    alpha = math.pi / 2 if near <= d.g_max else math.asin(d.g_max / near)
    fw = math.sqrt(4 * math.pi / d.npix)
    bound = d.npix * (1 - math.cos(alpha)) / 2 + 8 * 2 * math.pi * math.sin(alpha) / fw + 16
    return int(min(d.npix, math.ceil(bound)))


def prior_density(domain: Domain3D, prior: str, r, g, el, az) -> np.ndarray:
    """The prior density of Algorithm 1 in 3D in (x, y, z, g), up to a constant, at balls
    of centre (r, az, el) and radius g (0 outside its support; the field test and
    Definition 1 are not applied here)."""
    d = domain
    s = math.sin(d.gamma / 2)
    with np.errstate(invalid="ignore", divide="ignore"):
        a = np.arcsin(np.minimum(g / r, 1.0))
        cone = d.psi + a
        ok = (r >= d.r_min) & (r <= d.r_max) & (g >= r * s) & (g <= d.g_max) & (g <= r)
        ok &= (cone < math.pi / 2) & (np.abs(el) <= d.el_max)
        cel = np.cos(el)
        if prior == "multi":
            az0 = np.arccos(np.minimum(np.cos(cone) / math.cos(d.el_max), 1.0))
            dens = r * r * cel
        else:
            az0 = np.arccos(np.minimum(np.cos(cone) / cel, 1.0))
            dens = np.ones_like(r)
        ok &= (az >= az0) & (az <= math.pi - az0)
        dens = dens / ((d.g_max - r * s) * (math.pi - 2 * az0) * r * r * cel)
    return np.where(ok & np.isfinite(dens), dens, 0.0)


# --- counter-based uniforms: a function of the key and the draw's number -----------------

_M1 = np.uint64(0xBF58476D1CE4E5B9)
_M2 = np.uint64(0x94D049BB133111EB)
_GOLD = np.uint64(0x9E3779B97F4A7C15)


def _mix(z: np.ndarray) -> np.ndarray:
    with np.errstate(over="ignore"):
        z = z + _GOLD
        z = (z ^ (z >> np.uint64(30))) * _M1
        z = (z ^ (z >> np.uint64(27))) * _M2
    return z ^ (z >> np.uint64(31))


def _key_hash(lit_a: LitCSR, lit_b: LitCSR) -> np.ndarray:
    out = np.zeros(lit_a[0].size - 1, np.uint64)
    for salt, (ptr, ind) in enumerate((lit_a, lit_b)):
        hv = _mix(ind.astype(np.uint64) + np.uint64(salt << 40))
        cnt = np.diff(ptr)
        sums = np.zeros(cnt.size, np.uint64)
        nz = cnt > 0
        with np.errstate(over="ignore"):
            sums[nz] = np.add.reduceat(hv, ptr[:-1][nz])
            out = _mix(out ^ sums ^ (cnt.astype(np.uint64) << np.uint64(48)))
    return out


def _uniforms(keys: np.ndarray, m: int, k: int, stream: int) -> np.ndarray:
    """(N, m, k) uniforms in (0, 1) from the key hashes."""
    j = np.arange(m * k, dtype=np.uint64) + np.uint64(stream << 32)
    with np.errstate(over="ignore"):
        z = _mix(keys[:, None] * _M1 + j[None, :])
    u = ((z >> np.uint64(11)).astype(np.float64) + 0.5) * 2.0**-53
    return u.reshape(keys.size, m, k)


# --- one eye's edge cells ------------------------------------------------------------------


def _frame(c: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """East and north unit vectors (N, 3) at unit vectors c (N, 3)."""
    e1 = np.stack([-c[:, 1], c[:, 0], np.zeros(len(c))], axis=1)
    n1 = np.linalg.norm(e1, axis=1, keepdims=True)
    e1 = np.where(n1 > 1e-12, e1 / np.maximum(n1, 1e-300), [1.0, 0.0, 0.0])
    e2 = np.cross(c, e1)
    return e1, e2


def _sample_gap(nside: int, d: np.ndarray) -> np.ndarray:
    """How much farther than a cell's closure its nearest boundary sample can be, given
    that sample's distance d: samples are s = 1.5 fw / STEP apart along edges (edges are
    at most 1.5 facet widths fw long), so the nearest sample to the closure's nearest
    point q lies within s / 2 of q along the edge: d <= sqrt(D^2 + s^2 / 4) with D the
    true distance, hence D >= D_lo = sqrt(d^2 - s^2 / 4) and d - D <= sqrt(D_lo^2 +
    s^2 / 4) - D_lo. Times 1.5 for the edges' curvature."""
    s = 1.5 * math.sqrt(4 * math.pi / (12 * nside**2)) / STEP
    d_lo = np.sqrt(np.maximum(d * d - 0.25 * s * s, 0.0))
    return 1.5 * (np.sqrt(d_lo * d_lo + 0.25 * s * s) - d_lo)


def _prefilter(eye: _Eye, row: np.ndarray, c: np.ndarray, alpha: np.ndarray) -> np.ndarray:
    """A necessary condition for caps (c (D, 3) unit, alpha (D,)) of the keys ``row`` (D,)
    to light exactly the key's cells, on the eye's (pruned) edge cells, from their
    boundary samples' true distances: a lit cell needs alpha > dist(c, cell) >= d_s -
    gap (d_s: the nearest sample's distance, gap: :func:`_sample_gap`), an unlit one
    alpha <= dist(c, closure) <= d_s. Both with a 1e-9 rad margin for rounding. Draws
    failing it would fail the exact check; the survivors get that check."""
    ok = np.ones(row.size, bool)
    pp = eye.pts.shape[2]
    bounds = np.flatnonzero(np.diff(row)) + 1  # row is sorted: one product per key
    for idx in np.split(np.arange(row.size), bounds):
        if not idx.size:
            continue
        r = row[idx[0]]
        live = ~eye.pad[r]
        k = int(live.sum())
        pts = eye.pts[r][live].reshape(k * pp, 3)
        dots = (pts @ c[idx].T).reshape(k, pp, idx.size).max(axis=1)
        ds = np.arccos(np.clip(dots, -1.0, 1.0))  # (K, Dk)
        a = alpha[idx][None, :]
        lit = eye.lit[r][live][:, None]
        bad = np.where(lit, a + _sample_gap(eye.nside, ds) + 1e-9 <= ds, a > ds + 1e-9)
        ok[idx] = ~bad.any(axis=0)
    return ok


def _codes(ptr: np.ndarray, ind: np.ndarray, npix: int) -> np.ndarray:
    rows = np.repeat(np.arange(ptr.size - 1, dtype=np.int64), np.diff(ptr))
    return rows * npix + ind


class _Eye:
    """The edge cells of one eye for a chunk of keys: their boundary points, padded to
    (N, K, P, 3), with ``lit`` (N, K) (True: must stay lit), ``pad`` (N, K)."""

    def __init__(self, domain: Domain3D, lit: LitCSR, centre: np.ndarray, eye: int):
        self.nside = domain.nside
        npix = domain.npix
        u, alpha = cap_estimates(domain.nside, lit)
        self.u0 = u
        self.alpha0 = alpha
        fw = math.sqrt(4 * math.pi / npix)
        n = u.shape[0]
        dist = 1000.0
        a_in = np.maximum(alpha - EDGE * fw, 0.5 * fw)
        a_out = np.minimum(alpha + EDGE * fw, math.pi / 2 - 1e-6)
        gs = dist * np.sin(np.concatenate([a_in, a_out]))
        pos = np.asarray(centre) + dist * np.concatenate([u, u])
        res = domain.eyes.lit_csr(pos[:, 0], pos[:, 1], pos[:, 2], gs)[eye]
        ptr, ind = res
        inner = (ptr[: n + 1], ind[: ptr[n]])
        outer = (ptr[n:] - ptr[n], ind[ptr[n] :])
        key = _codes(*lit, npix)
        c_in = _codes(*inner, npix)
        # a key too small for an inner cap of half a facet: every lit cell is an edge cell
        # (a cap of 1e-9 rad would send its cells to the exact fallback, ~10 ms each)
        small = alpha - EDGE * fw < 0.5 * fw
        c_in = c_in[~small[c_in // npix]]
        c_out = _codes(*outer, npix)
        lit_edge = key[~np.isin(key, c_in, assume_unique=True)]
        unlit = c_out[~np.isin(c_out, key, assume_unique=True)]
        codes = np.concatenate([lit_edge, unlit])
        is_lit = np.concatenate([np.ones(lit_edge.size, bool), np.zeros(unlit.size, bool)])
        rows = codes // npix
        order = np.argsort(rows, kind="stable")
        codes, is_lit, rows = codes[order], is_lit[order], rows[order]
        cnt = np.bincount(rows, minlength=n)
        kmax = max(1, int(cnt.max()) if cnt.size else 1)
        slot = np.arange(codes.size) - np.repeat(np.cumsum(cnt) - cnt, cnt)
        pts = healpix.boundaries(self.nside, codes % npix, STEP)  # (T, P, 3)
        self.pts = np.zeros((n, kmax, pts.shape[1], 3))
        self.pts[rows, slot] = pts
        self.lit = np.zeros((n, kmax), bool)
        self.lit[rows, slot] = is_lit
        self.pad = np.ones((n, kmax), bool)
        self.pad[rows, slot] = False
        self.n_lit_edge = np.bincount(rows[is_lit], minlength=n)
        self.n_unlit = np.bincount(rows[~is_lit], minlength=n)
        self.centre = np.asarray(centre, float)
        self.a = np.zeros(3)  # the other eye's centre relative to this one (set by the caller)
        self.linearise(u)

    def linearise(self, c: np.ndarray) -> None:
        """Distances d (N, K) and gradients t (N, K, 2) of every edge cell at centres c."""
        self.c = c / np.linalg.norm(c, axis=1, keepdims=True)
        self.e1, self.e2 = _frame(self.c)
        dots = np.einsum("nkpj,nj->nkp", self.pts, self.c)
        best = np.argmax(dots, axis=2)
        p = np.take_along_axis(self.pts, best[:, :, None, None], 2)[:, :, 0]
        cp = np.einsum("nkj,nj->nk", p, self.c)
        tang = p - cp[..., None] * self.c[:, None, :]
        tn = np.linalg.norm(tang, axis=2)
        d = np.arctan2(tn, cp)
        # the nearest boundary sample is farther than the cell by at most _sample_gap:
        # lit cells' distances are lowered by that much, so the linearised region holds
        # the true one; unlit cells' samples lie in the cell's closure
        self.d = np.where(self.lit, d - _sample_gap(self.nside, d), d)
        with np.errstate(invalid="ignore", divide="ignore"):
            t1 = np.einsum("nkj,nj->nk", tang, self.e1) / tn
            t2 = np.einsum("nkj,nj->nk", tang, self.e2) / tn
        self.t = np.stack([np.nan_to_num(t1), np.nan_to_num(t2)], axis=-1)
        self._affine()

    def prune(self, reach: np.ndarray) -> None:
        """Drop the edge cells that cannot bind anywhere within ``reach`` (N,) of the
        centre: a lit cell's modelled distance moves by at most |delta| and an unlit
        one's by at most |delta| + |delta|^2 / (2 d), so a lit cell below max_lit - 2.2
        reach or an unlit one above min_unlit + 2.2 reach never decides. (Dropping
        constraints only loosens the model: the exact check decides.)"""
        live = ~self.pad
        lo0 = np.where(self.lit & live, self.d, -np.inf).max(axis=1)
        hi0 = np.where(~self.lit & live, self.d, np.inf).min(axis=1)
        m = 2.2 * reach[:, None]
        keep = live & np.where(self.lit, self.d >= lo0[:, None] - m, self.d <= hi0[:, None] + m)
        cnt = keep.sum(axis=1)
        kmax = max(1, int(cnt.max()) if cnt.size else 1)
        if kmax >= keep.shape[1]:
            return
        order = np.argsort(~keep, axis=1, kind="stable")[:, :kmax]
        rows = np.arange(keep.shape[0])[:, None]
        self.pts = self.pts[rows, order]
        self.lit = self.lit[rows, order]
        self.pad = ~keep[rows, order]
        self.d = self.d[rows, order]
        self.t = self.t[rows, order]
        self._affine()

    def _affine(self) -> None:
        """The model as affine forms in delta: a lit cell's distance is d - t . delta, an
        unlit one's squared distance is d^2 - 2 d t . delta + |delta|^2 (the same value as
        (d - t . delta)^2 + |delta_perp|^2, |t| = 1), so max_lit and min_unlit are one
        matrix product and one reduction each (padding: -inf / +inf, zero slope)."""
        lit = self.lit & ~self.pad
        unl = ~self.lit & ~self.pad
        self.a_lit = np.where(lit, self.d, -np.inf)
        self.t_lit = np.where(lit[..., None], self.t, 0.0)
        self.a_unl = np.where(unl, self.d * self.d, np.inf)
        self.t_unl = np.where(unl[..., None], 2.0 * self.d[..., None] * self.t, 0.0)

    def model(self, delta: np.ndarray) -> np.ndarray:
        """Each edge cell's modelled distance (N, K, G) at gnomonic offsets delta (N, G, 2).

        Lit cells: d - t . delta, below the true distance (the distance to an edge is
        linear to first order and to a vertex convex), so their constraint alpha > dist
        is loosened. Unlit cells: the distance to their nearest sample point p,
        sqrt((d - t . delta)^2 + |delta_perp|^2), above the true distance (p lies in the
        cell), so alpha <= dist is loosened too: the modelled region holds the true one.
        (Padding cells: any value; callers mask them with ``pad``.)
        """
        dt = np.swapaxes(delta, 1, 2)  # (N, 2, G)
        td = np.matmul(self.t, dt)
        v = self.d[:, :, None] - td
        sq = np.einsum("ngj,ngj->ng", delta, delta)[:, None, :]
        w = self.d[:, :, None] * (self.d[:, :, None] - 2.0 * td) + sq
        return np.where(self.lit[:, :, None], v, np.sqrt(np.maximum(w, 0.0)))

    def bounds(self, delta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(max over lit edge cells, min over unlit) of :meth:`model` at gnomonic offsets
        delta (N, G, 2): arrays (N, G)."""
        dx = delta[:, None, :, 0]
        dy = delta[:, None, :, 1]
        v = self.t_lit[..., 0, None] * dx
        v += self.t_lit[..., 1, None] * dy
        lo = (self.a_lit[..., None] - v).max(axis=1)
        v = self.t_unl[..., 0, None] * dx
        v += self.t_unl[..., 1, None] * dy
        hi2 = (self.a_unl[..., None] - v).min(axis=1)
        hi2 += np.einsum("ngj,ngj->ng", delta, delta)
        return lo, np.sqrt(np.maximum(hi2, 0.0))

    def direction(self, delta: np.ndarray) -> np.ndarray:
        """Unit vectors (N, M, 3) at gnomonic offsets delta (N, M, 2)."""
        v = (
            self.c[:, None, :]
            + delta[..., :1] * self.e1[:, None, :]
            + delta[..., 1:] * self.e2[:, None, :]
        )
        return v / np.linalg.norm(v, axis=2, keepdims=True)

    def gnomonic(self, v: np.ndarray) -> np.ndarray:
        """Gnomonic offsets (N, M, 2) of unit vectors v (N, M, 3) about the centre."""
        cc = np.einsum("nmj,nj->nm", v, self.c)
        x, y = np.einsum("nmj,nj->nm", v, self.e1), np.einsum("nmj,nj->nm", v, self.e2)
        with np.errstate(divide="ignore", invalid="ignore"):  # v at 90 deg: inf, no warning
            return np.stack([x / cc, y / cc], axis=-1)


def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def _grid(n: int) -> np.ndarray:
    t = (np.arange(n) + 0.5) / n * 2 - 1
    a, b = np.meshgrid(t, t, indexing="ij")
    return np.stack([a.ravel(), b.ravel()], axis=1)  # (n*n, 2) in (-1, 1)


_DIRS = np.stack([np.cos(np.arange(8) * math.pi / 4), np.sin(np.arange(8) * math.pi / 4)], axis=1)


def _locate(eye: _Eye, half: float, n: int, levels: int) -> None:
    """Move the eye's centre to the maximum of G (zooming grids of n x n about the best
    point, each a third as wide) and linearise there."""
    rows = np.arange(eye.c.shape[0])
    g0 = _grid(n)
    for _ in range(levels):
        g = g0[None] * half
        lo, hi = eye.bounds(np.broadcast_to(g, (rows.size, *g0.shape)))
        best = np.argmax(hi - lo, axis=1)
        eye.linearise(eye.direction(g[0][best][:, None, :])[:, 0])
        half = half / 3.0


def _extent(eye: _Eye, reach: float, slack, iters: int = 12) -> np.ndarray:
    """Half-widths (N, 2) of a box about the centre holding every delta with
    G(delta) >= -slack (bisection along NDIR directions: G is concave)."""
    n = eye.c.shape[0]
    dirs = _dirs(NDIR)
    lo = np.zeros((n, NDIR))
    hi = np.full((n, NDIR), reach)
    for _ in range(iters):
        mid = 0.5 * (lo + hi)
        a, b = eye.bounds(mid[..., None] * dirs[None])
        inside = (b - a) >= -slack
        lo = np.where(inside, mid, lo)
        hi = np.where(inside, hi, mid)
    pts = hi[..., None] * dirs[None]  # (N, NDIR, 2): outside the region by < one step
    # the box of the boundary points, widened: a convex polygon between two of them
    # bulges out by at most tan(pi / NDIR) times their distance
    ext = np.abs(pts).max(axis=1) * (1.0 + math.tan(math.pi / NDIR))
    return np.maximum(ext, 1e-12)


def _dirs(k: int) -> np.ndarray:
    t = np.arange(k) * 2 * math.pi / k
    return np.stack([np.cos(t), np.sin(t)], axis=1)


_BOX = np.array(
    [(x, y) for x in (-1.0, -0.5, 0.0, 0.5, 1.0) for y in (-1.0, 1.0)]
    + [(x, y) for x in (-1.0, 1.0) for y in (-0.5, 0.0, 0.5)]
)  # 16 points on the boundary of [-1, 1]^2, at most 1/2 apart along each edge


def _epipolar(v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(theta, phi) of unit vectors v (..., 3): theta = atan2(v_z, v_y), the angle of the
    plane through the baseline (the x-axis) and v, and phi the angle of v from +x. A ball's
    centre and both eyes' cap centres share one theta (the eyes lie on the x-axis)."""
    return np.arctan2(v[..., 2], v[..., 1]), np.arctan2(np.hypot(v[..., 1], v[..., 2]), v[..., 0])


def _angle_box(eye: _Eye, ext: np.ndarray) -> np.ndarray:
    """Bounds (N, 4) = (theta_lo, theta_hi, phi_lo, phi_hi) over the eye's box of centres
    (half-widths ``ext`` (N, 2) about its centre, gnomonic). theta and phi have no
    critical point off the x-axis, so their extremes lie on the box's boundary, whose
    edges are great-circle arcs: sampled at most s = ext / 2 apart, each is off by at
    most M s^2 / 8 with |theta''|, |phi''| <= M = 2 / sin(phi)^2 along a unit-speed arc;
    the pad is four times that. NaN where the box reaches y <= 0 or the x-axis."""
    pts = eye.direction(_BOX[None] * ext[:, None, :])  # (N, 16, 3)
    th, ph = _epipolar(pts)
    s = 0.5 * np.hypot(ext[:, 0], ext[:, 1])
    sin_min = np.sin(ph).min(axis=1) - 2.0 * s
    ok = (pts[..., 1].min(axis=1) > 0) & (sin_min > 1e-3)
    pad = s * s / np.where(ok, sin_min, 1.0) ** 2 + 1e-12
    out = np.stack(
        [th.min(axis=1) - pad, th.max(axis=1) + pad, ph.min(axis=1) - pad, ph.max(axis=1) + pad],
        axis=1,
    )
    return np.where(ok[:, None], out, np.nan)


def _ray_in_box(eye_b: _Eye, ca: np.ndarray, ext: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The interval (lo, hi) (N, M) of u = 1 / rho where the direction from B to
    A + c_A / u, proportional to v(u) = c_A + u (A - B), has gnomonic coordinates about
    B's centre inside the box |delta_i| <= ext_i (N, 2): with v . c_B > 0 each side is
    |v . e_i| <= ext_i v . c_B, two inequalities linear in u (ca: (N, M, 3))."""
    a = eye_b.a
    shape = ca.shape[:2]
    c = eye_b.c[:, None, :]
    cc = (ca * c).sum(-1)
    rows = [(-cc, np.broadcast_to(-(eye_b.c @ a)[:, None], shape))]  # v . c_B >= 0
    for e, x in ((eye_b.e1, ext[:, 0]), (eye_b.e2, ext[:, 1])):
        ce = (ca * e[:, None, :]).sum(-1)
        for sgn in (1.0, -1.0):  # sgn v . e - ext v . c_B <= 0
            k1 = sgn * (e @ a) - x * (eye_b.c @ a)
            rows.append((sgn * ce - x[:, None] * cc, np.broadcast_to(k1[:, None], shape)))
    lo = np.zeros(shape)
    hi = np.full(shape, np.inf)
    for k0, k1 in rows:  # k0 + u k1 <= 0
        with np.errstate(divide="ignore", invalid="ignore"):
            root = -k0 / k1
        hi = np.where(k1 > 0, np.minimum(hi, root), hi)
        lo = np.where(k1 < 0, np.maximum(lo, root), lo)
        lo = np.where((k1 == 0) & (k0 > 0), np.inf, lo)
    return lo, hi


def _ray_in_region(eye_b: _Eye, ca, lo, hi, slack, grid: int = 12, rounds: int = 2):
    """Shrink each draw's u-interval [lo, hi] (N, M) to one holding every u whose view
    from B lies in B's modelled region G = min_unlit - max_lit >= -slack. G is concave
    and the view moves monotonically along a great circle, so those u form an interval:
    G on ``grid`` points, the interval from the grid point before the first inside to the
    one after the last (or the two neighbours of the best point when none is inside);
    ``rounds`` times. Returns (lo, hi)."""
    n, m = lo.shape
    t = np.linspace(0.0, 1.0, grid)
    for _ in range(rounds):
        uu = lo[..., None] + (hi - lo)[..., None] * t  # (N, M, grid)
        v = ca[:, :, None, :] + uu[..., None] * eye_b.a
        v = v / np.linalg.norm(v, axis=-1, keepdims=True)
        with np.errstate(invalid="ignore", divide="ignore"):
            dl = eye_b.gnomonic(v.reshape(n, m * grid, 3))
            blo, bhi = eye_b.bounds(np.nan_to_num(dl, nan=1e3, posinf=1e3, neginf=-1e3))
        g = (bhi - blo).reshape(n, m, grid)
        inside = g >= -slack[..., None]
        anyin = inside.any(axis=2)
        first = np.where(anyin, inside.argmax(axis=2), g.argmax(axis=2))
        last = np.where(anyin, grid - 1 - inside[..., ::-1].argmax(axis=2), first)
        i0 = np.maximum(first - 1, 0)
        i1 = np.minimum(last + 1, grid - 1)
        lo, hi = (
            np.take_along_axis(uu, i0[..., None], 2)[..., 0],
            np.take_along_axis(uu, i1[..., None], 2)[..., 0],
        )
    return lo, hi


class Limit3DEstimator(Estimator3D):
    """The MAPE-optimal answers of the 3D posterior, by importance sampling with the exact
    0/1 likelihood (module docstring); any design, no weights.

    Predictions carry ``flagged`` (empty posterior: answered by analytic3d),
    ``mc_error`` (relative standard error of r's estimate; NaN where flagged) and
    ``n_accepted`` (samples that reproduce both lit sets)."""

    name = "limit3d"

    def __init__(
        self,
        domain: Domain3D = PAPER_DOMAIN3D,
        prior: str = "single",
        samples: int = 256,
        grid: int = 8,
        seed: int = 0,
    ) -> None:
        if prior not in PRIORS:
            raise ValueError(f"prior must be one of {PRIORS}, got {prior!r}")
        # bounded so that one chunk's draws and grid fit in memory
        for name, v, lo, hi in (("samples", samples, 4, MAX_SAMPLES), ("grid", grid, 4, MAX_GRID)):
            if not isinstance(v, int | np.integer) or isinstance(v, bool) or not lo <= v <= hi:
                raise ValueError(f"{name} must be an integer >= {lo} and <= {hi}, got {v!r}")
        # the seed is xor-ed into the keys' uint64 hashes
        if (
            not isinstance(seed, int | np.integer)
            or isinstance(seed, bool)
            or not 0 <= seed < 2**64
        ):
            raise ValueError(f"seed must be an integer >= 0 and < 2^64, got {seed!r}")
        super().__init__(domain, {"n_weights": 0, "train_seconds": 0.0, "prior": prior})
        self.prior = prior
        self.samples = int(samples)
        self.grid = int(grid)
        self.seed = int(seed)
        self.last_mc_error: np.ndarray = np.zeros(0)
        self.last_accepted: np.ndarray = np.zeros(0, np.int64)

    # --- the posterior of a chunk of keys ------------------------------------------------
    def _draw(
        self,
        lit_a: LitCSR,
        lit_b: LitCSR,
        keys: np.ndarray,
        wide: float,
        stream: int,
        reps: int = 1,
    ) -> dict[str, np.ndarray]:
        """Weighted posterior samples of a chunk: dict of (N, reps * samples) arrays (the
        proposal set up once, ``reps`` batches of draws)."""
        d = self.domain
        fw = math.sqrt(4 * math.pi / d.npix)
        A = np.array([-d.h, 0.0, 0.0])
        B = np.array([d.h, 0.0, 0.0])
        ea = _Eye(d, lit_a, A, 0)
        eb = _Eye(d, lit_b, B, 1)
        n = ea.c.shape[0]
        m = self.samples
        ng = self.grid
        slack0 = wide * 0.002 * fw
        for e in (ea, eb):
            e.prune(np.full(n, PRUNE * wide * fw))
            _locate(e, 0.25 * wide * fw, ng, LEVELS)
        ext = _extent(ea, wide * 0.5 * fw, slack0)
        eb.a = A - B
        ext_b = _extent(eb, wide * 0.5 * fw, slack0)
        # within a box of radius R the model's distances are off by second-order terms,
        # below R^2 (1 / alpha + 1) / 2: a thin posterior (a box far smaller than the
        # search window) needs a slack far below the window's, or the proposal is
        # mostly slack (keys with a tiny posterior found nothing in 10^4 draws)
        sec = np.zeros(n)
        for e, x in ((ea, ext), (eb, ext_b)):
            sec = np.maximum(sec, (x * x).sum(axis=1) * (1.0 / e.alpha0 + 1.0))
        slack = np.minimum(slack0, wide * (SLACK_SAFETY * sec + 1e-7 * fw))[:, None]
        ext = _extent(ea, wide * 0.5 * fw, slack)
        ext_b = _extent(eb, wide * 0.5 * fw, slack)
        ea.prune(1.2 * math.sqrt(2.0) * ext.max(axis=1))
        eb.prune(1.2 * math.sqrt(2.0) * ext_b.max(axis=1))
        # A's centre: uniform in (theta, phi) over the bounds of A's box, theta cut to
        # those of B's box (both caps' centres share the ball's theta: B's box bounds it)
        box = _angle_box(ea, ext)
        box_b = _angle_box(eb, ext_b)
        th_lo = np.fmax(box[:, 0], box_b[:, 0])
        th_hi = np.fmin(box[:, 1], box_b[:, 1])
        st = dict(d=d, A=A, B=B, ea=ea, eb=eb, n=n, m=m, slack=slack, ext=ext, ext_b=ext_b,
                  box=box, th_lo=th_lo, th_hi=th_hi, lit_a=lit_a, lit_b=lit_b)  # fmt: skip
        parts = [self._sample(st, keys, stream + 8 * rep) for rep in range(reps)]
        out = {k: np.concatenate([q[k] for q in parts], axis=1) for k in parts[0]}
        if reps > 1:
            return out
        # top-ups: a key with too few or too spread draws (_needs_more) gets another batch
        # (its own stream; the other keys' draws are left as they are)
        for rep in range(1, 1 + TOPUP):
            need = _needs_more(out["r"], out["w"])
            if not need.any():
                break
            more = self._sample(st, keys, stream + 8 * rep)
            more["w"] = np.where(need[:, None], more["w"], 0.0)
            out = {k: np.concatenate([out[k], more[k]], axis=1) for k in out}
        if out["w"].shape[1] > m:  # the accepted draws first, in draw order
            order = np.argsort(~(out["w"] > 0), axis=1, kind="stable")[:, :m]
            out = {k: np.take_along_axis(v, order, 1) for k, v in out.items()}
        return out

    def _sample(self, st: dict, keys: np.ndarray, stream: int) -> dict[str, np.ndarray]:
        """``samples`` weighted draws per key of a chunk set up by :meth:`_draw`."""
        d, A, B, ea, eb = st["d"], st["A"], st["B"], st["ea"], st["eb"]
        n, m, slack, ext, ext_b = st["n"], st["m"], st["slack"], st["ext"], st["ext_b"]
        box, th_lo, th_hi = st["box"], st["th_lo"], st["th_hi"]
        lit_a, lit_b = st["lit_a"], st["lit_b"]
        u = _uniforms(keys, m, 4, stream)
        th = th_lo[:, None] + (th_hi - th_lo)[:, None] * u[..., 0]
        ph = box[:, 2:3] + (box[:, 3] - box[:, 2])[:, None] * u[..., 1]
        sp = np.sin(ph)
        ca = np.stack([np.cos(ph), sp * np.cos(th), sp * np.sin(th)], axis=-1)
        good = np.broadcast_to(((th_hi > th_lo) & (box[:, 3] > box[:, 2]))[:, None], (n, m))
        with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
            delta = ea.gnomonic(np.where(good[..., None], ca, ea.c[:, None, :]))
        # outside A's box the model region is empty: drawn, then dropped
        good = good & (np.abs(delta) <= ext[:, None, :]).all(axis=2)
        delta = np.where(good[..., None], delta, 0.0)
        ca = np.where(good[..., None], ca, ea.c[:, None, :])
        lo_a, hi_a = ea.bounds(delta)
        good = good & (hi_a - lo_a > -2.0 * slack)
        # along the ray A + c_A / u: u where B's view of it lies in B's box (the
        # directions from B, c_A + u (A - B), span a great circle: a line in B's
        # gnomonic coordinates, and each side of the box is linear in u), then in B's
        # modelled region; on the live draws only (moved to the front of each row)
        u_lo, u_hi = _ray_in_box(eb, ca, ext_b)
        u_lo = np.maximum(u_lo, 1.0 / (d.r_max + d.h))
        if d.r_min > d.h:
            u_hi = np.minimum(u_hi, 1.0 / (d.r_min - d.h))
        good = good & (u_hi > u_lo)
        order = np.argsort(~good, axis=1, kind="stable")[:, : max(1, int(good.sum(1).max()))]
        sel = np.take_along_axis(good, order, 1)

        def pick(x: np.ndarray) -> np.ndarray:
            return np.take_along_axis(x, order if x.ndim == 2 else order[..., None], 1)

        c_lo = np.where(sel, pick(u_lo), 1.0 / d.r_max)
        c_hi = np.where(sel, pick(u_hi), 1.0 / d.r_max)
        c_lo, c_hi = _ray_in_region(eb, pick(ca), c_lo, c_hi, slack, RAY_GRID, RAY_ROUNDS)
        rows = np.arange(n)[:, None]
        u_lo, u_hi = u_lo.copy(), u_hi.copy()
        u_lo[rows, order] = c_lo
        u_hi[rows, order] = c_hi
        u_lo = np.where(good, u_lo, 1.0 / d.r_max)
        u_hi = np.where(good, u_hi, 1.0 / d.r_max)
        uu = u_lo + (u_hi - u_lo) * u[..., 2]
        uu = np.where(good, uu, 1.0 / d.r_max)
        rho = 1.0 / uu
        p = A + rho[..., None] * ca
        r = np.linalg.norm(p, axis=2)
        vb = p - B
        rho_b = np.linalg.norm(vb, axis=2)
        # g: uniform where both eyes' modelled cap radii allow it (and the prior's g range)
        lo_b, hi_b = eb.bounds(eb.gnomonic(vb / rho_b[..., None]))
        g_lo, g_hi = r * math.sin(d.gamma / 2), np.full_like(r, d.g_max)
        for lo_e, hi_e, rh in ((lo_a, hi_a, rho), (lo_b, hi_b, rho_b)):
            g_lo = np.maximum(g_lo, rh * np.sin(np.clip(lo_e - slack, 0.0, math.pi / 2)))
            g_hi = np.minimum(g_hi, rh * np.sin(np.clip(hi_e + slack, 0.0, math.pi / 2)))
        good = good & (g_hi > g_lo)
        gg = g_lo + (g_hi - g_lo) * u[..., 3]
        el = np.arcsin(np.clip(p[..., 2] / r, -1, 1))
        az = np.arctan2(p[..., 1], p[..., 0])
        alpha = np.arcsin(np.clip(gg / rho, 0.0, 1.0))
        # d(x, y, z, g) = rho^4 sin(phi) d(u, theta, phi, g); 1 / q = the boxes' volume
        with np.errstate(over="ignore", invalid="ignore"):
            vol = (th_hi - th_lo)[:, None] * (box[:, 3] - box[:, 2])[:, None]
            vol = vol * (u_hi - u_lo) * (g_hi - g_lo)
            w = prior_density(d, self.prior, r, gg, el, az) * rho**4 * sp * vol
        w = np.where(good & np.isfinite(w), w, 0.0)
        # the exact 0/1 likelihood on the draws with prior mass
        cand = np.flatnonzero(w.ravel() > 0)
        hit = np.zeros(n * m, bool)
        if cand.size:  # a cheap necessary condition first
            row = cand // m
            pc = p.reshape(-1, 3)[cand]
            pb_ = pc - B
            rb = np.linalg.norm(pb_, axis=1)
            keep = _prefilter(ea, row, ca.reshape(-1, 3)[cand], alpha.ravel()[cand])
            cand, row, pb_, rb = cand[keep], row[keep], pb_[keep], rb[keep]
            sin_b = np.minimum(gg.ravel()[cand] / rb, 1.0)
            keep = _prefilter(eb, row, pb_ / rb[:, None], np.arcsin(sin_b))
            cand = cand[keep]
        if cand.size:
            x, y, z = (p.reshape(-1, 3)[cand, i] for i in range(3))
            gc = gg.ravel()[cand]
            inb = d.eyes.in_bfv(x, y, z, gc)
            (pa, ia), (pb, ib) = d.eyes.lit_csr(x, y, z, gc)
            row = cand // m
            match = inb & _same(pa, ia, lit_a, row) & _same(pb, ib, lit_b, row)
            hit[cand] = match
        w = np.where(hit.reshape(n, m), w, 0.0)
        return {"r": r, "az": az, "el": el, "g": gg, "x": p[..., 0], "y": p[..., 1],
                "z": p[..., 2], "w": w}  # fmt: skip

    def _posterior(self, lit_a: LitCSR, lit_b: LitCSR):
        keys = _key_hash(lit_a, lit_b) ^ np.uint64(self.seed)
        s = self._draw(lit_a, lit_b, keys, 1.0, 0)
        m = self.samples
        for stream, (wide, reps) in enumerate(RETRY, start=1):
            few = np.flatnonzero(~(s["w"].sum(axis=1) > 0))
            if not few.size:
                break
            # keys with nothing accepted: their posterior is a small part of the proposal
            # (the misses are found with more draws, not with wider windows): ``reps``
            # times the draws, the window and slack ``wide`` times wider; the accepted
            # draws kept, the first ``samples`` of them in draw order
            sub_a, sub_b = take_rows(*lit_a, few), take_rows(*lit_b, few)
            s2 = self._draw(sub_a, sub_b, keys[few], wide, stream, reps)
            order = np.argsort(~(s2["w"] > 0), axis=1, kind="stable")[:, :m]
            for k in s:
                s[k][few] = np.take_along_axis(s2[k], order, 1)
        return s

    def _predict_csr(self, lit_a: LitCSR, lit_b: LitCSR):
        n = lit_a[0].size - 1
        r = np.empty(n)
        az = np.empty(n)
        el = np.empty(n)
        empty = np.zeros(n, bool)
        mc = np.full(n, np.nan)
        acc = np.zeros(n, np.int64)
        # keys no ball of the domain lights, or too costly to sample: no draws (flagged)
        most = min(MAX_KEY_LIT, max_lit(self.domain))
        over = (np.diff(lit_a[0]) > most) | (np.diff(lit_b[0]) > most)
        empty |= over
        live = np.flatnonzero(~over)
        for s0 in range(0, live.size, _CHUNK):
            rows = live[s0 : s0 + _CHUNK]
            la, lb = take_rows(*lit_a, rows), take_rows(*lit_b, rows)
            sm = self._posterior(la, lb)
            w = sm["w"]
            tot = w.sum(axis=1)
            e = ~(tot > 0)
            with np.errstate(invalid="ignore", divide="ignore"):
                rr = weighted_median(sm["r"], w / sm["r"])
                aa = weighted_median(sm["az"], w / sm["az"])
                ee = weighted_median(sm["el"], w)
                _, sd, ess = _spread(sm["r"], w)
                mc[rows] = np.where(e, np.nan, 1.2533 * sd / np.sqrt(ess) / rr)
            r[rows], az[rows], el[rows] = rr, aa, ee
            empty[rows] = e
            acc[rows] = (w > 0).sum(axis=1)
        if empty.any():
            idx = np.flatnonzero(empty)
            fr, fa, fe, _ = estimate(self.domain, take_rows(*lit_a, idx), take_rows(*lit_b, idx))
            r[idx], az[idx], el[idx] = fr, fa, fe
        self._mc_parts.append(mc)
        self._acc_parts.append(acc)
        return r, az, el, empty

    def predict(self, lit_a, lit_b) -> Prediction3D:
        """As :meth:`Estimator3D.predict`, plus ``mc_error`` and ``n_accepted`` (also in
        :attr:`last_mc_error`, :attr:`last_accepted`); NaN / 0 on invalid rows."""
        self._mc_parts: list[np.ndarray] = []
        self._acc_parts: list[np.ndarray] = []
        p: Any = super().predict(lit_a, lit_b)
        valid = np.atleast_1d(p.valid)
        mc = np.full(valid.shape, np.nan)
        acc = np.zeros(valid.shape, np.int64)
        if self._mc_parts:
            mc[valid] = np.concatenate(self._mc_parts)
            acc[valid] = np.concatenate(self._acc_parts)
        scalar = np.ndim(p.valid) == 0
        p.mc_error = mc[0] if scalar else mc
        p.n_accepted = acc[0] if scalar else acc
        self.last_mc_error, self.last_accepted = mc, acc
        return p

    def __repr__(self) -> str:
        d = self.domain
        return (
            f"<Limit3DEstimator h={d.h:g} l={d.l:g} nside={d.nside} r=[{d.r_min:g}, "
            f"{d.r_max:g}] g_max={d.g_max:g} el_max={d.el_max:g} prior={self.prior}>"
        )


def _spread(r: np.ndarray, w: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per row of weighted draws: the weighted mean and standard deviation of r and the
    effective sample size ESS = (sum w)^2 / sum w^2 (NaN where nothing is accepted)."""
    tot = w.sum(axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        wn = w / tot[:, None]
        mean = (wn * r).sum(axis=1)
        sd = np.sqrt(np.maximum((wn * (r - mean[:, None]) ** 2).sum(axis=1), 0.0))
        ess = tot**2 / (w**2).sum(axis=1)
    return mean, sd, ess


def _needs_more(r: np.ndarray, w: np.ndarray) -> np.ndarray:
    """The keys to top up: the relative Monte-Carlo error of r, 1.2533 sd_w(r) / sqrt(ESS)
    / mean_w(r), above ``MC_TARGET``, or an ESS below ``MIN_ESS`` (one or two accepted
    draws give an error of 0 or none at all, not a small one), or nothing accepted."""
    mean, sd, ess = _spread(r, w)
    with np.errstate(invalid="ignore", divide="ignore"):
        mc = 1.2533 * sd / np.sqrt(ess) / mean
    return ~(ess >= MIN_ESS) | ~(mc <= MC_TARGET)


def _same(ptr: np.ndarray, ind: np.ndarray, key: LitCSR, row: np.ndarray) -> np.ndarray:
    """Whether each CSR row i of (ptr, ind) equals the key's row ``row[i]``."""
    kp, ki = key
    cnt = np.diff(ptr)
    kc = np.diff(kp)[row]
    same = cnt == kc
    sel = np.flatnonzero(same & (cnt > 0))
    if sel.size:
        lens = cnt[sel]
        starts = ptr[sel]
        kstarts = kp[row[sel]]
        off = np.arange(int(lens.sum())) - np.repeat(np.cumsum(lens) - lens, lens)
        a = ind[np.repeat(starts, lens) + off]
        b = ki[np.repeat(kstarts, lens) + off]
        bad = np.add.reduceat((a != b).astype(np.int64), np.cumsum(lens) - lens)
        same[sel] = bad == 0
    return same


def posterior_samples3d(est: Limit3DEstimator, lit_a, lit_b) -> dict[str, np.ndarray]:
    """The weighted posterior samples of one key (lit sets as sorted index arrays):
    ``x, y, z, g, r, azimuth, elevation, weight`` (weights sum to 1; empty arrays when no
    sample reproduced the key), for the app's point cloud."""
    a = np.asarray(lit_a, np.int64)
    b = np.asarray(lit_b, np.int64)
    ptr_a = np.array([0, a.size])
    ptr_b = np.array([0, b.size])
    la = as_csr("lit_a", (ptr_a, a), est.domain.npix)[:2]
    lb = as_csr("lit_b", (ptr_b, b), est.domain.npix)[:2]
    s = est._posterior(la, lb)
    w = s["w"][0]
    keep = w > 0
    tot = w.sum()
    return {
        "x": s["x"][0][keep],
        "y": s["y"][0][keep],
        "z": s["z"][0][keep],
        "g": s["g"][0][keep],
        "r": s["r"][0][keep],
        "azimuth": s["az"][0][keep],
        "elevation": s["el"][0][keep],
        "weight": w[keep] / tot if tot > 0 else w[keep],
    }


def load(domain: Domain3D | None = None, prior: str = "single", **kw) -> Limit3DEstimator:
    """The limit for ``domain`` (default the paper's design at nside 180)."""
    return Limit3DEstimator(PAPER_DOMAIN3D if domain is None else domain, prior, **kw)
