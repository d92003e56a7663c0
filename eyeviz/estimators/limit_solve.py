"""The planar information limit for keys not yet cached, with less work per key (issue 25).

Computes the quantity :mod:`eyeviz.estimators.limit` defines (its module docstring:
Algorithm 1's density restricted to the key's polyhedron, n x n rays of eye A times K
Gauss-Legendre nodes in the distance rho along each ray, the 1/r- and 1/phi-weighted
posterior medians that are MAPE-optimal, Eq. 34) on the same nodes, organised so that a
new key costs about half the earlier computation (``scripts/bench_limit.py``):

* per-design tables (cached on (domain, n, K)): the grid's offsets of the ray direction
  phi_A and of the half angle delta, with their sines and cosines. A key's n^2 ray
  directions then follow by angle addition from eight sines and cosines per key (not four
  per ray), and so do the six linear constraints of a ray: eye B's four half-planes and
  the two BFV lines (Prop. 4) are each sin(phi_A - beta) +- sin(delta) >= c / rho;
* design-level shortcuts that change no answer: with h <= r_min both circle constraints
  cut every ray (no branch per ray) and r <= r_max never bounds rho from below
  (r_max > sqrt(2) h); g >= r sin(gamma/2) is convex in rho wherever sin(delta) >
  sin(gamma/2), which is every ray of most keys, so its larger root is taken directly
  and the general root-finding runs on the other keys only;
* nodes laid out (key, Gauss node, ray), so every broadcast runs along a row of rays; r
  as sqrt(x^2 + y^2) in float32 (hypot is several times slower) where no square can
  overflow;
* the weighted medians by one sort per row of packed (value code, column) integers,
  32-bit when the row's codes allow it (:func:`row_medians`), the weights fetched with
  one flat ``take``.

The rays with no feasible stretch keep their nodes at the eye (zero weight), as in the
reference; :func:`row_medians` shows why such nodes never move a median. Differences
from the reference path (:func:`eyeviz.estimators.limit.reference_estimates`) are float
rounding: tested on a few thousand keys, far inside the error bound of the quadrature.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from eyeviz.core.domain import Domain

__all__ = ["Plan", "plan", "rays", "any_ray", "estimates", "row_medians", "interval_quadratic"]

_LO, _HI = (0, 1) if np.little_endian else (1, 0)
_fmin, _fmax = np.fmin.reduce, np.fmax.reduce  # NaN-skipping minimum / maximum
#: eye B's sector edges LB, LB + 1, RB, RB + 1 as half-planes: side and sign of g
_FLIP = np.array([1.0, -1.0, 1.0, -1.0])
#: sign of sin(delta) in the six linear constraints (eye B's four, the two BFV lines)
_BSIGN = (-1, 1, 1, -1, -1, -1)


@dataclass(frozen=True, eq=False)
class Plan:
    """Per-design constants and tables for an n x n grid with K nodes per ray."""

    n: int
    k: int
    gam: float  # one sector, 2 pi / m
    h: float
    s: float  # sin(gamma / 2)
    psi: float  # asin(l / h)
    g_max: float
    r_min: float
    r_max: float
    width: int  # m / 2
    tab: np.ndarray  # (4, R): cos b, sin b, cos e, sin e for the grid's offsets of phi_A,
    # b = (u1 + u2) gamma / 2, and of delta, e = (u2 - u1) gamma / 2
    du: np.ndarray  # (R,) u2 - u1
    gx: np.ndarray  # (K, 1) float32 Gauss-Legendre nodes and weights
    gw: np.ndarray
    near: bool  # h <= r_min and r_max^2 > 2 h^2: the circle shortcuts hold
    small: bool  # x^2 + y^2 of every node fits in float32


@functools.lru_cache(maxsize=32)
def plan(domain: Domain, n: int, k: int) -> Plan:
    """The tables of one design and grid (cached)."""
    gam = 2.0 * math.pi / domain.m
    u = (np.arange(n) + 0.5) / n
    u1, u2 = (v.ravel() for v in np.meshgrid(u, u, indexing="ij"))
    b = 0.5 * (u1 + u2) * gam
    e = 0.5 * (u2 - u1) * gam
    gx, gw = np.polynomial.legendre.leggauss(k)
    h, r_max = float(domain.h), float(domain.r_max)
    tab = np.stack([np.cos(b), np.sin(b), np.cos(e), np.sin(e)])
    du = u2 - u1
    gx32, gw32 = gx.astype(np.float32)[:, None], gw.astype(np.float32)[:, None]
    for t in (tab, du, gx32, gw32):
        t.flags.writeable = False
    return Plan(
        n=n, k=k, gam=gam, h=h, s=math.sin(gam / 2), psi=math.asin(domain.l / h),
        g_max=float(domain.g_max), r_min=float(domain.r_min), r_max=r_max,
        width=domain.width, tab=tab, du=du, gx=gx32, gw=gw32,
        near=h <= domain.r_min and r_max * r_max > 2 * h * h,
        small=2 * (h + r_max) < 1e18,
    )  # fmt: skip


def interval_quadratic(qa, qb, qc):
    """rho >= 0 with qa rho^2 + qb rho + qc >= 0 as [lo, hi] (lo > hi when empty).

    qc < 0 always here (the point rho = 0 is the eye centre, never feasible).
    """
    disc = qb * qb - 4 * qa * qc
    sq = np.sqrt(np.maximum(disc, 0.0))
    with np.errstate(divide="ignore", invalid="ignore"):
        r1 = (-qb - sq) / (2 * qa)
        r2 = (-qb + sq) / (2 * qa)
    pos = qa > 1e-15
    neg = qa < -1e-15
    lo = np.where(pos, np.maximum(r1, r2), np.inf)
    hi = np.full_like(lo, np.inf)
    # concave: between the roots, if real
    lo = np.where(neg, np.minimum(r1, r2), lo)
    hi = np.where(neg, np.maximum(r1, r2), hi)
    lo = np.where(neg & (disc < 0), np.inf, lo)
    # (nearly) linear: qb rho + qc >= 0
    lin = ~(pos | neg)
    with np.errstate(divide="ignore", invalid="ignore"):
        root = -qc / qb
    lo = np.where(lin, np.where(qb > 0, root, np.inf), lo)
    return lo, hi


def rays(keys: np.ndarray, p: Plan):
    """(cu, su, sd, cd, lo, hi, ok), arrays (N, n*n): eye A's ray directions cos/sin
    phi_A, sin/cos of the half angle delta, and the feasible stretch [lo, hi] of rho
    (``ok``: non-empty; lo = hi = 0 elsewhere) for int64 keys (N, 4)."""
    N = keys.shape[0]
    LA, RA, LB, RB = (keys[:, i] for i in range(4))
    gam = p.gam
    h = p.h
    # angles per key: phi_A's and delta's centres, phi_A - beta for eye B's sector edges,
    # phi_A -+ psi for the BFV lines
    A = (LA + RA) * (0.5 * gam)
    ang = np.empty((N, 8))
    ang[:, 0] = A
    ang[:, 1] = (RA - LA) * (0.5 * gam)
    ang[:, 2] = A - LB * gam
    ang[:, 3] = A - (LB + 1) * gam
    ang[:, 4] = A - RB * gam
    ang[:, 5] = A - (RB + 1) * gam
    ang[:, 6] = A - p.psi
    ang[:, 7] = A + p.psi
    sn, cs = np.sin(ang), np.cos(ang)
    # the six linear constraints coef * rho >= rhs with coef = f sin(phi_A - beta)
    # +- sin(delta) (eye B's four sector edges, f = +-1, then the BFV lines at psi and
    # pi - psi), by angle addition linear in the tables [cos b, sin b, cos e, sin e]
    coef = np.empty((N, 6, 4))
    coef[:, :4, 0] = sn[:, 2:6] * _FLIP
    coef[:, :4, 1] = cs[:, 2:6] * _FLIP
    coef[:, 4:, 0] = sn[:, 6:8]
    coef[:, 4:, 1] = cs[:, 6:8]
    coef[:, :, 2] = sn[:, 1:2] * _BSIGN
    coef[:, :, 3] = cs[:, 1:2] * _BSIGN
    rhs = np.empty((N, 6))
    rhs[:, :4] = np.sin(np.stack([LB, LB + 1, RB, RB + 1], axis=1) * gam)
    rhs[:, :4] *= (-2 * h) * _FLIP
    sp = math.sin(p.psi)
    rhs[:, 4] = -sp * h
    rhs[:, 5] = sp * h
    # every ray quantity at once: (N, 10, 4) rows over the (4, R) tables. Rows 0-3: cos
    # and sin of phi_A and of delta; rows 4-9: coef / rhs. With 0 < beta < pi (eye B's
    # run clear of both ends of the half bitmap) rhs has a fixed sign per constraint, so
    # in v = 1 / rho each constraint is a bound of known side: v >= coef / rhs for
    # rhs < 0 (constraints 0, 2, 4), v <= coef / rhs for rhs > 0 (1, 3, 5)
    M = np.zeros((N, 10, 4))
    M[:, 0, 0] = M[:, 1, 1] = cs[:, 0]
    M[:, 0, 1] = -sn[:, 0]
    M[:, 1, 0] = sn[:, 0]
    M[:, 2, 2] = M[:, 3, 3] = sn[:, 1]
    M[:, 2, 3] = M[:, 3, 2] = cs[:, 1]
    M[:, 3, 3] *= -1
    with np.errstate(divide="ignore", invalid="ignore"):
        np.divide(coef, rhs[:, :, None], out=M[:, 4:])
        Y = np.einsum("nij,jr->nir", M, p.tab)  # no BLAS: its threads cost more here
        cu, su, sd, cd = Y[:, 0], Y[:, 1], Y[:, 2], Y[:, 3]
        v = np.maximum(Y[:, 4], Y[:, 6])
        np.maximum(v, Y[:, 8], out=v)
        np.maximum(v, 0.0, out=v)
        v += 0.0  # -0 -> +0
        hi = np.divide(1.0, v, out=v)
        v = np.minimum(Y[:, 5], Y[:, 7])
        np.minimum(v, Y[:, 9], out=v)
        np.maximum(v, 0.0, out=v)  # v <= 0: no rho > 0, lo = inf
        v += 0.0
        lo = np.divide(1.0, v, out=v)
        edge = np.flatnonzero((LB <= 0) | (RB >= p.width - 2))
        if edge.size:  # beta = 0 or pi: rhs of either sign (or 0), bounds in rho
            c = np.einsum("nij,jr->nir", coef[edge], p.tab)
            r = rhs[edge][:, :, None]
            # coef > 0: rho >= rhs / coef, i.e. rhs / max(coef, 0) (for coef <= 0: +inf
            # when rhs > 0, infeasible; -inf otherwise, no bound); coef < 0 with rhs <= 0:
            # rho <= rhs / coef = -|rhs| / min(coef, -0) (+inf for coef > 0); NaN (rhs =
            # 0 = coef) is no bound, skipped by fmax / fmin
            lo[edge] = np.maximum(np.fmax.reduce(r / np.maximum(c, 0.0), axis=1), 0.0)
            hi[edge] = np.fmin.reduce(-np.abs(r) / np.minimum(c, -0.0), axis=1)
        np.minimum(hi, p.g_max / sd, out=hi)
    # r^2 = rho^2 - 2 rho h cu + h^2: r >= r_min is rho >= h cu + sqrt(r_min^2 - h^2 su^2)
    # and r <= r_max is rho <= h cu + sqrt(r_max^2 - h^2 su^2) (see the reference)
    hcu = h * cu
    if p.near:
        hsu2 = su * su
        hsu2 *= h * h
        q = p.r_min * p.r_min - hsu2
        np.sqrt(q, out=q)
        q += hcu
        np.maximum(lo, q, out=lo)
        q = p.r_max * p.r_max - hsu2
        np.sqrt(q, out=q)
        q += hcu
        np.minimum(hi, q, out=hi)
    else:
        au = -hcu
        for rr, keep_above in ((p.r_min, True), (p.r_max, False)):
            disc = au * au - h * h + rr * rr
            sq = np.sqrt(np.maximum(disc, 0.0))
            if keep_above:
                lo = np.where(disc >= 0, np.maximum(lo, -au + sq), lo)
            else:
                hi = np.where(disc >= 0, np.minimum(hi, -au + sq), -np.inf)
                lo = np.where(disc >= 0, np.maximum(lo, -au - sq), lo)
    # g >= r sin(gamma/2): qa rho^2 + qb rho + qc >= 0 with qa = sd^2 - s^2,
    # qb = 2 s^2 h cu, qc = -s^2 h^2; convex (qa > 0): rho >= the larger root
    s2 = p.s * p.s
    qa = sd * sd
    qa -= s2
    qb = (2 * s2) * hcu
    qc = -s2 * h * h
    with np.errstate(divide="ignore", invalid="ignore"):
        root = qb * qb
        root += (-4 * qc) * qa
        np.sqrt(root, out=root)
        root -= qb
        root /= 2 * qa
    other = np.flatnonzero(qa.min(axis=1) <= 1e-15)
    if other.size:  # keys with a ray at delta <= gamma/2: the general root-finding
        ql, qh = interval_quadratic(qa[other], qb[other], np.full((other.size, 1), qc))
        root[other] = ql
        hi[other] = np.minimum(hi[other], qh)
    np.maximum(lo, root, out=lo)
    ok = hi > lo  # a NaN or infinite lo fails; hi is never +inf past the r <= r_max bound
    if (RA <= LA).any():  # keys with rays at delta <= 0
        ok &= (RA - LA)[:, None] + p.du > 0
    # no stretch: lo = hi = 0 (the reference's nodes at the eye, with zero weight); both
    # made finite first, leaving the rays with a stretch as they are (hi > lo >= 0)
    np.maximum(hi, 0.0, out=hi)
    np.fmin(lo, hi, out=lo)
    hi *= ok
    lo *= ok
    return cu, su, sd, cd, lo, hi, ok


def any_ray(keys: np.ndarray, domain: Domain, n: int) -> np.ndarray:
    """Per key: does any ray of the n x n grid have a feasible stretch (no nodes)."""
    p = plan(domain, n, 1)
    out = np.zeros(len(keys), bool)
    step = max(1, 40_000 // (n * n))  # ~40,000 rays a block: the six constraints in cache
    for s0 in range(0, len(keys), step):
        out[s0 : s0 + step] = rays(keys[s0 : s0 + step], p)[6].any(axis=1)
    return out


def _nodes(cu, su, sd, cd, lo, hi, p: Plan, prior: str):
    """(r, phi, w, r_span, phi_span): the nodes' distance, azimuth and posterior weight
    (density times the Jacobian rho^2 cos(delta) / 2, as the reference), float32
    (N, K * n^2), and per key the (lowest, highest) value of r and of phi over the rays
    with a stretch (float32 (N,) each), for :func:`row_medians`."""
    f32 = np.float32
    N, R = cu.shape
    half = (0.5 * (hi - lo)).astype(f32)[:, None, :]
    rho = (0.5 * (hi + lo)).astype(f32)[:, None, :] + half * p.gx  # (N, K, R)
    x = rho * cu.astype(f32)[:, None, :]
    x -= f32(p.h)
    y = rho * su.astype(f32)[:, None, :]
    g = rho * sd.astype(f32)[:, None, :]
    if p.small:
        r = x * x
        r += y * y
        np.sqrt(r, out=r)
    else:
        r = np.hypot(x, y)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        g /= r
        np.minimum(g, f32(1), out=g)
        np.arcsin(g, out=g)
        g *= f32(-2)
        g += f32(math.pi - 2 * p.psi)  # the azimuth range left at this (r, g)
        den = r * f32(-p.s)
        den += f32(p.g_max)
        den *= r
        den *= g
        w = rho * rho
        w /= den
        if prior == "multi":
            w *= r
        w *= cd.astype(f32)[:, None, :] * half
        w *= p.gw
    # weight 0 for NaN, inf and <= 0 (rays with no stretch: half = 0), no np.where
    np.fmax(w, f32(0), out=w)
    w[w == np.inf] = 0
    phi = np.arctan2(y, x)
    # each key's span of r and phi over the rays with a stretch (1 / 0 = inf and * 0 = 0
    # leave out the others). Along a ray from A, phi decreases (from pi at the eye) and
    # r increases where rho > h cu, which r >= r_min >= h ensures: the span is then that
    # of the first and last nodes (up to float32 rounding, which row_medians tolerates)
    on = (half[:, 0, :] > 0).astype(f32)
    with np.errstate(divide="ignore", invalid="ignore"):
        if p.near:
            r_span = _fmin(r[:, 0, :] / on, 1), _fmax(r[:, -1, :] * on, 1)
        else:
            r_span = _fmin(r / on[:, None], (1, 2)), _fmax(r * on[:, None], (1, 2))
        p_span = _fmin(phi[:, -1, :] / on, 1), _fmax(phi[:, 0, :] * on, 1)
    return r.reshape(N, -1), phi.reshape(N, -1), w.reshape(N, -1), r_span, p_span


@functools.lru_cache(maxsize=8)
def _columns(P: int) -> np.ndarray:
    c = np.arange(P, dtype=np.int32)
    c.flags.writeable = False
    return c


_BLOCK = 32  # weights summed in blocks of 32 to find the median's neighbourhood


def row_medians(v: np.ndarray, w: np.ndarray, span=None) -> np.ndarray:
    """Per row, the median of v >= 0 (float32, (N, P)) under weights w >= 0 (float32,
    (N, P)): the weighted CDF at node midpoints interpolated linearly, as
    :func:`eyeviz.estimators.limit.weighted_median` defines it.

    Each value's float32 bits (order-preserving for v >= 0) sit above its column in one
    integer, so one plain sort per row orders the values and carries the columns to fetch
    the weights with (one flat ``take``). The integer is 32-bit (sorted ~2.5x faster than
    64-bit) when the row's values span few enough codes: ``span`` (lowest, highest value
    per row, float32 (N,) each) must hold every node of positive weight, default that
    span computed here. Values outside it are clamped to its ends: a node before the
    first weighted one has CDF 0 and one after the last has CDF 1, so neither is ever the
    upper node of the interpolation, and the lower one only beside a lone weighted node,
    whose value is then the answer whatever the lower one's. A span too wide for the
    column bits drops its lowest bits (ties then ordered by column: an order error of at
    most 2^b float32 ulps for b dropped bits, b <= 8); rows wider still, or more than 2^13
    columns, use a 64-bit integer.

    The CDF is found from sums of blocks of 32 sorted weights (float64) and one cumulative
    sum over the three blocks around the median, not over the whole row.
    """
    N, P = v.shape
    v = np.ascontiguousarray(v, np.float32)
    w = np.ascontiguousarray(w, np.float32)
    code = v.view(np.int32)
    cbits = max(1, (P - 1).bit_length())
    drop = 99
    if cbits <= 13 and N:
        if span is None:
            pos = w > 0
            cmin = np.min(code, axis=1, where=pos, initial=np.iinfo(np.int32).max)
            cmax = np.max(code, axis=1, where=pos, initial=0)
        else:
            cmin = np.ascontiguousarray(span[0], np.float32).view(np.int32)
            cmax = np.ascontiguousarray(span[1], np.float32).view(np.int32)
        width = np.maximum(cmax - cmin, 0)  # rows with no weight: cmin > cmax
        drop = max(0, int(width.max()).bit_length() - (31 - cbits))
    if drop <= 8:
        q = code - cmin[:, None]
        np.maximum(q, 0, out=q)
        np.minimum(q, width[:, None], out=q)
        if drop:
            q >>= drop
        q <<= cbits
        q |= _columns(P)
        q.sort(axis=1)
        col = q & ((1 << cbits) - 1)
    else:
        packed = np.empty((N, P), np.int64)
        halves = packed.view(np.int32).reshape(N, P, 2)
        halves[..., _HI] = code
        halves[..., _LO] = _columns(P)
        packed.sort(axis=1)
        col = packed.view(np.int32).reshape(N, P, 2)[..., _LO]
    rows = np.arange(N)
    flat = col + (rows * P).astype(np.int32 if N * P < 2**31 else np.int64)[:, None]
    ws = np.take(w.reshape(-1), flat)
    nb = P // _BLOCK
    if P % _BLOCK or nb < 3:
        cw = np.cumsum(ws, axis=1, dtype=np.float64)
        tot = cw[:, -1].copy()
        crit = cw - 0.5 * ws
        base = np.zeros(N, np.intp)
    else:
        # (einsum sums the blocks ~4x faster than .sum(axis=2))
        blocks = np.einsum("nbk->nb", ws.reshape(N, nb, _BLOCK))
        blocks = np.cumsum(blocks, axis=1, dtype=np.float64)
        tot = blocks[:, -1].copy()
        # the crossing lies in the first block whose cumulative weight reaches half the
        # total, or the next; its lower neighbour may end the block before
        jb = np.count_nonzero(blocks < (0.5 * tot)[:, None], axis=1)
        sb = np.clip(jb - 1, 0, nb - 3)
        prefix = np.where(sb > 0, blocks[rows, sb - 1], 0.0)
        base = sb * _BLOCK
        win = ws[rows[:, None], base[:, None] + np.arange(3 * _BLOCK)]
        crit = np.cumsum(win, axis=1, dtype=np.float64)
        crit += prefix[:, None]
        crit -= 0.5 * win
    i = np.count_nonzero(crit < (0.5 * tot)[:, None], axis=1)
    i1 = np.clip(base + i, 1, P - 1) - base
    i0 = i1 - 1
    t_ = np.where(tot > 0, tot, 1.0)
    m0, m1 = crit[rows, i0] / t_, crit[rows, i1] / t_
    vf = v.reshape(-1)
    v0 = vf[flat[rows, base + i0]].astype(np.float64)
    v1 = vf[flat[rows, base + i1]].astype(np.float64)
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.clip((0.5 - m0) / (m1 - m0), 0.0, 1.0)
    t = np.where(np.isfinite(t), t, 0.0)
    return v0 + t * (v1 - v0)


def estimates(keys, domain: Domain, prior: str = "single", n: int = 12, k: int = 6):
    """(r, phi, empty) for int64 keys (N, 4): as
    :func:`eyeviz.estimators.limit.limit_estimates` (which calls this)."""
    keys = np.asarray(keys, np.int64).reshape(-1, 4)
    p = plan(domain, n, k)
    N = keys.shape[0]
    r_out = np.full(N, np.nan)
    p_out = np.full(N, np.nan)
    empty = np.ones(N, bool)
    step = max(1, 60_000 // (n * n * k))
    for s0 in range(0, N, step):
        cu, su, sd, cd, lo, hi, ok = rays(keys[s0 : s0 + step], p)
        live = ok.any(axis=1)
        idx = np.flatnonzero(live)
        if not idx.size:
            continue
        if idx.size < live.size:
            cu, su, sd, cd, lo, hi = (a[idx] for a in (cu, su, sd, cd, lo, hi))
        r, phi, w, r_span, p_span = _nodes(cu, su, sd, cd, lo, hi, p, prior)
        e = ~(w.sum(axis=1) > 0)
        wr = w / np.maximum(r, np.float32(1e-30))
        wp = w / np.maximum(phi, np.float32(1e-30))
        M = idx.size
        if M <= 16:  # one call for both medians (rows are independent): less overhead
            span = (np.concatenate([r_span[0], p_span[0]]), np.concatenate([r_span[1], p_span[1]]))
            both = row_medians(np.concatenate([r, phi]), np.concatenate([wr, wp]), span)
            rr, pp = both[:M], both[M:]
        else:
            rr, pp = row_medians(r, wr, r_span), row_medians(phi, wp, p_span)
        idx += s0
        r_out[idx] = np.where(e, np.nan, rr)
        p_out[idx] = np.where(e, np.nan, pp)
        empty[idx] = e
    # a sliver polyhedron can fall between the grid's rays: retry those keys on a 4x grid,
    # once a 2x grid's rays (a quarter of the 4x grid's) show that some ray reaches it
    again = np.flatnonzero(empty)
    if again.size and n < 48:
        again = again[any_ray(keys[again], domain, 2 * n)]
    if again.size and n < 48:
        r2, p2, e2 = estimates(keys[again], domain, prior, 4 * n, k)
        r_out[again], p_out[again], empty[again] = r2, p2, e2
    return r_out, p_out, empty
