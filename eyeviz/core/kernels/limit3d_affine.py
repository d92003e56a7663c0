"""The HEALPix proposal's set-up compiled (numba): the linearisation of each edge cell's
distance about a key's centre (:meth:`eyeviz.estimators.limit3d_eye._Eye.linearise`,
called at every zoom level of the centre search) and the affine forms of the model built
from it (``_Eye._affine``, bit for bit), and the edge cells' boundary samples
(``healpix.boundaries``, to a few ulps).

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

__all__ = [
    "affine_bounds_kernel",
    "extent_kernel",
    "ray_region_kernel",
    "healpix_draws_kernel",
    "healpix_prior",
    "linearise_kernel",
    "affine_kernel",
    "boundaries_kernel",
    "compact_kernel",
    "warm",
]

_jit = njit(cache=True, nogil=True)
#: the model's evaluation and the ray search, inlined into their callers (numba IR
#: inlining): a call that passes the model's arrays costs a reference count on each,
#: more than the evaluation itself (2-3x the evaluations a second inlined)
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
    if not (math.isfinite(dx) and math.isfinite(dy)):
        return _affine_at(a_lit, t_lit, a_unl, t_unl, n, dx, dy)
    l_a, l_t, nl, u_a, u_t, nu = lists
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


@_jit
def affine_bounds_kernel(a_lit, t_lit, a_unl, t_unl, lists, delta, lo, hi):
    """_Eye.bounds: lo, hi (N, G) at gnomonic offsets delta (N, G, 2)."""
    for n in range(delta.shape[0]):
        for g in range(delta.shape[1]):
            lo[n, g], hi[n, g] = _affine_lists(
                a_lit, t_lit, a_unl, t_unl, lists, n, delta[n, g, 0], delta[n, g, 1]
            )


@_jit
def extent_kernel(a_lit, t_lit, a_unl, t_unl, lists, dirs, reach, slack, iters, hi):
    """limit3d_proposal._extent's bisection: along each direction dirs[k] (K, 2) from each
    key's centre, ``iters`` halvings of [0, reach] keeping the model's G = min_unlit -
    max_lit >= -slack[n] below; hi (N, K) the outer ends (the same arithmetic as numpy's:
    the same bits)."""
    for n in range(hi.shape[0]):
        for k in range(dirs.shape[0]):
            lo_ = 0.0
            hi_ = reach
            for _ in range(iters):
                mid = 0.5 * (lo_ + hi_)
                a, b = _affine_lists(a_lit, t_lit, a_unl, t_unl, lists, n, mid * dirs[k, 0],
                                     mid * dirs[k, 1])  # fmt: skip
                if (b - a) >= -slack[n]:
                    lo_ = mid
                else:
                    hi_ = mid
            hi[n, k] = hi_


@_jit
def _clean(x):
    """numpy's nan_to_num(x, nan=1e3, posinf=1e3, neginf=-1e3)."""
    if x != x:
        return 1e3
    if x == np.inf:
        return 1e3
    if x == -np.inf:
        return -1e3
    return x


@_jit_inline
def _gap_at(a_lit, t_lit, a_unl, t_unl, lists, c, e1, e2, a, n, cax, cay, caz, u):
    """G = min_unlit - max_lit of B's model (key n) seen along A's ray at u."""
    vx = cax + u * a[0]
    vy = cay + u * a[1]
    vz = caz + u * a[2]
    nrm = math.sqrt(vx * vx + vy * vy + vz * vz)
    vx, vy, vz = vx / nrm, vy / nrm, vz / nrm
    cc = vx * c[n, 0] + vy * c[n, 1] + vz * c[n, 2]
    x = vx * e1[n, 0] + vy * e1[n, 1] + vz * e1[n, 2]
    y = vx * e2[n, 0] + vy * e2[n, 1] + vz * e2[n, 2]
    lo, hi = _affine_lists(a_lit, t_lit, a_unl, t_unl, lists, n, _clean(x / cc), _clean(y / cc))
    return hi - lo


@_jit_inline
def _gap_g(a_lit, t_lit, a_unl, t_unl, lists, c, e1, e2, a, n, cax, cay, caz, u, sa_lo, sa_hi,
           slack):  # fmt: skip
    """The g test's gap along A's ray at u, in B's sin-angle: min(sin(hi_B + s), sin_hi_A /
    k) - max(sin(lo_B - s), sin_lo_A / k), k = |c_A + u (A - B)| = rho_B / rho (the
    angles clipped to [0, pi / 2]; sa_lo, sa_hi: A's sin(lo_A - s), sin(hi_A + s)). A
    draw's g interval is not empty iff it is above 0 (the prior's g range aside)."""
    vx = cax + u * a[0]
    vy = cay + u * a[1]
    vz = caz + u * a[2]
    nrm = math.sqrt(vx * vx + vy * vy + vz * vz)
    vx, vy, vz = vx / nrm, vy / nrm, vz / nrm
    cc = vx * c[n, 0] + vy * c[n, 1] + vz * c[n, 2]
    x = vx * e1[n, 0] + vy * e1[n, 1] + vz * e1[n, 2]
    y = vx * e2[n, 0] + vy * e2[n, 1] + vz * e2[n, 2]
    lo, hi = _affine_lists(a_lit, t_lit, a_unl, t_unl, lists, n, _clean(x / cc), _clean(y / cc))
    h2 = 0.5 * math.pi
    sb_lo = math.sin(_clip_nan(lo - slack, 0.0, h2))
    sb_hi = math.sin(_clip_nan(hi + slack, 0.0, h2))
    return _min(sb_hi, sa_hi / nrm) - _max(sb_lo, sa_lo / nrm)


@_jit
def _clip_nan(x, lo, hi):
    """numpy's clip (NaN stays NaN)."""
    if x != x:
        return x
    return min(max(x, lo), hi)


@_jit_inline
def _ray_search(a_lit, t_lit, a_unl, t_unl, lists, c, e1, e2, a, n, cax, cay, caz, lo_, hi_,
                slack, t, rounds, gv, uu, aim=False, sa_lo=0.0, sa_hi=0.0):  # fmt: skip
    """One draw's search of :func:`ray_region_kernel`: (lo, hi) shrunk ``rounds`` times
    on the grid t (gv, uu: work arrays of its size). ``aim``: for the g test's gap
    (:func:`_gap_g`, inside where > 0), not B's region (inside where >= -slack)."""
    grid = t.size
    for _ in range(rounds):
        first = -1
        last = -1
        best = 0
        for j in range(grid):
            uu[j] = lo_ + (hi_ - lo_) * t[j]
            if aim:
                gv[j] = _gap_g(a_lit, t_lit, a_unl, t_unl, lists, c, e1, e2, a, n, cax, cay, caz,
                               uu[j], sa_lo, sa_hi, slack)  # fmt: skip
                inside = gv[j] > 0.0
            else:
                gv[j] = _gap_at(a_lit, t_lit, a_unl, t_unl, lists, c, e1, e2, a, n, cax, cay,
                                caz, uu[j])  # fmt: skip
                inside = gv[j] >= -slack
            if inside:
                if first < 0:
                    first = j
                last = j
            # argmax: the first maximum, the first NaN before any number
            gb = gv[best]
            if gb == gb and (gv[j] != gv[j] or gv[j] > gb):
                best = j
        if first < 0:
            first = best
            last = best
        lo_ = uu[max(first - 1, 0)]
        hi_ = uu[min(last + 1, grid - 1)]
    return lo_, hi_


@_jit
def ray_region_kernel(a_lit, t_lit, a_unl, t_unl, lists, c, e1, e2, a, ca, lo, hi, slack,
                      t, rounds, live):  # fmt: skip
    """_ray_in_region on the draws where ``live`` (N, M): lo, hi (N, M) shrunk in place."""
    gv = np.empty(t.size)
    uu = np.empty(t.size)
    for n in range(ca.shape[0]):
        for m in range(ca.shape[1]):
            if not live[n, m]:
                continue
            lo[n, m], hi[n, m] = _ray_search(a_lit, t_lit, a_unl, t_unl, lists, c, e1, e2, a, n,
                                             ca[n, m, 0], ca[n, m, 1], ca[n, m, 2], lo[n, m],
                                             hi[n, m], slack[n], t, rounds, gv, uu)  # fmt: skip


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
def boundaries_kernel(nside, ix, iy, face, rows, slot, dx, dy, jrll, jpll, out):
    """healpix.boundaries of the cells (ix, iy, face) (T,) at the face offsets dx, dy (P,),
    written to out[rows[i], slot[i]] (out (N, K, P, 3)): healpix.xyf2vec's formulas point
    by point (``math``'s sin and cos, which may differ from numpy's in the last bit)."""
    n = float(nside)
    for i in range(ix.size):
        f = face[i]
        for p in range(dx.size):
            fx = (ix[i] + dx[p]) / n
            fy = (iy[i] + dy[p]) / n
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


_jit_np = njit(cache=True, nogil=True, error_model="numpy")


@_jit_np
def healpix_prior(r, g, el, az, s_half, g_max, r_min, r_max, el_max, psi, multi):
    """limit3d_exact.prior_density of a HEALPix pair for one ball; 0 outside the support."""
    if not (r >= r_min and r <= r_max and g >= r * s_half and g <= g_max and g <= r):
        return 0.0
    if not abs(el) <= el_max:
        return 0.0
    cel = math.cos(el)
    cone = psi + math.asin(min(g / r, 1.0))
    if not cone < math.pi / 2:
        return 0.0
    if multi:
        az0 = math.acos(min(math.cos(cone) / math.cos(el_max), 1.0))
        dens = r * r * cel
    else:
        az0 = math.acos(min(math.cos(cone) / cel, 1.0))
        dens = 1.0
    if not (az >= az0 and az <= math.pi - az0):
        return 0.0
    dens = dens / ((g_max - r * s_half) * (math.pi - 2 * az0) * r * r * cel)
    return dens if math.isfinite(dens) else 0.0


@_jit_np
def _ray_box(c, e1, e2, a, ext0, ext1, cax, cay, caz):
    """limit3d_proposal._ray_in_box for one ray: (lo, hi) of u where B's view of
    A + c_A / u lies in B's box (c, e1, e2: B's centre and frame; a = A - B)."""
    ca_ = c[0] * a[0] + c[1] * a[1] + c[2] * a[2]
    cc = cax * c[0] + cay * c[1] + caz * c[2]
    lo = 0.0
    hi = np.inf
    for j in range(5):
        if j == 0:
            k0, k1 = -cc, -ca_
        else:
            e = e1 if j < 3 else e2
            x = ext0 if j < 3 else ext1
            sgn = 1.0 if j % 2 == 1 else -1.0
            ce = cax * e[0] + cay * e[1] + caz * e[2]
            k1 = sgn * (e[0] * a[0] + e[1] * a[1] + e[2] * a[2]) - x * ca_
            k0 = sgn * ce - x * cc
        root = -k0 / k1
        if k1 > 0:
            hi = _min(hi, root)
        if k1 < 0:
            lo = _max(lo, root)
        if k1 == 0 and k0 > 0:
            lo = np.inf
    return lo, hi


@_jit_np
def _clip(x, lo, hi):
    """numpy's clip (NaN stays NaN)."""
    if x != x:
        return x
    return min(max(x, lo), hi)


# long: one draw of limit3d_healpix.HealpixProposal.sample up to the exact check (A's
# direction, A's model, B's box and region along the ray, g, prior, weight) is one loop
# body; split, it would pass a dozen scalars back and forth
@_jit_np
def healpix_draws_kernel(u, rows, th_lo, th_hi, box, ext, ext_b, slack, fa, ca_, e1a, e2a,
                         fb, cb, e1b, e2b, ab, pa, pb, u_min, u_max, s_half, g_max, r_min,
                         r_max, el_max, psi, multi, t, rounds, n_def, samples,
                         x, y, z, g, r, az, el, w, ca, alpha):  # fmt: skip
    """HealpixProposal.sample's draws before the exact check, one at a time, each given up
    at its first test that fails: (theta, phi) of A's direction from the uniforms u
    (N, M, 4), inside A's box of centres and A's modelled region, u = 1 / rho in B's box
    along the ray (:func:`_ray_box`), then narrowed to where the g test can pass
    (:func:`_ray_search` of :func:`_gap_g`), g where both eyes' modelled radii and the
    prior allow it, the prior and the weight. Of each batch of ``samples`` draws the first
    ``n_def`` take u uniform on B's box along the ray (the defensive share: the narrowed
    interval is a search's bracket, not a proven hull), the others on the narrowed
    interval; every weight divides by the two's mixture density at its u. fa, fb:
    each eye's affine forms (a_lit, t_lit, a_unl, t_unl, lists); ab = A - B; pa, pb the
    eyes' centres. Writes x, y, z, g, r, az, el, w, ca (N, M, 3) and alpha (N, M) where
    the weight is above 0 (w 0 elsewhere, the others then unset); only the keys ``rows``
    (N,) get draws."""
    al, tl, au, tu, la = fa
    bl, sl_, bu, su, lb = fb
    gv = np.empty(t.size)
    uu = np.empty(t.size)
    h2 = 0.5 * math.pi
    lam = n_def / samples
    for n in range(u.shape[0]):
        sn = slack[n]
        dth = th_hi[n] - th_lo[n]
        dph = box[n, 3] - box[n, 2]
        live = rows[n] and dth > 0 and dph > 0
        vol0 = dth * dph
        for m in range(u.shape[1]):
            w[n, m] = 0.0
            if not live:
                continue
            th = th_lo[n] + dth * u[n, m, 0]
            ph = box[n, 2] + dph * u[n, m, 1]
            sp = math.sin(ph)
            cx, cy, cz = math.cos(ph), sp * math.cos(th), sp * math.sin(th)
            cc = cx * ca_[n, 0] + cy * ca_[n, 1] + cz * ca_[n, 2]
            dx = (cx * e1a[n, 0] + cy * e1a[n, 1] + cz * e1a[n, 2]) / cc
            dy = (cx * e2a[n, 0] + cy * e2a[n, 1] + cz * e2a[n, 2]) / cc
            if not (abs(dx) <= ext[n, 0] and abs(dy) <= ext[n, 1]):
                continue
            lo_a, hi_a = _affine_lists(al, tl, au, tu, la, n, dx, dy)
            if not hi_a - lo_a > -2.0 * sn:
                continue
            ulo, uhi = _ray_box(cb[n], e1b[n], e2b[n], ab, ext_b[n, 0], ext_b[n, 1], cx, cy, cz)
            ulo = _max(ulo, u_min)
            uhi = _min(uhi, u_max)
            if not uhi > ulo:
                continue
            sa_lo = math.sin(_clip(lo_a - sn, 0.0, h2))
            sa_hi = math.sin(_clip(hi_a + sn, 0.0, h2))
            hlo, hhi = _ray_search(bl, sl_, bu, su, lb, cb, e1b, e2b, ab, n, cx, cy, cz, ulo, uhi,
                                   sn, t, rounds, gv, uu, True, sa_lo, sa_hi)  # fmt: skip
            if not hhi > hlo:  # a bracket of no width: the box's interval instead
                hlo, hhi = ulo, uhi
            if m % samples < n_def:
                uv = ulo + (uhi - ulo) * u[n, m, 2]
            else:
                uv = hlo + (hhi - hlo) * u[n, m, 2]
            q = lam / (uhi - ulo)
            if uv >= hlo and uv <= hhi:
                q += (1.0 - lam) / (hhi - hlo)
            rho = 1.0 / uv
            px, py, pz = pa[0] + rho * cx, pa[1] + rho * cy, pa[2] + rho * cz
            rr = math.sqrt(px * px + py * py + pz * pz)
            vx, vy, vz = px - pb[0], py - pb[1], pz - pb[2]
            rho_b = math.sqrt(vx * vx + vy * vy + vz * vz)
            vx, vy, vz = vx / rho_b, vy / rho_b, vz / rho_b
            cc = vx * cb[n, 0] + vy * cb[n, 1] + vz * cb[n, 2]
            bx = (vx * e1b[n, 0] + vy * e1b[n, 1] + vz * e1b[n, 2]) / cc
            by = (vx * e2b[n, 0] + vy * e2b[n, 1] + vz * e2b[n, 2]) / cc
            lo_b, hi_b = _affine_lists(bl, sl_, bu, su, lb, n, bx, by)
            g_lo = rr * s_half
            g_hi = g_max
            g_lo = _max(g_lo, rho * math.sin(_clip(lo_a - sn, 0.0, h2)))
            g_hi = _min(g_hi, rho * math.sin(_clip(hi_a + sn, 0.0, h2)))
            g_lo = _max(g_lo, rho_b * math.sin(_clip(lo_b - sn, 0.0, h2)))
            g_hi = _min(g_hi, rho_b * math.sin(_clip(hi_b + sn, 0.0, h2)))
            if not g_hi > g_lo:
                continue
            gg = g_lo + (g_hi - g_lo) * u[n, m, 3]
            e = math.asin(_clip(pz / rr, -1.0, 1.0))
            phi = math.atan2(py, px)
            dens = healpix_prior(rr, gg, e, phi, s_half, g_max, r_min, r_max, el_max, psi, multi)
            vol = vol0 * ((g_hi - g_lo) / q)
            wt = dens * rho**4 * sp * vol
            if not (math.isfinite(wt) and wt > 0.0):
                continue
            x[n, m], y[n, m], z[n, m], g[n, m] = px, py, pz, gg
            r[n, m], az[n, m], el[n, m], w[n, m] = rr, phi, e, wt
            ca[n, m, 0], ca[n, m, 1], ca[n, m, 2] = cx, cy, cz
            alpha[n, m] = math.asin(_clip(gg / rho, 0.0, 1.0))


def warm() -> None:
    """Compile (or load from the cache) the kernels for their one signature each."""
    pts = np.ones((1, 1, 2, 3))
    b = np.zeros((1, 1), np.bool_)
    c = np.ones((1, 3))
    d, t = np.empty((1, 1)), np.empty((1, 1, 2))
    linearise_kernel(pts, b, b.copy(), c, c, c, 0.01, d, t)
    n1 = np.zeros(1, np.int64)
    f12 = np.zeros(12, np.int64)
    boundaries_kernel(2, n1, n1, n1, n1, n1, np.zeros(2), np.zeros(2), f12, f12, pts)
    compact_kernel(b, pts, b, d, t, pts.copy(), b.copy(), b.copy(), d.copy(), t.copy())
    affine_kernel(d, t, b, b.copy(), d.copy(), t.copy(), d.copy(), t.copy(), d.copy(), t.copy(),
                  n1, d.copy(), t.copy(), n1.copy())  # fmt: skip
    a2 = np.zeros((1, 1))
    a3 = np.zeros((1, 1, 2))
    dl = np.zeros((1, 1, 2))
    out = np.zeros((1, 1))
    lists = (a2, a3, n1 + 1, a2, a3, n1 + 1)
    affine_bounds_kernel(a2, a3, a2, a3, lists, dl, out, out.copy())
    extent_kernel(a2, a3, a2, a3, lists, np.ones((1, 2)), 1.0, np.ones(1), 2, out.copy())
    v3 = np.ones(3)
    ca = np.ones((1, 1, 3))
    bb = np.ones((1, 1), np.bool_)
    tt = np.linspace(0.0, 1.0, 3)
    ray_region_kernel(a2, a3, a2, a3, lists, c, c, c, v3, ca, out, out + 1, np.ones(1), tt, 1,
                      bb)  # fmt: skip
    f = (a2, a3, a2, a3, lists)
    o = [np.zeros((1, 1)) for _ in range(8)]  # x, y, z, g, r, az, el, w
    one, b4 = np.ones(1), np.ones((1, 4))
    healpix_draws_kernel(np.full((1, 1, 4), 0.5), np.ones(1, np.bool_), one * 0, one, b4,
                         c[:, :2].copy(), c[:, :2].copy(), one, f, c, c, c, f, c, c, c, v3, v3,
                         v3, 0.01, np.inf, 0.1, 1.0, 1.0, 10.0, 1.0, 0.1, False, tt, 1, 0, 1,
                         o[0], o[1], o[2], o[3], o[4], o[5], o[6], o[7], ca.copy(),
                         out.copy())  # fmt: skip
