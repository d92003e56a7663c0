"""The planar information limit for keys not yet cached, with less work per key (issue 25).

Computes the quantity :mod:`eyeviz.estimators.limit` defines (its module docstring:
Algorithm 1's density restricted to the key's polyhedron, n x n rays of eye A times K
Gauss-Legendre nodes in the distance rho along each ray, the 1/r- and 1/phi-weighted
posterior medians that are MAPE-optimal, Eq. 34) on the same nodes, organised so that a
new key costs about half the computation before issue 25 (``scripts/bench_limit.py``
measures both in one run):

* per-design tables (cached on (domain, n, K)): the grid's offsets b of the ray
  direction phi_A and e of the half angle delta, with their sines and cosines. By angle
  addition every ray quantity of a key is a combination of those four tables with
  per-key coefficients (eight sines and cosines a key, not four a ray): cos and sin of
  phi_A and of delta, and the six linear constraints (eye B's four half-planes and the
  two BFV lines, Prop. 4), each f sin(phi_A - beta) +- sin(delta) >= rhs / rho; one
  einsum makes them all (BLAS is avoided: its threads cost more than they save here);
* in v = 1 / rho each linear constraint bounds v from a side known per key (the sign of
  its rhs) when eye B's run is clear of both ends of the half bitmap, so no per-ray
  branch; the other keys take the general per-ray form;
* design-level shortcuts that change no answer: with h <= r_min both circle
  constraints cut every ray and r <= r_max never bounds rho from below;
  g >= r sin(gamma/2) is convex in rho wherever sin(delta) > sin(gamma/2), every ray of
  most keys, so its larger root is taken directly and the general root-finding runs on
  the other keys only;
* nodes laid out (key, Gauss node, ray), so every broadcast runs along a row of rays; r
  as sqrt(x^2 + y^2) in float32 (hypot is several times slower) where no square can
  overflow; no np.where on nodes (~3 ns an element here);
* both medians of a key in one call of :func:`row_medians`: one sort per row of 32-bit
  packed (value code, column) integers, the weights fetched with one flat ``take``, the
  CDF from block sums and one cumulative sum around the median.

The rays with no feasible stretch keep their nodes at the eye (zero weight), as in the
reference; :func:`row_medians` shows why such nodes never move a median. The answers
equal the reference (:func:`eyeviz.estimators.limit._reference_estimates`) up to float
rounding (tested on ~11,000 keys from m = 8 to m = 2^20), and each key's answer is a
function of that key alone (tested bit for bit, alone and in shuffled batches).
Measured on a 2-core machine shared with other jobs (load ~1.5, ``bench_limit.py``): a
new key batched 29 us against 59 us before (0.48x), one key per call 0.18 against
0.46 ms (0.39x); through the estimator (validation and cache included) 0.49x and 0.47x;
at m = 2^20 0.46x batched, 0.43x one key per call through the estimator.
Cutting each block to the rays with a stretch (a quarter of the nodes lie on rays with
none) was tried and measured slower: the gathers cost more than the nodes saved.
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
#: keys (LA, RA, LB, RB) -> LA + RA, RA - LA, LB, RB, LB (+1), RB (+1)
_KEY_INTS = np.array(
    [[1, -1, 0, 0, 0, 0], [1, 1, 0, 0, 0, 0], [0, 0, 1, 0, 1, 0], [0, 0, 0, 1, 0, 1]]
)
#: columns of that array holding rhs in the constraints' order: -2 h sin(beta) for LB,
#: RB, then -h sin psi, 2 h sin(beta) for LB + 1, RB + 1, then h sin psi
_RHS = np.array([35, 36, 33, 37, 38, 34])
#: Rows of the (N, 10, 4) matrix of :func:`rays`, as columns of the angles' [sin (0-7),
#: cos (8-15), -sin (16-23), -cos (24-31), 0 (32)], the angles being A, D, A - beta for
#: LB, RB, LB + 1, RB + 1, A - psi, A + psi. cos phi_A = cos A cos b - sin A sin b, and
#: so on; a constraint's row is [f sin(A - beta), f cos(A - beta), +-sin D, +-cos D]
#: with f = +1 for LB, RB (and the BFV lines), -1 for LB + 1, RB + 1, and the sign of
#: sin(delta) -1 for LB, RB + 1 and the BFV lines, +1 for RB, LB + 1.
_ROWS = np.array(
    [[8, 16, 32, 32], [0, 8, 32, 32], [32, 32, 1, 9], [32, 32, 9, 17],  # cu su sd cd
     [2, 10, 17, 25], [3, 11, 1, 9], [6, 14, 17, 25],  # LB, RB, line at psi
     [20, 28, 1, 9], [21, 29, 17, 25], [7, 15, 17, 25]]  # LB + 1, RB + 1, line at pi - psi
)  # fmt: skip


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
    scale: np.ndarray  # (6,) gamma / 2, gamma / 2, then gamma four times
    psis: np.ndarray  # (2,) -psi, psi
    rhs_edges: np.ndarray  # (4,) -2 h, -2 h, 2 h, 2 h (times sin beta: LB, RB, LB + 1, RB + 1)
    consts: np.ndarray  # (3,) 0, -h sin psi, h sin psi (the BFV lines' rhs)
    radii2: np.ndarray  # (2, 1, 1) r_min^2, r_max^2
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
    psi = math.asin(domain.l / h)
    tab = np.stack([np.cos(b), np.sin(b), np.cos(e), np.sin(e)])
    du = u2 - u1
    gx32, gw32 = gx.astype(np.float32)[:, None], gw.astype(np.float32)[:, None]
    for t in (tab, du, gx32, gw32):
        t.flags.writeable = False
    return Plan(
        n=n, k=k, gam=gam, h=h, s=math.sin(gam / 2), psi=psi,
        g_max=float(domain.g_max), r_min=float(domain.r_min), r_max=r_max,
        width=domain.width, scale=np.array([0.5 * gam] * 2 + [gam] * 4),
        psis=np.array([-psi, psi]), rhs_edges=np.array([-2 * h, -2 * h, 2 * h, 2 * h]),
        consts=np.array([0.0, -h * math.sin(psi), h * math.sin(psi)]),
        radii2=np.array([domain.r_min**2, r_max**2], float)[:, None, None],
        tab=tab, du=du, gx=gx32, gw=gw32,
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


# long: eye A's ray directions and their feasible ranges in one vectorised pass over every key's
# quadrature nodes
@np.errstate(divide="ignore", invalid="ignore")
def rays(keys: np.ndarray, p: Plan):
    """(cu, su, sd, cd, lo, hi, ok), arrays (N, n*n): eye A's ray directions cos/sin
    phi_A, sin/cos of the half angle delta, and the feasible stretch [lo, hi] of rho
    (``ok``: non-empty; lo = hi = 0 elsewhere) for int64 keys (N, 4)."""
    N = keys.shape[0]
    h = p.h
    # per key, exactly in integers: LA + RA, RA - LA, then eye B's sector edges LB, RB,
    # LB + 1, RB + 1; in angle: phi_A's and delta's centres A and D, the edges' beta
    ints = keys @ _KEY_INTS
    ints[:, 4:] += 1
    x = ints * p.scale
    # the angles whose sines and cosines build every ray quantity: A, D, A - beta for
    # the four edges, A -+ psi for the BFV lines (Prop. 4)
    ang = np.empty((N, 8))
    ang[:, :2] = x[:, :2]
    np.subtract(x[:, :1], x[:, 2:], out=ang[:, 2:6])
    np.add(x[:, :1], p.psis, out=ang[:, 6:])
    # sin, cos, -sin, -cos of the angles, 0, then the constraints' right-hand sides
    vals = np.empty((N, 39))
    np.sin(ang, out=vals[:, :8])
    np.cos(ang, out=vals[:, 8:16])
    np.negative(vals[:, :16], out=vals[:, 16:32])
    vals[:, 32:35] = p.consts
    # the linear constraints coef * rho >= rhs, coef = f sin(phi_A - beta) +- sin(delta)
    # (eye B's sector edges, f = +-1; the BFV lines), rhs = -2 h f sin(beta) (-+ h sin psi
    # for the BFV lines); ordered: rhs < 0 (LB, RB, the line at psi), then rhs > 0
    np.multiply(np.sin(x[:, 2:]), p.rhs_edges, out=vals[:, 35:])
    rhs = vals[:, _RHS]
    M = vals[:, _ROWS]
    M[:, 4:] /= rhs[:, :, None]
    Y = np.einsum("nij,jr->nir", M, p.tab)  # no BLAS: its threads cost more here
    cu, su, sd, cd = Y[:, 0], Y[:, 1], Y[:, 2], Y[:, 3]
    v = np.maximum.reduce(Y[:, 4:7], axis=1)
    np.maximum(v, 0.0, out=v)
    v += 0.0  # -0 -> +0
    hi = np.divide(1.0, v, out=v)
    v = np.minimum.reduce(Y[:, 7:10], axis=1)
    np.maximum(v, 0.0, out=v)  # v <= 0: no rho > 0, lo = inf
    v += 0.0
    lo = np.divide(1.0, v, out=v)
    low = ints.min(axis=0)  # RA - LA, LB: the lowest in the batch
    if low[2] <= 0 or ints[:, 3].max() >= p.width - 2:
        edge = np.flatnonzero((ints[:, 2] <= 0) | (ints[:, 3] >= p.width - 2))
        # beta = 0 or pi: rhs of either sign (or 0), bounds in rho instead
        c = np.einsum("nij,jr->nir", vals[edge][:, _ROWS[4:]], p.tab)
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
    if p.near:  # both circles at once: (2, N, R)
        hsu2 = su * su
        hsu2 *= h * h
        q = p.radii2 - hsu2
        np.sqrt(q, out=q)
        q += hcu
        np.maximum(lo, q[0], out=lo)
        np.minimum(hi, q[1], out=hi)
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
    root = qb * qb
    root += (-4 * qc) * qa
    np.sqrt(root, out=root)
    root -= qb
    root /= 2 * qa
    other = np.flatnonzero(qa.min(axis=1) <= 1e-15) if qa.min() <= 1e-15 else ()
    if len(other):  # keys with a ray at delta <= gamma/2: the general root-finding
        ql, qh = interval_quadratic(qa[other], qb[other], np.full((len(other), 1), qc))
        root[other] = ql
        hi[other] = np.minimum(hi[other], qh)
    np.maximum(lo, root, out=lo)
    ok = hi > lo  # a NaN or infinite lo fails; hi is never +inf past the r <= r_max bound
    if low[1] <= 0:  # keys with rays at delta <= 0 (RA <= LA)
        ok &= ints[:, 1:2] + p.du > 0
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


@np.errstate(divide="ignore", invalid="ignore", over="ignore")
def _nodes(cu, su, sd, cd, lo, hi, p: Plan, prior: str):
    """(values, weights, span, empty) for the N keys' nodes: values (2N, K n^2) float32,
    the nodes' distance r (rows 0..N-1) and azimuth phi (rows N..2N-1); weights the
    posterior weight (density times the Jacobian rho^2 cos(delta) / 2, as the reference)
    over r, then over phi (the MAPE medians' weights); span the (lowest, highest) value
    per row over the rays with a stretch (float32 (2N,) each, for :func:`row_medians`);
    empty (N,): no weight."""
    f32 = np.float32
    N, R = cu.shape
    half = (0.5 * (hi - lo)).astype(f32)[:, None, :]
    rho = (0.5 * (hi + lo)).astype(f32)[:, None, :] + half * p.gx  # (N, K, R)
    x = rho * cu.astype(f32)[:, None, :]
    x -= f32(p.h)
    y = rho * su.astype(f32)[:, None, :]
    g = rho * sd.astype(f32)[:, None, :]
    vals = np.empty((2, *rho.shape), f32)
    r, phi = vals[0], vals[1]
    if p.small:
        np.multiply(x, x, out=r)
        r += y * y
        np.sqrt(r, out=r)
    else:
        np.hypot(x, y, out=r)
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
    if w.max(initial=0) == np.inf:  # (rare: a zero density denominator)
        w[w == np.inf] = 0
    np.arctan2(y, x, out=phi)
    wts = np.maximum(vals, f32(1e-30))
    np.divide(w, wts, out=wts)
    empty = ~(w.reshape(N, -1).sum(axis=1) > 0)
    # each key's span of r and phi over the rays with a stretch (1 / 0 = inf and * 0 = 0
    # leave out the others). Along a ray from A, phi decreases (from pi at the eye) and
    # r increases where rho > h cu, which r >= r_min >= h ensures: the span is then that
    # of the first and last nodes (up to float32 rounding, which row_medians tolerates)
    on = (half[:, 0, :] > 0).astype(f32)
    span = np.empty((2, 2, N), f32)  # (low, high), (r, phi), key
    if p.near:  # the first and last nodes of r and of phi: (2, N, 2, R)
        ends = vals[:, :, :: p.k - 1 if p.k > 1 else 1, :]
        low = np.minimum(ends[:, :, 0], ends[:, :, -1])
        low /= on
        np.fmin.reduce(low, axis=2, out=span[0])
        np.maximum(ends[:, :, 0], ends[:, :, -1], out=low)
        low *= on
        np.fmax.reduce(low, axis=2, out=span[1])
    else:
        np.fmin.reduce(r / on[:, None], axis=(1, 2), out=span[0, 0])
        np.fmax.reduce(r * on[:, None], axis=(1, 2), out=span[1, 0])
        np.fmin.reduce(phi[:, -1, :] / on, axis=1, out=span[0, 1])
        np.fmax.reduce(phi[:, 0, :] * on, axis=1, out=span[1, 1])
    return vals.reshape(2 * N, -1), wts.reshape(2 * N, -1), span.reshape(2, 2 * N), empty


@functools.lru_cache(maxsize=8)
def _columns(P: int) -> np.ndarray:
    c = np.arange(P, dtype=np.int32)
    c.flags.writeable = False
    return c


_BLOCK = 32  # weights summed in blocks of 32 to find the median's neighbourhood
_PAIR = np.array([-1, 0])


@functools.lru_cache(maxsize=1)
def _window() -> np.ndarray:
    c = np.arange(3 * _BLOCK, dtype=np.int32)
    c.flags.writeable = False
    return c


# long: a weighted median per row in one vectorised pass over float32 buffers reused in place
def row_medians(v: np.ndarray, w: np.ndarray, span=None) -> np.ndarray:
    """Per row, the median of v >= 0 (float32, (N, P)) under weights w >= 0 (float32,
    (N, P)): the weighted CDF at node midpoints interpolated linearly, as
    :func:`eyeviz.estimators.limit.weighted_median` defines it.

    Each value's float32 bits (order-preserving for v >= 0) sit above its column in one
    integer, so one plain sort per row orders the values and carries the columns to fetch
    the weights with (one flat ``take``). The integer is 32-bit (sorted ~2.5x faster than
    64-bit) for up to 2^13 columns: ``span`` (lowest, highest value per row, float32
    (N,) each) must hold every node of positive weight, default that span computed here.
    Values outside it are clamped to its ends: a node before the first weighted one has
    CDF 0 and one after the last has CDF 1, so neither is ever the upper node of the
    interpolation, and the lower one only beside a lone weighted node, whose value is
    then the answer whatever the lower one's. A row whose span has more codes than the
    bits left beside the column drops its lowest bits (ties then ordered by column: an
    order error of at most 2^b float32 ulps for b dropped bits, b <= 8; on the paper's
    design b <= 3 for r and 0 for phi); a row wider still, and every row past 2^13
    columns, sorts full codes in a 64-bit integer. Each choice is the row's own: a row's
    answer does not depend on the rows computed with it.

    The CDF is found from sums of blocks of 32 sorted weights and one cumulative sum
    (float64) over the three blocks around the median, not over the whole row.
    """
    N, P = v.shape
    v = np.ascontiguousarray(v, np.float32)
    w = np.ascontiguousarray(w, np.float32)
    code = v.view(np.int32)
    cbits = max(1, (P - 1).bit_length())
    wide = np.arange(N)  # rows sorted by a 64-bit integer
    if cbits <= 13:
        if span is None:
            pos = w > 0
            cmin = np.min(code, axis=1, where=pos, initial=np.iinfo(np.int32).max)
            cmax = np.max(code, axis=1, where=pos, initial=0)
        else:
            cmin = np.ascontiguousarray(span[0], np.float32).view(np.int32)
            cmax = np.ascontiguousarray(span[1], np.float32).view(np.int32)
        width = np.maximum(cmax - cmin, 0)  # rows with no weight: cmin > cmax
        q = code - cmin[:, None]
        np.maximum(q, 0, out=q)
        np.minimum(q, width[:, None], out=q)
        # bits dropped per row, from that row alone (a row's answer never depends on the
        # rows batched with it): its span's bit length beyond the 31 - cbits available
        narrow: slice | np.ndarray = slice(None)
        if width.max() >> (31 - cbits):
            drop = np.frexp(width.astype(np.float64))[1] - (31 - cbits)
            np.maximum(drop, 0, out=drop)
            wide = np.flatnonzero(drop > 8)
            if wide.size:
                narrow = np.flatnonzero(drop <= 8)
                q = q[narrow]
            q >>= drop[narrow].astype(np.int32)[:, None]
        else:
            wide = wide[:0]
        q <<= cbits
        q |= _columns(P)
        q.sort(axis=1)
        q &= (1 << cbits) - 1
        col = q if not wide.size else np.empty((N, P), np.int32)
        if wide.size:
            col[narrow] = q
    else:
        col = np.empty((N, P), np.int32)
    if wide.size:  # each value's full code above its column
        packed = np.empty((wide.size, P), np.int64)
        halves = packed.view(np.int32).reshape(wide.size, P, 2)
        halves[..., _HI] = code[wide]
        halves[..., _LO] = _columns(P)
        packed.sort(axis=1)
        col[wide] = packed.view(np.int32).reshape(wide.size, P, 2)[..., _LO]
    rows = np.arange(N)
    off = np.arange(0, N * P, P, dtype=np.int32 if N * P < 2**31 else np.int64)[:, None]
    flat = col + off
    ws = np.take(w.reshape(-1), flat)
    nb = P // _BLOCK
    cum = np.zeros((N, nb + 1))  # the CDF (times the total) at the ends of the blocks
    if P % _BLOCK or nb < 3:
        base = np.zeros(N, np.intp)
        win = ws
        cum[:, -1] = ws.sum(axis=1, dtype=np.float64)
        half = 0.5 * cum[:, -1]
    else:
        # (einsum sums the blocks ~4x faster than .sum(axis=2))
        np.einsum("nbk->nb", ws.reshape(N, nb, _BLOCK)).cumsum(axis=1, out=cum[:, 1:])
        half = 0.5 * cum[:, -1]
        # the crossing lies in the first block whose cumulative weight reaches half the
        # total, or the next; its lower neighbour may end the block before
        jb = (cum[:, 1:] < half[:, None]).sum(axis=1)
        jb -= 1
        np.maximum(jb, 0, out=jb)
        np.minimum(jb, nb - 3, out=jb)
        base = jb * _BLOCK
        win = ws.reshape(-1)[(off + base[:, None]) + _window()]
    crit = win.cumsum(axis=1, dtype=np.float64)
    crit += cum[rows, base // _BLOCK][:, None]
    crit -= 0.5 * win  # the CDF at node midpoints, times the total
    i = (crit < half[:, None]).sum(axis=1)
    i += base
    np.maximum(i, 1, out=i)
    np.minimum(i, P - 1, out=i)
    i -= base
    both = i[:, None] + _PAIR  # the nodes below and above the median, in the window
    c0, c1 = crit[rows[:, None], both].T
    v0, v1 = v.reshape(-1)[flat[rows[:, None], base[:, None] + both]].astype(np.float64).T
    with np.errstate(divide="ignore", invalid="ignore"):
        t = (half - c0) / (c1 - c0)
    t = np.fmin(np.fmax(t, 0.0), 1.0)  # NaN (c1 = c0) -> 0
    return v0 + t * (v1 - v0)


def estimates(keys, domain: Domain, prior: str = "single", n: int = 12, k: int = 6):
    """(r, phi, empty) for int64 keys (N, 4): as
    :func:`eyeviz.estimators.limit.limit_estimates` (which calls this)."""
    keys = np.asarray(keys, np.int64).reshape(-1, 4)
    p = plan(domain, n, k)
    N = keys.shape[0]
    out = np.full((2, N), np.nan)  # r, phi
    empty = np.ones(N, bool)
    step = max(1, 60_000 // (n * n * k))
    for s0 in range(0, N, step):
        cu, su, sd, cd, lo, hi, ok = rays(keys[s0 : s0 + step], p)
        live = ok.any(axis=1)
        idx = live.nonzero()[0]
        if not idx.size:
            continue
        if idx.size < live.size:
            cu, su, sd, cd, lo, hi = (a[idx] for a in (cu, su, sd, cd, lo, hi))
        vals, wts, span, e = _nodes(cu, su, sd, cd, lo, hi, p, prior)
        both = row_medians(vals, wts, span)  # r's rows, then phi's
        idx += s0
        both = both.reshape(2, -1)
        both[:, e] = np.nan
        out[:, idx] = both
        empty[idx] = e
    # a sliver polyhedron can fall between the grid's rays: retry those keys on a 4x grid,
    # once a 2x grid's rays (a quarter of the 4x grid's) show that some ray reaches it
    again = empty.nonzero()[0]
    if again.size and n < 48:
        again = again[any_ray(keys[again], domain, 2 * n)]
    if again.size and n < 48:
        r2, p2, e2 = estimates(keys[again], domain, prior, 4 * n, k)
        out[0, again], out[1, again], empty[again] = r2, p2, e2
    return out[0], out[1], empty
