"""The measured proposal's kernels compiled (numba): the region test, H >= -slack at
points (delta, beta) of the box search and the pilot (:meth:`eyeviz.estimators.
limit3d_measured.MeasuredProposal._hb`; both searches key by key in one call:
``box_kernel``), the draws, the direction search and the reference search's step.
The region test and the draws walk both eyes' constraining facets of a key as one
table of its live facets (limit3d_cones.both_columns), the facet that rules a point out
moved to the front (:func:`_walk1`): no branch per facet on its eye or its padding (a
mispredicted branch costs more than a fold: docs/limit3d.md, "bee33e").

It calls :mod:`.limit3d_region`'s functions (``bcentre``, ``_empty``), so its numba
cache is stamped with that module's source as well as its own (:class:`_WithRegionSource`,
as healpix_match does for healpix_lit): an edit of either recompiles it."""

from __future__ import annotations

import hashlib
import math
import os

import numpy as np
from numba.core import caching

from eyeviz.core.kernels import limit3d_region
from eyeviz.core.kernels.limit3d_region import (
    _GOLD,
    _M1,
    _M2,
    _cone_fold,
    _empty,
    _inline_np,
    _jit_np,
    _max,
    _min,
    bcentre,
    bcentre_at,
    bcentre_inline,
    measured_prior,
)

__all__ = ["box_kernel", "direction_kernel", "locate_kernel", "mixture_draws_kernel"]
__all__ += ["region_kernel", "search_kernel", "warm"]


class _WithRegionSource(caching.InTreeCacheLocator):
    """numba's in-tree cache for this module's kernels, its source stamp that of this file
    and of limit3d_region.py together (numba checks only the caller's file)."""

    @classmethod
    def from_function(cls, py_func, py_file):
        if os.path.abspath(py_file) != os.path.abspath(__file__):
            return None
        return super().from_function(py_func, py_file)

    def get_source_stamp(self):
        digest = hashlib.sha256()
        for path in (self._py_file, limit3d_region.__file__):
            with open(path, "rb") as f:
                digest.update(f.read())
        return digest.hexdigest()


_LOCATORS = caching.CacheImpl._locator_classes
if _WithRegionSource not in _LOCATORS:
    _LOCATORS.insert(0, _WithRegionSource)


@_inline_np
def _fold_at(vx, vy, vz, a0, a1, a2, c, sn, lt, lo, hi):
    """limit3d_region._cone_fold of one facet given by its values (v = c - p_k the centre
    from its lens, unit axis a, cos and sin of its half angle, lit), the lens distance |v|
    taken only where it is read (a lit facet's lens, an unlit cone's apex): the same
    values. Scalars only: an array passed even to an inlined function counts an atomic
    reference on entry and exit, per facet more than the fold's arithmetic
    (docs/limit3d.md, "bee33h")."""
    s = vx * a0 + vy * a1 + vz * a2
    wx, wy, wz = vy * a2 - vz * a1, vz * a0 - vx * a2, vx * a1 - vy * a0
    q = math.sqrt(wx * wx + wy * wy + wz * wz)
    m = q * c - s * sn
    if m <= 0.0:
        d = 0.0
    elif s * c + q * sn > 0.0:
        d = m
    else:
        d = math.sqrt(vx * vx + vy * vy + vz * vz)
    if lt:
        return _max(lo, d), _min(hi, math.sqrt(vx * vx + vy * vy + vz * vz))
    return lo, _min(hi, d)


@_inline_np
def _fold1(pos, ax, ch, sh, lit, n, k, cx, cy, cz, lo, hi):
    """:func:`_fold_at` of facet k of key n's table."""
    return _fold_at(cx - pos[n, k, 0], cy - pos[n, k, 1], cz - pos[n, k, 2], ax[n, k, 0],
                    ax[n, k, 1], ax[n, k, 2], ch[n, k], sh[n, k], lit[n, k], lo, hi)  # fmt: skip


@_inline_np
def _walk1(pos, ax, ch, sh, lit, order, nl, n, cx, cy, cz, lo_, hi_):
    """One draw's g interval (lo_, hi_ coming in as the prior's bounds) over key n's nl
    live facets of both eyes' table (limit3d_cones.both_columns), the early exit: the facets are
    folded in one at a time in the key's order ``order[n]``, stopping at the first after
    which the interval is empty (lo only grows and hi only shrinks, and
    limit3d_region._empty is monotone, so a partial interval that is empty gives the full
    one's verdict); the facet that stops a draw is moved to the front, so the facets that
    rule most draws out are tried first. Returns (stopped, lo, hi)."""
    if _empty(lo_, hi_):
        return True, lo_, hi_
    for p in range(nl):
        k = order[n, p]
        lo_, hi_ = _fold1(pos, ax, ch, sh, lit, n, k, cx, cy, cz, lo_, hi_)
        if _empty(lo_, hi_):
            for j in range(p, 0, -1):
                order[n, j] = order[n, j - 1]
            order[n, 0] = k
            return True, lo_, hi_
    return False, lo_, hi_


@_jit_np
def _walk_slack(pos, ax, ch, sh, lit, order, nl, n, cx, cy, cz, lo_, hi_, slack):
    """:func:`_walk1` with the region test's stop, H = hi - lo < -slack (or NaN): the facet
    that stops a point moved to the front. Returns (lo, hi): the whole walk's where it
    does not stop, else the partial ones (then H < -slack all the same: lo only grows, hi
    only shrinks)."""
    if not (hi_ - lo_ >= -slack):
        return lo_, hi_
    for p in range(nl):
        k = order[n, p]
        lo_, hi_ = _fold1(pos, ax, ch, sh, lit, n, k, cx, cy, cz, lo_, hi_)
        if not (hi_ - lo_ >= -slack):
            for j in range(p, 0, -1):
                order[n, j] = order[n, j - 1]
            order[n, 0] = k
            return lo_, hi_
    return lo_, hi_


@_jit_np
def region_kernel(x, u0, e1, e2, fa, bhat, blen, origin, s_half, g_max, slack,
                  pos, ax, ch, sh, lit, nls, h):  # fmt: skip
    """MeasuredProposal._hb: H (N, G) at the points x (N, G, 3) = (delta_1, delta_2, beta)
    of each key: the centre (``bcentre``; -inf where the rays do not meet in front), then
    g_hi - g_lo over the prior's g range and both eyes' constraining facets, the walk
    stopped once H < -slack (H then some value below -slack)."""
    order = np.empty((x.shape[0], pos.shape[1]), np.int64)
    for n in range(x.shape[0]):
        for k in range(order.shape[1]):
            order[n, k] = k
        for g in range(x.shape[1]):
            cx, cy, cz, rho, _ = bcentre(u0[n], e1[n], e2[n], x[n, g, 0], x[n, g, 1],
                                         x[n, g, 2], fa, bhat, blen)  # fmt: skip
            if not math.isfinite(rho):
                h[n, g] = -np.inf
                continue
            qx, qy, qz = cx - origin[0], cy - origin[1], cz - origin[2]
            rr = math.sqrt(qx * qx + qy * qy + qz * qz)
            lo_, hi_ = _walk_slack(pos, ax, ch, sh, lit, order, nls[n], n, cx, cy, cz,
                                   rr * s_half, min(rr, g_max), slack)  # fmt: skip
            hv = hi_ - lo_
            h[n, g] = hv if math.isfinite(hv) else -np.inf


# long: the bisection's steps and the pilot's rounds as batches of points whose region
# test is written out with scalars (a helper taking arrays counts atomic references per call)
@_jit_np
def box_kernel(u0, e1, e2, fa, bhat, blen, origin, s_half, g_max, slack, pos, ax, ch, sh,
               lit, nls, beta0, reach, widen, floor, dirs, iters, up, rounds, box_lo, box_hi,
               t_lo, t_hi, t_n):  # fmt: skip
    """limit3d_measured.MeasuredProposal._around's box search and its ``_pilot``, key by
    key in one call (each key's search reads its own points alone): the bisection of H >=
    -slack along ``dirs`` (26 unit directions in (delta_1, delta_2, beta) from (0, 0,
    beta0[n]), ``iters`` steps from [0, reach]), the boundary points' box widened
    ``widen`` times (at least ``floor`` about the centre); then up to ``rounds`` pilot
    rounds of the points lo + (hi - lo) up[n, j] (up (N, J, 3)): the box widened by half
    its span on each face within a tenth of the span of which a feasible point lies,
    until no face is; t_lo, t_hi, t_n the last round's feasible points' box and number.
    The same arithmetic as the numpy loops there, so the same boxes bit for bit."""
    order = np.empty((u0.shape[0], pos.shape[1]), np.int64)
    nd, nu = dirs.shape[0], up.shape[1]
    lo = np.empty(nd)
    hi = np.empty(nd)
    pts = np.empty((max(nd, nu), 3))
    ok = np.empty(max(nd, nu), np.bool_)
    f0, f1, f2 = fa[0], fa[1], fa[2]
    h0, h1, h2 = bhat[0], bhat[1], bhat[2]
    o0, o1, o2 = origin[0], origin[1], origin[2]
    for n in range(u0.shape[0]):
        for k in range(order.shape[1]):
            order[n, k] = k
        nl = nls[n]
        a00, a01, a02 = u0[n, 0], u0[n, 1], u0[n, 2]
        e10, e11, e12 = e1[n, 0], e1[n, 1], e1[n, 2]
        e20, e21, e22 = e2[n, 0], e2[n, 1], e2[n, 2]
        c = (0.0, 0.0, beta0[n])
        for q in range(nd):
            lo[q] = 0.0
            hi[q] = reach
        # the bisection's steps, the box, then the pilot's rounds: each step or round a
        # batch of points, their verdicts taken in order in one loop below
        l0 = l1 = l2 = s0 = s1 = s2 = 0.0
        for stage in range(iters + 1 + rounds):
            if stage == iters:
                for j in range(3):
                    pmin, pmax = np.inf, -np.inf
                    for q in range(nd):
                        v = hi[q] * dirs[q, j]
                        pmin = min(pmin, v)
                        pmax = max(pmax, v)
                    box_lo[n, j] = min(c[j] + min(pmin, 0.0) * widen, c[j] - floor)
                    box_hi[n, j] = max(c[j] + max(pmax, 0.0) * widen, c[j] + floor)
                continue
            if stage < iters:
                npt = nd
                for q in range(nd):
                    mid = 0.5 * (lo[q] + hi[q])
                    pts[q, 0] = c[0] + mid * dirs[q, 0]
                    pts[q, 1] = c[1] + mid * dirs[q, 1]
                    pts[q, 2] = c[2] + mid * dirs[q, 2]
            else:
                npt = nu
                l0, l1, l2 = box_lo[n, 0], box_lo[n, 1], box_lo[n, 2]
                s0, s1, s2 = box_hi[n, 0] - l0, box_hi[n, 1] - l1, box_hi[n, 2] - l2
                for q in range(nu):
                    pts[q, 0] = l0 + s0 * up[n, q, 0]
                    pts[q, 1] = l1 + s1 * up[n, q, 1]
                    pts[q, 2] = l2 + s2 * up[n, q, 2]
            # region_kernel's verdict H >= -slack at each point, its walk written out with
            # scalars (an array passed to a helper, even an inlined one, counts an atomic
            # reference a point or a facet: docs/limit3d.md, "bee33h"); the facet that
            # stops a point moved to the front of order[n] (max and min are exact, so the
            # verdict is the same in any order)
            for q in range(npt):
                ok[q] = False
                cx, cy, cz, rho, _ = bcentre_at(
                    a00, a01, a02, e10, e11, e12, e20, e21, e22, pts[q, 0], pts[q, 1],
                    pts[q, 2], f0, f1, f2, h0, h1, h2, blen,
                )  # fmt: skip
                if not math.isfinite(rho):
                    continue
                qx, qy, qz = cx - o0, cy - o1, cz - o2
                rr = math.sqrt(qx * qx + qy * qy + qz * qz)
                lo_, hi_ = rr * s_half, min(rr, g_max)
                if hi_ - lo_ >= -slack:
                    for p in range(nl):
                        k = order[n, p]
                        lo_, hi_ = _fold_at(cx - pos[n, k, 0], cy - pos[n, k, 1],
                                            cz - pos[n, k, 2], ax[n, k, 0], ax[n, k, 1],
                                            ax[n, k, 2], ch[n, k], sh[n, k], lit[n, k], lo_,
                                            hi_)  # fmt: skip
                        if not (hi_ - lo_ >= -slack):
                            for j in range(p, 0, -1):
                                order[n, j] = order[n, j - 1]
                            order[n, 0] = k
                            break
                hv = hi_ - lo_
                ok[q] = math.isfinite(hv) and hv >= -slack
            if stage < iters:
                for q in range(nd):
                    mid = 0.5 * (lo[q] + hi[q])
                    if ok[q]:
                        lo[q] = mid
                    else:
                        hi[q] = mid
                continue
            b0, b1, b2 = 0.1 * s0, 0.1 * s1, 0.1 * s2
            a0, a1, a2 = l0 + b0, l1 + b1, l2 + b2
            z0, z1, z2 = box_hi[n, 0] - b0, box_hi[n, 1] - b1, box_hi[n, 2] - b2
            m0 = m1 = m2 = np.inf
            x0 = x1 = x2 = -np.inf
            nlo0 = nlo1 = nlo2 = nhi0 = nhi1 = nhi2 = False
            cnt = 0
            for q in range(nu):
                if not ok[q]:
                    continue
                p0, p1, p2 = pts[q, 0], pts[q, 1], pts[q, 2]
                cnt += 1
                m0, m1, m2 = min(m0, p0), min(m1, p1), min(m2, p2)
                x0, x1, x2 = max(x0, p0), max(x1, p1), max(x2, p2)
                nlo0, nlo1, nlo2 = nlo0 or p0 < a0, nlo1 or p1 < a1, nlo2 or p2 < a2
                nhi0, nhi1, nhi2 = nhi0 or p0 > z0, nhi1 or p1 > z1, nhi2 or p2 > z2
            t_lo[n, 0], t_lo[n, 1], t_lo[n, 2] = m0, m1, m2
            t_hi[n, 0], t_hi[n, 1], t_hi[n, 2] = x0, x1, x2
            t_n[n] = cnt
            if not (nlo0 or nlo1 or nlo2 or nhi0 or nhi1 or nhi2):
                break
            if nlo0:
                box_lo[n, 0] = l0 - 0.5 * s0
            if nlo1:
                box_lo[n, 1] = l1 - 0.5 * s1
            if nlo2:
                box_lo[n, 2] = l2 - 0.5 * s2
            if nhi0:
                box_hi[n, 0] = box_hi[n, 0] + 0.5 * s0
            if nhi1:
                box_hi[n, 1] = box_hi[n, 1] + 0.5 * s1
            if nhi2:
                box_hi[n, 2] = box_hi[n, 2] + 0.5 * s2


@_inline_np
def _component(counts, n, j):
    """The mixture component of a batch's draw j of key n: the first counts[n, 0] draws
    come from component 0, the next counts[n, 1] from 1, ..., the rest from the last."""
    c, acc = 0, counts[n, 0]
    while j >= acc and c < counts.shape[1] - 1:
        c += 1
        acc += counts[n, c]
    return c


@_inline_np
def _density(boxes, dens, n, d0, d1, beta):
    """The mixture's density in (delta, beta) at a point: the sum of dens[n, c] (share /
    volume) over the components whose box holds it."""
    q = 0.0
    for c in range(boxes.shape[1]):
        if (dens[n, c] > 0.0 and boxes[n, c, 0, 0] <= d0 <= boxes[n, c, 1, 0]
                and boxes[n, c, 0, 1] <= d1 <= boxes[n, c, 1, 1]
                and boxes[n, c, 0, 2] <= beta <= boxes[n, c, 1, 2]):  # fmt: skip
            q += dens[n, c]
    return q


@_inline_np
def _u01(base, s, j):
    """limit3d_proposal._uniforms' uniform of counter j in stream s of a key whose hash
    times _M1 is ``base`` (limit3d_region.uniforms_kernel's hash: the same bits)."""
    z = base + (np.uint64(j) + (np.uint64(s) << np.uint64(32)))
    z = z + _GOLD
    z = (z ^ (z >> np.uint64(30))) * _M1
    z = (z ^ (z >> np.uint64(27))) * _M2
    z = z ^ (z >> np.uint64(31))
    return (np.float64(z >> np.uint64(11)) + 0.5) * 2.0**-53


# long: one draw of limit3d_measured.MeasuredProposal.sample (component, centre, g
# interval, g, weight) is one loop body; split, it would pass a dozen scalars back and forth
@_jit_np
def mixture_draws_kernel(keys, streams, nst, u, boxes, counts, dens, samples, u0, e1, e2, fa,
                         bhat, blen, origin, s_half, g_max, r_min, r_max, el_max, multi, rows,
                         pos, ax, ch, sh, lit, nls, at, x, y, z, g, r, az, el, w):  # fmt: skip
    """limit3d_measured.MeasuredProposal.sample up to the exact check, draw by draw, from
    a deterministic mixture of boxes in (delta, beta) (boxes (N, C, 2, 3): lo, hi): of
    each batch of ``samples`` draws, counts[n, c] from box c in turn (:func:`_component`),
    (delta, beta) and g from four uniforms, the centre, its g interval (the walk of
    :func:`_walk1`, stopping once it is empty; each component keeps its own facet order),
    the prior and the weight prior x Jacobian x the interval's length / the mixture's
    density (:func:`_density`, dens (N, C) = share / volume). Only the keys ``rows`` (N,)
    get draws.

    The uniforms: u (N, M, 4) where given (u.shape[0] == N), else those of
    limit3d_proposal._batch_uniforms of the key hashes ``keys`` (N,) and key n's streams
    ``streams[n, :nst[n]]`` (``samples`` draws each, side by side; M = samples x
    streams.shape[1]), each drawn when first read (the same bits; a draw given up before
    its g never draws its last). The draws weighted above 0 only, in draw order (key by
    key): at (their flat index n M + m), x, y, z, g, r, az, el, w, the first
    returned-count entries of each (arrays of N M or more)."""
    nc = boxes.shape[1]
    given = u.shape[0] == rows.shape[0]
    mm = u.shape[1] if given else samples * streams.shape[1]
    order = np.empty((nc, rows.shape[0], pos.shape[1]), np.int64)
    cnt = 0
    for n in range(rows.shape[0]):
        if not rows[n]:
            continue
        nl = nls[n]
        base = keys[n] * _M1
        for c in range(nc):
            for k in range(order.shape[2]):
                order[c, n, k] = k
        for m in range(mm if given else samples * nst[n]):
            jm = m % samples
            sm = streams[n, m // samples] if not given else 0
            c = _component(counts, n, jm)
            lo_, hi_ = boxes[n, c, 0], boxes[n, c, 1]
            if given:
                u0_, u1_, u2_ = u[n, m, 0], u[n, m, 1], u[n, m, 2]
            else:
                u0_, u1_, u2_ = (
                    _u01(base, sm, 4 * jm),
                    _u01(base, sm, 4 * jm + 1),
                    _u01(base, sm, 4 * jm + 2),
                )
            d0 = lo_[0] + (hi_[0] - lo_[0]) * u0_
            d1 = lo_[1] + (hi_[1] - lo_[1]) * u1_
            beta = lo_[2] + (hi_[2] - lo_[2]) * u2_
            cx, cy, cz, rho, drho = bcentre_inline(
                u0[n], e1[n], e2[n], d0, d1, beta, fa, bhat, blen
            )
            if not math.isfinite(rho):
                continue
            qx, qy, qz = cx - origin[0], cy - origin[1], cz - origin[2]
            rr = math.sqrt(qx * qx + qy * qy + qz * qz)
            out, g_lo, g_hi = _walk1(pos, ax, ch, sh, lit, order[c], nl, n, cx, cy, cz,
                                     rr * s_half, min(rr, g_max))  # fmt: skip
            if out:
                continue
            pad = 1e-9 * g_hi
            g_lo, g_hi = max(g_lo - pad, 0.0), g_hi + pad
            u3_ = u[n, m, 3] if given else _u01(base, sm, 4 * jm + 3)
            gg = g_lo + (g_hi - g_lo) * u3_
            e = math.asin(min(max(qz / rr, -1.0), 1.0))
            phi = math.atan2(qy, qx)
            dens_p = measured_prior(rr, gg, e, phi, s_half, g_max, r_min, r_max, el_max, multi)
            jac = rho * rho * (1.0 + (d0 * d0 + d1 * d1)) ** -1.5 * drho
            wt = dens_p * jac * ((g_hi - g_lo) / _density(boxes, dens, n, d0, d1, beta))
            if not (math.isfinite(wt) and wt > 0.0):
                continue
            at[cnt] = n * mm + m
            x[cnt], y[cnt], z[cnt], g[cnt] = cx, cy, cz, gg
            r[cnt], az[cnt], el[cnt], w[cnt] = rr, phi, e, wt
            cnt += 1
    return cnt


@_jit_np
def _grid_value(ax, half, lit, pad, order, n, vx, vy, vz, best):
    """G(v) = min over unlit facets of (angle(a_j, v) - alpha_j) - max over lit ones of
    (angle(a_i, v) - alpha_i) of key n at the unit v, the facets in the key's order
    ``order`` (K,); stops once G <= best (G only falls as facets are folded in: such a
    point is not the first maximum), the facet that stopped it moved to the front (max
    and min are exact, so the order changes no value that is not cut)."""
    lo, hi = np.inf, -np.inf
    for p in range(order.shape[0]):
        k = order[p]
        if pad[n, k]:
            continue
        dot = ax[n, k, 0] * vx + ax[n, k, 1] * vy + ax[n, k, 2] * vz
        ang = math.acos(min(max(dot, -1.0), 1.0)) - half[n, k]
        if lit[n, k]:
            hi = max(hi, ang)
        else:
            lo = min(lo, ang)
        if lo - hi <= best:
            for j in range(p, 0, -1):
                order[j] = order[j - 1]
            order[0] = k
            return lo - hi
    return lo - hi


@_jit_np
def direction_kernel(ax, half, lit, pad, c, hw, grid, levels):
    """limit3d_cones._direction's zooming grids, key by key: about each key's c (N, 3)
    (unit; replaced by the result), grid x grid points of half width hw[n] (then / 2.5
    each level) in gnomonic coordinates, the first point of largest G (:func:`_grid_value`,
    early exit) the next centre."""
    order = np.empty(ax.shape[1], np.int64)
    for n in range(c.shape[0]):
        for k in range(order.shape[0]):
            order[k] = k
        cx, cy, cz, h = c[n, 0], c[n, 1], c[n, 2], hw[n]
        for _ in range(levels):
            ex, ey = -cy, cx
            nn = math.sqrt(ex * ex + ey * ey)
            if nn > 1e-12:
                ex, ey, ez = ex / nn, ey / nn, 0.0
            else:
                ex, ey, ez = 1.0, 0.0, 0.0
            fx, fy, fz = cy * ez - cz * ey, cz * ex - cx * ez, cx * ey - cy * ex
            best, bx, by, bz = -np.inf, cx, cy, cz
            for i in range(grid):
                di = ((i + 0.5) / grid * 2 - 1) * h
                for j in range(grid):
                    dj = ((j + 0.5) / grid * 2 - 1) * h
                    vx, vy, vz = (
                        cx + di * ex + dj * fx,
                        cy + di * ey + dj * fy,
                        cz + di * ez + dj * fz,
                    )
                    nv = math.sqrt(vx * vx + vy * vy + vz * vz)
                    vx, vy, vz = vx / nv, vy / nv, vz / nv
                    gv = _grid_value(ax, half, lit, pad, order, n, vx, vy, vz, best)
                    if gv > best or (i == 0 and j == 0):
                        best, bx, by, bz = gv, vx, vy, vz
            cx, cy, cz, h = bx, by, bz, h / 2.5
        c[n, 0], c[n, 1], c[n, 2] = cx, cy, cz


@_jit_np
def locate_kernel(c, r, ww, s_half, g_max, pos_a, ax_a, ch_a, sh_a, lit_a, pad_a,
                  pos_b, ax_b, ch_b, sh_b, lit_b, pad_b, best):  # fmt: skip
    """The reference search's step (limit3d_measured.MeasuredProposal.setup): per key n
    the first grid point g of largest (g_hi - g_lo) x ww[n, g] at the centres c (N, G, 3)
    (r (N, G) their distance from the origin), g_lo and g_hi over the prior's g range and
    both eyes' facets (as MeasuredProposal._h: max and min are exact, so the same values
    in any order); a point is given up once its value falls to the best so far (it only
    falls as facets are folded in, and a product by ww > 0 keeps the order), the facet
    that gave it up moved to the front of the key's order (both eyes' facets: index k <
    K_A A's facet k, else B's facet k - K_A), as the draws' walk (:func:`_locate1`)."""
    order = np.empty(pos_a.shape[1] + pos_b.shape[1], np.int64)
    for n in range(c.shape[0]):
        best[n] = _locate1(c[n], r[n], ww[n], n, s_half, g_max, pos_a, ax_a, ch_a, sh_a, lit_a,
                           pad_a, pos_b, ax_b, ch_b, sh_b, lit_b, pad_b, order)  # fmt: skip


@_jit_np
def _locate1(c, r, ww, n, s_half, g_max, pos_a, ax_a, ch_a, sh_a, lit_a, pad_a,
             pos_b, ax_b, ch_b, sh_b, lit_b, pad_b, order):  # fmt: skip
    """locate_kernel for key n, its points c (G, 3), r and ww (G,); ``order`` its facets'
    order, reset here."""
    ka = pos_a.shape[1]
    for k in range(order.shape[0]):
        order[k] = k
    top, arg = -np.inf, 0
    for g in range(c.shape[0]):
        cx, cy, cz, w = c[g, 0], c[g, 1], c[g, 2], ww[g]
        lo, hi = r[g] * s_half, min(r[g], g_max)
        out = False
        for p in range(order.shape[0]):
            k = order[p]
            if k < ka:
                if pad_a[n, k]:
                    continue
                lo, hi = _cone_fold(pos_a, ax_a, ch_a, sh_a, lit_a, n, k, cx, cy, cz, lo, hi)
            else:
                if pad_b[n, k - ka]:
                    continue
                lo, hi = _cone_fold(pos_b, ax_b, ch_b, sh_b, lit_b, n, k - ka, cx, cy, cz,
                                    lo, hi)  # fmt: skip
            if g > 0 and (hi - lo) * w <= top:
                for j in range(p, 0, -1):
                    order[j] = order[j - 1]
                order[0] = k
                out = True
                break
        if not out and (g == 0 or (hi - lo) * w > top):
            top, arg = (hi - lo) * w, g
    return arg


@_jit_np
def search_kernel(u0, e1, e2, fa, origin, wc, wh, half, levels, g3, w_min, w_max, s_half,
                  g_max, pos_a, ax_a, ch_a, sh_a, lit_a, pad_a, pos_b, ax_b, ch_b, sh_b,
                  lit_b, pad_b, dc, wr):  # fmt: skip
    """limit3d_measured.MeasuredProposal._search's zooming grids key by key in one call:
    per level the points (delta, w) = (dc, wc) + g3 x (half, wh) (w clipped to [w_min,
    w_max]), their centres fa + v / w (v the unit direction u0 + delta_1 e1 + delta_2 e2,
    normalised), :func:`_locate1`'s point, then half and wh / 2.5. dc (N, 2) and wr (N,)
    the last point. The same arithmetic as the numpy loop (its norms' sums in the same
    order), so the same points bit for bit."""
    ng = g3.shape[0]
    c = np.empty((ng, 3))
    r = np.empty(ng)
    ww = np.empty(ng)
    d0 = np.empty(ng)
    d1 = np.empty(ng)
    order = np.empty(pos_a.shape[1] + pos_b.shape[1], np.int64)
    for n in range(u0.shape[0]):
        c0, c1, wcn, whn, hf = 0.0, 0.0, wc[n], wh[n], half
        for _ in range(levels):
            for g in range(ng):
                d0[g] = c0 + g3[g, 0] * hf
                d1[g] = c1 + g3[g, 1] * hf
                ww[g] = min(max(wcn + g3[g, 2] * whn, w_min), w_max)
                vx = u0[n, 0] + d0[g] * e1[n, 0] + d1[g] * e2[n, 0]
                vy = u0[n, 1] + d0[g] * e1[n, 1] + d1[g] * e2[n, 1]
                vz = u0[n, 2] + d0[g] * e1[n, 2] + d1[g] * e2[n, 2]
                nv = math.sqrt(vx * vx + vy * vy + vz * vz)
                c[g, 0] = fa[0] + vx / nv / ww[g]
                c[g, 1] = fa[1] + vy / nv / ww[g]
                c[g, 2] = fa[2] + vz / nv / ww[g]
                qx, qy, qz = c[g, 0] - origin[0], c[g, 1] - origin[1], c[g, 2] - origin[2]
                r[g] = math.sqrt(qx * qx + qy * qy + qz * qz)
            b = _locate1(c, r, ww, n, s_half, g_max, pos_a, ax_a, ch_a, sh_a, lit_a, pad_a,
                         pos_b, ax_b, ch_b, sh_b, lit_b, pad_b, order)  # fmt: skip
            c0, c1, wcn = d0[b], d1[b], ww[b]
            hf, whn = hf / 2.5, whn / 2.5
        dc[n, 0], dc[n, 1], wr[n] = c0, c1, wcn


def warm() -> None:
    """Compile (or load from the cache) the kernels for their one signature each."""
    a2 = np.zeros((1, 1))
    p3 = np.ones((1, 1, 3))
    b = np.ones((1, 1), np.bool_)
    cs = (p3, p3, a2 + 0.9, a2 + 0.1, b, ~b)
    c = np.ones((1, 3))
    v3 = np.ones(3)
    both = (p3, p3, a2 + 0.9, a2 + 0.1, b, np.ones(1, np.int64))
    region_kernel(p3, c, c, c, v3, v3, 1.0, v3, 0.1, 1.0, 1e-7, *both, a2.copy())
    box_kernel(c, c, c, v3, v3, 1.0, v3, 0.1, 1.0, 1e-7, *both, np.ones(1), 0.5, 2.0, 1e-9,
               c, 2, p3 * 0.5, 2, c.copy(), c.copy(), c.copy(), c.copy(),
               np.zeros(1, np.int64))  # fmt: skip
    direction_kernel(p3, a2, b, ~b, np.array([[0.0, 0.0, 1.0]]), np.ones(1), 2, 1)
    locate_kernel(p3, a2 + 1, a2 + 1, 0.1, 1.0, *cs, *cs, np.zeros(1, np.int64))
    search_kernel(c, c, c, v3, v3, np.ones(1), np.ones(1), 0.1, 1, c, 0.5, 2.0, 0.1, 1.0, *cs,
                  *cs, np.zeros((1, 2)), np.ones(1))  # fmt: skip
    u4 = np.full((1, 1, 4), 0.5)
    boxes = np.zeros((1, 2, 2, 3))
    boxes[:, :, 1] = 1.0
    o1 = np.zeros(2)
    mixture_draws_kernel(np.ones(1, np.uint64), np.zeros((1, 1), np.int64),
                         np.ones(1, np.int64), u4, boxes,
                         np.ones((1, 2), np.int64), np.ones((1, 2)), 2, c, c, c, v3, v3, 1.0,
                         v3, 0.1, 1.0, 0.5, 9.0, 1.0, False, b[0].copy(), *both,
                         np.zeros(2, np.int64), o1, o1.copy(), o1.copy(), o1.copy(), o1.copy(),
                         o1.copy(), o1.copy(), o1.copy())  # fmt: skip
