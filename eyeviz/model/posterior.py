"""The posterior over feature centres given the bitmaps: the ``posterior`` layer (issue 10
item 5). Qt-, VTK- and matplotlib-free; cached per key (a drag changes the key rarely).

A feature's bitmaps are its key (LA, RA, LB, RB) (Prop. 2); the features (x, y, g) giving
that key form a convex polyhedron (:mod:`eyeviz.core.ambiguity`: eight half-spaces
``a . p + b g >= c``, linear in the centre p and g jointly). The posterior is Algorithm 1's
prior density restricted to it (:mod:`eyeviz.estimators.limit`): in (x, y, g)

    f(x, y, g) = p(r) / r * 1 / (g_max - r sin(gamma/2)) * 1 / (pi - 2 psi - 2 asin(g/r))

on r_min <= r <= r_max, r sin(gamma/2) <= g <= g_max and the BFV
psi + asin(g/r) <= phi <= pi - psi - asin(g/r) (Algorithm 1 steps 7-12, Eq. 15), with
p(r) = 1 (single pass) or r (multi pass). The shading is its marginal over *every* g
the key allows (not only the feature's own g): for a centre p the allowed g form an
interval [g_lo(p), g_hi(p)] (each constraint bounds g on one side, the BFV gives
g <= r sin(min(phi - psi, pi - psi - phi))), and

    density(p) = integral of f(p, g) over [g_lo(p), g_hi(p)]

by 6-point Gauss-Legendre. It is evaluated at the centres of a polar grid (about the
origin, ``N_R`` x ``N_PHI`` cells) spanning the support found by the limit's quadrature
nodes (:func:`eyeviz.estimators.limit.posterior_nodes`), so each drawn cell is a
midpoint-rule value of the density (the nodes' own weights are quadrature weights, not
samples: drawing them would shade where the rays are dense). The cell masses sum to 1.
The estimate marked is the ``limit`` estimator's (the MAPE-optimal 1/r-weighted median,
Eq. 34), the same the predictions layer draws. A key the prior cannot produce (g = 5
beyond r = 1146, say) is ``empty``: no cells, and the estimate is the triangulation.
"""

from __future__ import annotations

import math
from collections import OrderedDict
from dataclasses import dataclass, field

import numpy as np

from eyeviz.core.domain import Domain
from eyeviz.core.geometry import EyePair

__all__ = [
    "N_PHI",
    "N_R",
    "Posterior",
    "key_of",
    "posterior_for_key",
    "posterior_of",
    "readout",
]

N_R = 72  # radial cells
N_PHI = 18  # angular cells
_GAUSS = 6
_CACHE: OrderedDict[tuple, Posterior] = OrderedDict()


def _none() -> np.ndarray:
    return np.zeros(0)


_CACHE_SIZE = 64


@dataclass(frozen=True)
class Posterior:
    """The posterior of one key over feature centres.

    ``x, y`` (P,) the centres of the non-empty grid cells, ``g`` (P,) the posterior mean
    radius at each, ``weight`` (P,) each cell's posterior mass (sums to 1), ``density``
    (P,) mass per unit area scaled to a maximum of 1 (for shading), ``cells`` (P, 4, 2) the
    cells' corners (polar quads, counter-clockwise), ``r_hat, phi_hat`` the limit's
    estimate, ``empty`` True when the prior cannot produce the key (P = 0). The whole grid
    (for a seamless mesh): ``r_edges`` (N_R + 1), ``phi_edges`` (N_PHI + 1) and ``grid``
    (N_R, N_PHI), the density scaled to a maximum of 1, 0 in cells without mass.
    """

    key: tuple[int, int, int, int]
    domain: Domain
    prior: str
    x: np.ndarray
    y: np.ndarray
    g: np.ndarray
    weight: np.ndarray
    density: np.ndarray
    cells: np.ndarray
    r_hat: float
    phi_hat: float
    empty: bool
    r_edges: np.ndarray = field(default_factory=_none)  # the grid: N_R + 1 radii,
    phi_edges: np.ndarray = field(default_factory=_none)  # N_PHI + 1 azimuths (rad),
    grid: np.ndarray = field(default_factory=_none)  # (N_R, N_PHI) density / max (0: none)

    @property
    def n(self) -> int:
        return int(self.x.shape[0])

    def r_interval(self, mass: float = 0.9) -> tuple[float, float]:
        """The central interval of r holding ``mass`` of the posterior (cell centres)."""
        if self.empty or self.n == 0:
            return (math.nan, math.nan)
        r = np.hypot(self.x, self.y)
        o = np.argsort(r)
        cw = np.cumsum(self.weight[o])
        lo = float(np.interp((1 - mass) / 2, cw, r[o]))
        hi = float(np.interp((1 + mass) / 2, cw, r[o]))
        return lo, hi

    @property
    def estimate(self) -> tuple[float, float]:
        """(x, y) of the limit's estimate."""
        return (self.r_hat * math.cos(self.phi_hat), self.r_hat * math.sin(self.phi_hat))


def key_of(pair: EyePair, x: float, y: float, g: float) -> tuple[int, int, int, int]:
    """The lit intervals (LA, RA, LB, RB) of one feature (Prop. 2)."""
    iv = pair.intervals(np.array([float(x)]), np.array([float(y)]), np.array([float(g)]))
    return (int(iv[0][0]), int(iv[1][0]), int(iv[2][0]), int(iv[3][0]))


def _density(domain: Domain, key, prior: str, x: np.ndarray, y: np.ndarray):
    """(density, mean g) at centres (x, y): f integrated over the key's g interval."""
    from eyeviz.core.ambiguity import halfplanes

    pair = domain.eyes
    a, b, c, _ = halfplanes(pair, key)
    s = math.sin(pair.gamma / 2)
    psi = math.asin(domain.l / domain.h)
    r = np.hypot(x, y)
    phi = np.arctan2(y, x)
    lo = np.maximum(r * s, 0.0)
    hi = np.minimum(domain.g_max, r * np.sin(np.minimum(phi - psi, math.pi - psi - phi)))
    ap = x[:, None] * a[:, 0] + y[:, None] * a[:, 1]  # (P, 8)
    need = c[None, :] - ap  # b g >= c - a.p, b = +-1
    lo = np.maximum(lo, np.where(b > 0, need, -np.inf).max(axis=1))
    hi = np.minimum(hi, np.where(b < 0, -need, np.inf).min(axis=1))
    ok = (hi > lo) & (r >= domain.r_min) & (r <= domain.r_max)
    lo, hi = np.where(ok, lo, 0.0), np.where(ok, hi, 0.0)
    gx, gw = np.polynomial.legendre.leggauss(_GAUSS)
    half = 0.5 * (hi - lo)
    g = 0.5 * (hi + lo)[:, None] + half[:, None] * gx  # (P, K)
    rr = r[:, None]
    with np.errstate(divide="ignore", invalid="ignore"):
        width = math.pi - 2 * psi - 2 * np.arcsin(np.minimum(g / rr, 1.0))
        f = 1.0 / (rr * (domain.g_max - rr * s) * width)
    if prior == "multi":
        f = f * rr
    f = np.where(ok[:, None] & np.isfinite(f) & (f > 0), f, 0.0) * gw * half[:, None]
    dens = f.sum(axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        gbar = np.where(dens > 0, (f * g).sum(axis=1) / dens, np.nan)
    return dens, gbar


def _compute(domain: Domain, key: tuple[int, int, int, int], prior: str) -> Posterior:
    from eyeviz.estimators.limit import LimitEstimator, posterior_nodes

    est = LimitEstimator(domain, prior)
    pred = est.predict_intervals(*key)
    r_hat, phi_hat = float(np.atleast_1d(pred.r)[0]), float(np.atleast_1d(pred.phi)[0])
    nd = posterior_nodes([key], domain, prior)
    keep = nd.w[0] > 0
    none = np.zeros(0)
    if not keep.any():
        return Posterior(
            key, domain, prior, none, none, none, none, none, np.zeros((0, 4, 2)),
            r_hat, phi_hat, True,
        )  # fmt: skip
    rn, pn = nd.r[0][keep].astype(np.float64), nd.phi[0][keep].astype(np.float64)
    r0, r1 = float(rn.min()), float(rn.max())
    p0, p1 = float(pn.min()), float(pn.max())
    dr = max(r1 - r0, 1e-6 * r1) / (N_R - 2)
    dp = max(p1 - p0, 1e-9) / (N_PHI - 2)
    re = r0 - dr + dr * np.arange(N_R + 1)  # one cell of margin each side
    pe = p0 - dp + dp * np.arange(N_PHI + 1)
    rc, pc = 0.5 * (re[1:] + re[:-1]), 0.5 * (pe[1:] + pe[:-1])
    R, P = (v.ravel() for v in np.meshgrid(rc, pc, indexing="ij"))
    x, y = R * np.cos(P), R * np.sin(P)
    dens, gbar = _density(domain, key, prior, x, y)
    mass = dens * R * dr * dp
    ok = mass > 0
    if not ok.any():  # a sliver between the grid's centres: the nodes themselves
        w = nd.w[0][keep].astype(np.float64)
        xs, ys = nd.x[0][keep].astype(np.float64), nd.y[0][keep].astype(np.float64)
        gs = nd.g[0][keep].astype(np.float64)
        cells = np.repeat(np.column_stack([xs, ys])[:, None, :], 4, axis=1)
        return Posterior(
            key, domain, prior, xs, ys, gs, w / w.sum(), np.ones_like(w), cells,
            r_hat, phi_hat, False,
        )  # fmt: skip
    i = np.flatnonzero(ok)
    ri, pi_ = np.divmod(i, N_PHI)
    corners = [
        (re[ri], pe[pi_]),
        (re[ri + 1], pe[pi_]),
        (re[ri + 1], pe[pi_ + 1]),
        (re[ri], pe[pi_ + 1]),
    ]
    cells = np.stack([np.column_stack([rr * np.cos(pp), rr * np.sin(pp)]) for rr, pp in corners], 1)
    d = dens[i]
    grid = np.where(ok, dens, 0.0).reshape(N_R, N_PHI) / d.max()
    return Posterior(
        key, domain, prior, x[i], y[i], gbar[i], mass[i] / mass[i].sum(), d / d.max(), cells,
        r_hat, phi_hat, False, re, pe, grid,
    )  # fmt: skip


def posterior_for_key(key, domain: Domain, prior: str = "single") -> Posterior:
    """The :class:`Posterior` of ``key`` = (LA, RA, LB, RB) for eyes and prior ``domain``
    (cached: the last 64 keys). ValueError for a key that is not one run per eye in the
    half bitmaps 0..m/2-1 (Section 4: what every estimator sees)."""
    la, ra, lb, rb = (int(v) for v in key)
    kk = (la, ra, lb, rb)
    if not (0 <= la <= ra < domain.width and 0 <= lb <= rb < domain.width):
        raise ValueError(f"key {kk} is not one lit run per eye within the half bitmaps")
    k = (domain, kk, str(prior))
    hit = _CACHE.get(k)
    if hit is not None:
        _CACHE.move_to_end(k)
        return hit
    post = _compute(domain, kk, str(prior))
    _CACHE[k] = post
    while len(_CACHE) > _CACHE_SIZE:
        _CACHE.popitem(last=False)
    return post


def posterior_of(
    pair: EyePair, x: float, y: float, g: float, prior: str = "single", domain: Domain | None = None
) -> Posterior:
    """The posterior for the bitmaps of feature (x, y, g) seen by ``pair``; the prior's
    ranges are Table 4's (``domain`` overrides them; its h, l, m must be the pair's)."""
    dom = Domain.from_eyes(pair) if domain is None else domain
    if dom.design != (float(pair.h), float(pair.l), int(pair.m)):
        raise ValueError(f"domain {dom.design} is not the eyes' design")
    return posterior_for_key(key_of(pair, x, y, g), dom, prior)


def readout(pair: EyePair, x: float, y: float, g: float) -> str:
    """Two short lines for the app's readout: where the posterior's mass is and the limit's
    answer, or why there is no posterior."""
    try:
        post = posterior_of(pair, x, y, g)
    except (ValueError, ArithmeticError):
        return "none: not one lit run per eye"
    if post.empty:
        return "none: the prior never makes these bitmaps\n(g below r sin(γ/2), or r out of range)"
    lo, hi = post.r_interval(0.9)
    deg = math.degrees(post.phi_hat)
    return f"90 % in r ∈ [{lo:.0f}, {hi:.0f}]\nlimit r {post.r_hat:.0f}, φ {deg:.2f}°"
