"""The HEALPix proposal's set-up compiled (numba): the linearisation of each edge cell's
distance about a key's centre (:meth:`eyeviz.estimators.limit3d_eye._Eye.linearise`,
called at every zoom level of the centre search) and the affine forms of the model built
from it (``_Eye._affine``, bit for bit), and the edge cells' boundary samples
(``healpix.boundaries``, to a few ulps); the model's evaluation (:func:`_affine_lists`,
inlined into its callers here, in :mod:`.limit3d_locate` and in :mod:`.limit3d_draws`, the
search along A's rays and the draws) and the box's bisection.

The linearisation and the boundaries are not bit for bit the numpy reference's
(``EYEVIZ_JIT=0``): numpy's einsum sums its three products in an order of its own, and its
arctan2, sin and cos are not ``math``'s to the last bit. The kernels compute the same
formulas and agree with the reference to a few ulps
(tests/core/test_kernels_limit3d_affine.py). Only where draws are proposed depends on these
numbers (each draw's weight uses the proposal it was drawn from); every draw is still
checked exactly.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from eyeviz.core.kernels import healpix_boundary
from eyeviz.core.kernels.healpix_boundary import _pix2xyf, stamp_with

# before the first kernel: its cache carries the source of the module it calls as well
stamp_with(__file__, healpix_boundary.__file__)

__all__ = [
    "affine_bounds_kernel",
    "extent_kernel",
    "linearise_kernel",
    "affine_kernel",
    "affine_forms_kernel",
    "candidates_kernel",
    "boundaries_kernel",
    "compact_kernel",
    "box_lists_kernel",
    "warm",
]

_jit = njit(cache=True, nogil=True)
#: the model's evaluation, inlined into its callers (numba IR inlining): a call that
#: passes the model's arrays costs a reference count on each, more than the evaluation
#: itself (2-3x the evaluations a second inlined)
_jit_inline = njit(cache=True, nogil=True, inline="always")


@_jit
def _max(m, x):
    """numpy's maximum: NaN wins."""
    if m != m:
        return m
    if x != x or x > m:
        return x
    return m


@_jit
def _min(m, x):
    """numpy's minimum: NaN wins."""
    if m != m:
        return m
    if x != x or x < m:
        return x
    return m


@_jit
def _affine_at(a_lit, t_lit, a_unl, t_unl, n, dx, dy):
    """(max_lit, min_unlit) of the affine model of key n at one offset (dx, dy)."""
    lo = -np.inf
    hi2 = np.inf
    for k in range(a_lit.shape[1]):
        v = t_lit[n, k, 0] * dx
        v = v + t_lit[n, k, 1] * dy
        lo = _max(lo, a_lit[n, k] - v)
        w = t_unl[n, k, 0] * dx
        w = w + t_unl[n, k, 1] * dy
        hi2 = _min(hi2, a_unl[n, k] - w)
    hi2 = hi2 + (dx * dx + dy * dy)
    return lo, math.sqrt(_max(hi2, 0.0))


@_jit_inline
def _affine_lists(a_lit, t_lit, a_unl, t_unl, lists, n, dx, dy):
    """:func:`_affine_at` on the key's lit and unlit cells alone (``lists``: the model's
    lit cells (l_a (N, KL), l_t (N, KL, 2), nl (N,)) and unlit ones (u_a, u_t, nu) in slot
    order, _Eye._affine): a padding or unlit slot gives max_lit -inf - (0 dx + 0 dy) =
    -inf, which changes no maximum, and likewise +inf for min_unlit, as long as dx and dy
    are finite (0 * inf is NaN: then every slot, as the reference)."""
    l_a, l_t, nl, u_a, u_t, nu = lists
    return _affine_flat(a_lit, t_lit, a_unl, t_unl, l_a, l_t, nl, u_a, u_t, nu, n, dx, dy)


@_jit_inline
def _affine_flat(a_lit, t_lit, a_unl, t_unl, l_a, l_t, nl, u_a, u_t, nu, n, dx, dy):
    """:func:`_affine_lists` with the lists' six arrays passed one by one: a caller in a
    loop unpacks the tuple once (each unpacking counts a reference on each array, atomic
    operations that cost more than the evaluation)."""
    if not (math.isfinite(dx) and math.isfinite(dy)):
        return _affine_at(a_lit, t_lit, a_unl, t_unl, n, dx, dy)
    # a plain compare-and-select, not numpy's NaN-first _max / _min: with dx, dy finite
    # and the lists' forms finite nothing here is NaN, so the value is the same, and the
    # loop compiles to a few instructions a cell (2.3x the evaluations a second)
    lo = -np.inf
    for k in range(nl[n]):
        v = l_t[n, k, 0] * dx
        v = v + l_t[n, k, 1] * dy
        v = l_a[n, k] - v
        lo = v if v > lo else lo
    hi2 = np.inf
    for k in range(nu[n]):
        w = u_t[n, k, 0] * dx
        w = w + u_t[n, k, 1] * dy
        w = u_a[n, k] - w
        hi2 = w if w < hi2 else hi2
    hi2 = hi2 + (dx * dx + dy * dy)
    return lo, math.sqrt(_max(hi2, 0.0))


@_jit_inline
def _affine_points(lists, n, gx, gy, m, lo, hi):
    """:func:`_affine_lists` of key n at the m points (gx[j], gy[j]) (finite), into lo[j],
    hi[j]: the same operations on each point in the same order (a form's products, its
    difference, the running max and min, the squared offset, the root), with the points
    as the inner loop (vectorised by the compiler), so the same bits."""
    l_a, l_t, nl, u_a, u_t, nu = lists
    for j in range(m):
        lo[j] = -np.inf
        hi[j] = np.inf
    for k in range(nl[n]):
        a, t0, t1 = l_a[n, k], l_t[n, k, 0], l_t[n, k, 1]
        for j in range(m):
            v = t0 * gx[j]
            v = v + t1 * gy[j]
            v = a - v
            lo[j] = v if v > lo[j] else lo[j]
    for k in range(nu[n]):
        a, t0, t1 = u_a[n, k], u_t[n, k, 0], u_t[n, k, 1]
        for j in range(m):
            w = t0 * gx[j]
            w = w + t1 * gy[j]
            w = a - w
            hi[j] = w if w < hi[j] else hi[j]
    for j in range(m):
        h = hi[j] + (gx[j] * gx[j] + gy[j] * gy[j])
        hi[j] = math.sqrt(_max(h, 0.0))


@_jit
def affine_bounds_kernel(a_lit, t_lit, a_unl, t_unl, lists, delta, lo, hi):
    """_Eye.bounds: lo, hi (N, G) at gnomonic offsets delta (N, G, 2)."""
    for n in range(delta.shape[0]):
        for g in range(delta.shape[1]):
            lo[n, g], hi[n, g] = _affine_lists(
                a_lit, t_lit, a_unl, t_unl, lists, n, delta[n, g, 0], delta[n, g, 1]
            )


@_jit
def extent_kernel(a_lit, t_lit, a_unl, t_unl, lists, dirs, reach, slack, iters, todo, hi):
    """limit3d_proposal._extent's bisection: along each direction dirs[k] (K, 2) from each
    key's centre, ``iters`` halvings of [0, reach] keeping the model's G = min_unlit -
    max_lit >= -slack[n] below; hi (N, K) the outer ends (the same arithmetic as numpy's:
    the same bits), on the keys ``todo`` (N,) only (the others' rows left as they were)."""
    nd = dirs.shape[0]
    lo_, hi_, mid = np.empty(nd), np.empty(nd), np.empty(nd)
    gx, gy, a, b = np.empty(nd), np.empty(nd), np.empty(nd), np.empty(nd)
    for n in range(hi.shape[0]):
        if not todo[n]:
            continue
        if not math.isfinite(reach):  # the model's non-finite path: one point at a time
            for k in range(nd):
                lo1 = 0.0
                hi1 = reach
                for _ in range(iters):
                    m1 = 0.5 * (lo1 + hi1)
                    a1, b1 = _affine_lists(a_lit, t_lit, a_unl, t_unl, lists, n,
                                           m1 * dirs[k, 0], m1 * dirs[k, 1])  # fmt: skip
                    if (b1 - a1) >= -slack[n]:
                        lo1 = m1
                    else:
                        hi1 = m1
                hi[n, k] = hi1
            continue
        # every direction's bisection at once (each the same steps as alone)
        for k in range(nd):
            lo_[k] = 0.0
            hi_[k] = reach
        for _ in range(iters):
            for k in range(nd):
                mid[k] = 0.5 * (lo_[k] + hi_[k])
                gx[k] = mid[k] * dirs[k, 0]
                gy[k] = mid[k] * dirs[k, 1]
            _affine_points(lists, n, gx, gy, nd, a, b)
            for k in range(nd):
                if (b[k] - a[k]) >= -slack[n]:
                    lo_[k] = mid[k]
                else:
                    hi_[k] = mid[k]
        for k in range(nd):
            hi[n, k] = hi_[k]


# long: the nearest sample, its distance and its tangent are one pass over a cell's samples
@_jit
def linearise_kernel(pts, lit, pad, c, e1, e2, s, d, t):
    """_Eye.linearise on the live slots (``pad`` False) of pts (N, K, P, 3) about the unit
    centres c (N, 3) with frames e1, e2 (N, 3): d (N, K) the distance to the nearest
    boundary sample (lit cells: less the sample gap for spacing s, as
    limit3d_eye._sample_gap), t (N, K, 2) the unit tangent towards it in (e1, e2)
    (0 where the sample is the centre itself). Padding slots get d = 0 and t = 0."""
    q = 0.25 * s * s
    for n in range(pts.shape[0]):
        c0, c1, c2 = c[n, 0], c[n, 1], c[n, 2]
        for k in range(pts.shape[1]):
            if pad[n, k]:
                d[n, k] = 0.0
                t[n, k, 0] = 0.0
                t[n, k, 1] = 0.0
                continue
            best = 0
            bd = -np.inf
            for p in range(pts.shape[2]):
                v = pts[n, k, p, 0] * c0 + pts[n, k, p, 1] * c1 + pts[n, k, p, 2] * c2
                if v > bd:
                    bd = v
                    best = p
            px, py, pz = pts[n, k, best, 0], pts[n, k, best, 1], pts[n, k, best, 2]
            cp = px * c0 + py * c1 + pz * c2
            tx, ty, tz = px - cp * c0, py - cp * c1, pz - cp * c2
            tn = math.sqrt(tx * tx + ty * ty + tz * tz)
            dd = math.atan2(tn, cp)
            if lit[n, k]:
                lo = math.sqrt(max(dd * dd - q, 0.0))
                dd = dd - 1.5 * (math.sqrt(lo * lo + q) - lo)
            d[n, k] = dd
            if tn > 0.0:
                t[n, k, 0] = (tx * e1[n, 0] + ty * e1[n, 1] + tz * e1[n, 2]) / tn
                t[n, k, 1] = (tx * e2[n, 0] + ty * e2[n, 1] + tz * e2[n, 2]) / tn
            else:
                t[n, k, 0] = 0.0
                t[n, k, 1] = 0.0


@_jit
def affine_kernel(d, t, lit, pad, a_lit, t_lit, a_unl, t_unl, l_a, l_t, nl, u_a, u_t, nu):
    """_Eye._affine: the affine forms of the model from d (N, K), t (N, K, 2): a_lit,
    t_lit (lit live cells: d and t; else -inf and 0), a_unl, t_unl (unlit live cells: d d
    and 2 d t; else +inf and 0), and the same forms of each kind alone, in slot order
    (l_a, l_t, nl for the lit cells, u_a, u_t, nu for the unlit ones; beyond a row's
    count the slots are left as they were). The same operations as numpy's, elementwise:
    the reference's bits."""
    for n in range(d.shape[0]):
        il = 0
        iu = 0
        for k in range(d.shape[1]):
            dk = d[n, k]
            live = not pad[n, k]
            if live and lit[n, k]:
                a_lit[n, k] = dk
                t_lit[n, k, 0] = t[n, k, 0]
                t_lit[n, k, 1] = t[n, k, 1]
                l_a[n, il] = dk
                l_t[n, il, 0] = t[n, k, 0]
                l_t[n, il, 1] = t[n, k, 1]
                il += 1
            else:
                a_lit[n, k] = -np.inf
                t_lit[n, k, 0] = 0.0
                t_lit[n, k, 1] = 0.0
            if live and not lit[n, k]:
                a_unl[n, k] = dk * dk
                t_unl[n, k, 0] = 2.0 * dk * t[n, k, 0]
                t_unl[n, k, 1] = 2.0 * dk * t[n, k, 1]
                u_a[n, iu] = a_unl[n, k]
                u_t[n, iu, 0] = t_unl[n, k, 0]
                u_t[n, iu, 1] = t_unl[n, k, 1]
                iu += 1
            else:
                a_unl[n, k] = np.inf
                t_unl[n, k, 0] = 0.0
                t_unl[n, k, 1] = 0.0
        nl[n] = il
        nu[n] = iu


@_jit
def affine_forms_kernel(d, t, lit, pad):
    """_Eye._affine with its arrays made here: (a_lit, t_lit, a_unl, t_unl, lists) of
    :func:`affine_kernel`, the lists as wide as the most live lit (unlit) cells of a row
    (at least 1) and zero beyond each row's count."""
    n, k = d.shape
    kl = 1
    ku = 1
    for i in range(n):
        cl = 0
        cu = 0
        for j in range(k):
            if not pad[i, j]:
                if lit[i, j]:
                    cl += 1
                else:
                    cu += 1
        kl = max(kl, cl)
        ku = max(ku, cu)
    a_lit, a_unl = np.empty((n, k)), np.empty((n, k))
    t_lit, t_unl = np.empty((n, k, 2)), np.empty((n, k, 2))
    lists = (np.zeros((n, kl)), np.zeros((n, kl, 2)), np.zeros(n, np.int64),
             np.zeros((n, ku)), np.zeros((n, ku, 2)), np.zeros(n, np.int64))  # fmt: skip
    affine_kernel(d, t, lit, pad, a_lit, t_lit, a_unl, t_unl, *lists)
    return a_lit, t_lit, a_unl, t_unl, lists


@_jit
def _gap(s, d):
    """limit3d_eye._sample_gap for one distance: the same operations (NaN as numpy's)."""
    d_lo = math.sqrt(_max(d * d - 0.25 * s * s, 0.0))
    return 1.5 * (math.sqrt(d_lo * d_lo + 0.25 * s * s) - d_lo)


@_jit
def candidates_kernel(lit, rows, near, far, s, reach, nkeys, keep):
    """limit3d_eye._Eye._candidates' verdicts from the cells' bounds (``near``, ``far``;
    the keys ``rows``, sorted or not, of ``nkeys``): L and U (lit cells less the sample
    gap for spacing s), each key's largest lit L and smallest unlit U (numpy's maximum and
    minimum: NaN wins), and keep = U >= max L - m (lit) or L <= min U + m (unlit), m = 2.2
    reach[key] + 1e-9: numpy's operations, so the same verdicts."""
    t = rows.size
    lo, hi = np.empty(t), np.empty(t)
    lo_lit, hi_unl = np.full(nkeys, -np.inf), np.full(nkeys, np.inf)
    for k in range(t):
        if lit[k]:
            lo[k] = far[k] - _gap(s, far[k])
            hi[k] = near[k] - _gap(s, near[k])
            lo_lit[rows[k]] = _max(lo_lit[rows[k]], lo[k])
        else:
            lo[k], hi[k] = far[k], near[k]
            hi_unl[rows[k]] = _min(hi_unl[rows[k]], hi[k])
    for k in range(t):
        m = 2.2 * reach[rows[k]] + 1e-9
        keep[k] = hi[k] >= lo_lit[rows[k]] - m if lit[k] else lo[k] <= hi_unl[rows[k]] + m


@_jit
def boundaries_kernel(nside, pix, ring, first, rows, slot, dx, dy, jrll, jpll, out):
    """healpix.boundaries of the RING cells pix (T,) (in the rings ``ring`` (T,), whose
    first pixels are first[ring]) at the face offsets dx, dy (P,), written to
    out[rows[i], slot[i]] (out (N, K, P, 3)): healpix.pix2xyf (integers: the same) and
    healpix.xyf2vec's formulas point by point (``math``'s sin and cos, which may differ
    from numpy's in the last bit)."""
    n = float(nside)
    for i in range(pix.size):
        ix, iy, f = _pix2xyf(nside, pix[i], ring[i], first[ring[i]])
        for p in range(dx.size):
            fx = (ix + dx[p]) / n
            fy = (iy + dy[p]) / n
            jr = jrll[f] - fx - fy
            if jr < 1:
                nr = jr
                z = 1.0 - jr * jr / 3.0
            elif jr > 3:
                nr = 4.0 - jr
                z = (4.0 - jr) ** 2 / 3.0 - 1.0
            else:
                nr = 1.0
                z = (2.0 - jr) * (2.0 / 3.0)
            if jr < 1 or jr > 3:
                sth = nr * math.sqrt(max(2.0 - nr * nr / 3.0, 0.0) / 3.0)
            else:
                sth = math.sqrt(1.0 - z * z)
            phi = 0.0
            if nr > 0:
                phi = (0.25 * math.pi) * (jpll[f] * nr + fx - fy) / nr
            o = out[rows[i], slot[i], p]
            o[0] = sth * math.cos(phi)
            o[1] = sth * math.sin(phi)
            o[2] = z


@_jit
def compact_kernel(keep, pts, lit, d, t, o_pts, o_lit, o_pad, o_d, o_t):
    """_Eye.prune's gather: per row, the slots ``keep`` (N, K) first, then the others, each
    in slot order (numpy's stable argsort of ~keep), the first KM = o_d.shape[1] of them
    copied from pts, lit, d, t to o_pts (N, KM, P, 3), o_lit, o_d, o_t; o_pad = not kept."""
    km = o_d.shape[1]
    for n in range(keep.shape[0]):
        j = 0
        for phase in range(2):
            for k in range(keep.shape[1]):
                if j >= km:
                    break
                if keep[n, k] != (phase == 0):
                    continue
                o_pts[n, j] = pts[n, k]
                o_lit[n, j] = lit[n, k]
                o_pad[n, j] = phase == 1
                o_d[n, j] = d[n, k]
                o_t[n, j, 0] = t[n, k, 0]
                o_t[n, j, 1] = t[n, k, 1]
                j += 1


#: the box of box_lists_kernel widened by this relative and absolute amount (rad) beyond the
#: rounding of the points evaluated in it, and its domination margin over the forms' size
BOX_REL, BOX_ABS, BOX_TOL = 1e-9, 1e-12, 1e-12


@_jit
def _undominated(a, t, cnt, n, e0, e1, sgn, oa, ot):
    """The forms 0 .. cnt - 1 of row n (a (N, K), t (N, K, 2)) that no other form
    dominates on the box |dx| <= e0, |dy| <= e1 (sgn 1: for the maximum, the others
    below another by more than the margin; -1: for the minimum, above), copied in order
    to oa, ot; returns their number (box_lists_kernel)."""
    m = 0
    for i in range(cnt):
        ai, ti0, ti1 = a[n, i], t[n, i, 0], t[n, i, 1]
        mi = abs(ai) + abs(ti0) * e0 + abs(ti1) * e1
        dom = False
        for j in range(cnt):
            if j == i:
                continue
            aj, tj0, tj1 = a[n, j], t[n, j, 0], t[n, j, 1]
            spread = abs(tj0 - ti0) * e0 + abs(tj1 - ti1) * e1
            mj = abs(aj) + abs(tj0) * e0 + abs(tj1) * e1
            if sgn * (aj - ai) - spread > BOX_TOL * (1.0 + mi + mj):
                dom = True
                break
        if not dom:
            oa[n, m] = ai
            ot[n, m, 0] = ti0
            ot[n, m, 1] = ti1
            m += 1
    return m


@_jit
def box_lists_kernel(lists, ext, out):
    """limit3d_eye._Eye.box_lists: of the model's packed forms ``lists`` (l_a, l_t, nl,
    u_a, u_t, nu: _Eye._affine), per key n those not dominated on its box |delta_k| <=
    ext[n, k] (widened by BOX_REL, BOX_ABS), in slot order, into ``out`` (the same six
    arrays' shapes; slots beyond a row's count left as they were). A lit form i is
    dominated when another j has a_j - a_i - sum_k |t_jk - t_ik| e_k > BOX_TOL (1 + m_i +
    m_j) (m: |a| + sum_k |t_k| e_k), an unlit one when a_i - a_j - ... does: then form j
    is above (below) form i by more than that margin everywhere on the box, and far more
    than both values' rounding (below 4 2^-53 m each), so the computed maximum (minimum) of
    the forms at any point of the box is never form i's alone: the kept forms give
    _affine_lists' values there bit for bit (the proof: docs/kernels.md)."""
    l_a, l_t, nl, u_a, u_t, nu = lists
    o_la, o_lt, o_nl, o_ua, o_ut, o_nu = out
    for n in range(nl.size):
        e0 = ext[n, 0] * (1.0 + BOX_REL) + BOX_ABS
        e1 = ext[n, 1] * (1.0 + BOX_REL) + BOX_ABS
        o_nl[n] = _undominated(l_a, l_t, nl[n], n, e0, e1, 1.0, o_la, o_lt)
        o_nu[n] = _undominated(u_a, u_t, nu[n], n, e0, e1, -1.0, o_ua, o_ut)


def warm() -> None:
    """Compile (or load from the cache) the kernels for their one signature each."""
    pts = np.ones((1, 1, 2, 3))
    b = np.zeros((1, 1), np.bool_)
    c = np.ones((1, 3))
    d, t = np.empty((1, 1)), np.empty((1, 1, 2))
    linearise_kernel(pts, b, b.copy(), c, c, c, 0.01, d, t)
    n1 = np.zeros(1, np.int64)
    f12 = np.zeros(12, np.int64)
    boundaries_kernel(2, n1, n1 + 1, np.zeros(8, np.int64), n1, n1, np.zeros(2), np.zeros(2), f12,
                      f12, pts)  # fmt: skip
    compact_kernel(b, pts, b, d, t, pts.copy(), b.copy(), b.copy(), d.copy(), t.copy())
    affine_kernel(d, t, b, b.copy(), d.copy(), t.copy(), d.copy(), t.copy(), d.copy(), t.copy(),
                  n1, d.copy(), t.copy(), n1.copy())  # fmt: skip
    affine_forms_kernel(d, t, b, b.copy())
    i1 = np.zeros(1, np.int64)
    candidates_kernel(b[0], i1, np.ones(1), np.ones(1), 0.01, np.ones(1), 1, b[0].copy())
    a2 = np.zeros((1, 1))
    a3 = np.zeros((1, 1, 2))
    dl = np.zeros((1, 1, 2))
    out = np.zeros((1, 1))
    lists = (a2, a3, n1 + 1, a2, a3, n1 + 1)
    affine_bounds_kernel(a2, a3, a2, a3, lists, dl, out, out.copy())
    box_lists_kernel(lists, np.ones((1, 2)), tuple(x.copy() for x in lists))
    extent_kernel(a2, a3, a2, a3, lists, np.ones((1, 2)), 1.0, np.ones(1), 2,
                  np.ones(1, np.bool_), out.copy())  # fmt: skip
