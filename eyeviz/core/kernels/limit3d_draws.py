"""The HEALPix proposal's draws compiled (numba): the search along A's rays for where the g
test can pass (:func:`_ray_search`, its points chosen one by one: :func:`_aim_next`; on
given rays :func:`ray_region_kernel`), and the whole draw before the exact check
(:func:`healpix_draws_kernel`: A's direction, A's box and model, B's box and region along
the ray, g, the prior, the weight). They inline :mod:`.limit3d_affine`'s model, so this
module's numba cache is stamped with that module's source as well
(:func:`.healpix_boundary.stamp_with`). The numpy references are in
:mod:`eyeviz.estimators.limit3d_healpix` and :mod:`eyeviz.estimators.limit3d_proposal`
(``_draws_ref``, ``_ray_in_region``, ``_ray_bracket``); the draws agree with them to 1e-12,
the search's brackets bit for bit (tests/core/test_kernels_limit3d.py).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from eyeviz.core.kernels import limit3d_affine, limit3d_region
from eyeviz.core.kernels.healpix_boundary import stamp_with
from eyeviz.core.kernels.limit3d_affine import _affine_at, _affine_flat, _max, _min
from eyeviz.core.kernels.limit3d_region import _M1, _mix64

# before the first kernel: its cache carries the source of the modules it calls as well
stamp_with(__file__, limit3d_affine.__file__, limit3d_region.__file__)

__all__ = ["ray_region_kernel", "healpix_draws_kernel", "healpix_prior", "warm"]

_jit = njit(cache=True, nogil=True)
_jit_inline = njit(cache=True, nogil=True, inline="always")


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
def _gap_g(a_lit, t_lit, a_unl, t_unl, l_a, l_t, nl, u_a, u_t, nu, c, e1, e2, a, n, cax, cay,
           caz, u, sa_lo, sa_hi, slack):  # fmt: skip
    """The g test's gap along A's ray at u, in B's sin-angle: min(sin(hi_B + s), sin_hi_A /
    k) - max(sin(lo_B - s), sin_lo_A / k), k = |c_A + u (A - B)| = rho_B / rho (the
    angles clipped to [0, pi / 2]; sa_lo, sa_hi: A's sin(lo_A - s), sin(hi_A + s)). A
    draw's g interval is not empty iff it is above 0 (the prior's g range aside). B's model
    as :func:`.limit3d_affine._affine_flat` (its lists' arrays l_a .. nu)."""
    vx = cax + u * a[0]
    vy = cay + u * a[1]
    vz = caz + u * a[2]
    nrm = math.sqrt(vx * vx + vy * vy + vz * vz)
    vx, vy, vz = vx / nrm, vy / nrm, vz / nrm
    cc = vx * c[n, 0] + vy * c[n, 1] + vz * c[n, 2]
    x = vx * e1[n, 0] + vy * e1[n, 1] + vz * e1[n, 2]
    y = vx * e2[n, 0] + vy * e2[n, 1] + vz * e2[n, 2]
    lo, hi = _affine_flat(a_lit, t_lit, a_unl, t_unl, l_a, l_t, nl, u_a, u_t, nu, n,
                          _clean(x / cc), _clean(y / cc))  # fmt: skip
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
def _aim_next(gv, seen, grid):
    """:func:`_aim_next_at` of the values gv[0 .. grid - 1]."""
    return _aim_next_at(gv, 0, seen, grid)


@_jit_inline
def _aim_next_at(gv, o, seen, grid):
    """The next grid point of the search along A's ray (:func:`_ray_search`), replayed
    from the values found so far (gv, ``seen`` a bit mask of the points evaluated; grid
    >= 2): (j, first, last), j >= 0 the point to evaluate next, or j = -1 and the
    bracket's inside run [first, last]. The middle pair first, then a binary search on
    the slope of pairs (the gap is unimodal along the ray on 99.8 % of the draws: the
    search then finds its maximum), stopped at the first point inside (gap > 0); from
    there the run of inside points each way. Where no point is found inside, the run is
    the first maximum of the window the binary search leaves. No proof is needed: any
    bracket is a valid proposal (the weight's mixture density uses it); on a unimodal gap
    (rising, a flat top, falling) this is the full scan's bracket ((first, last) of the
    inside points, else the argmax), with about 4.6 of the 8 points evaluated instead of
    8. ``_ray_bracket`` in limit3d_proposal is the numpy reference. The values are gv[o ..
    o + grid - 1] (a lane's row of a flat array: a row as a view would count a reference
    at each step)."""
    m0 = (grid - 2) // 2
    hit = -1
    for j in (m0, m0 + 1):
        if not (seen >> j) & 1:
            return j, 0, 0
        if gv[o + j] > 0.0:
            hit = j
            break
    lo = 0
    hi = m0
    if gv[o + m0] < gv[o + m0 + 1]:
        lo = m0 + 1
        hi = grid - 1
    while hit < 0 and hi - lo > 1:
        m = (lo + hi) // 2
        for j in (m, m + 1):
            if not (seen >> j) & 1:
                return j, 0, 0
            if gv[o + j] > 0.0:
                hit = j
                break
        if hit < 0:
            if gv[o + m] < gv[o + m + 1]:
                lo = m + 1
            else:
                hi = m
    if hit < 0:
        best = lo
        for j in range(lo, hi + 1):
            if not (seen >> j) & 1:
                return j, 0, 0
            if gv[o + j] > 0.0:
                hit = j
                break
            if gv[o + j] > gv[o + best]:
                best = j
        if hit < 0:
            return -1, best, best
    first = hit
    while first > 0:
        if not (seen >> (first - 1)) & 1:
            return first - 1, 0, 0
        if not gv[o + first - 1] > 0.0:
            break
        first -= 1
    last = hit
    while last < grid - 1:
        if not (seen >> (last + 1)) & 1:
            return last + 1, 0, 0
        if not gv[o + last + 1] > 0.0:
            break
        last += 1
    return -1, first, last


@_jit_inline
def _ray_search(a_lit, t_lit, a_unl, t_unl, lists, c, e1, e2, a, n, cax, cay, caz, lo_, hi_,
                slack, t, rounds, gv, uu, sa_lo, sa_hi):  # fmt: skip
    """One draw's search along A's ray for where the g test can pass: (lo, hi) shrunk
    ``rounds`` times on the grid t (gv, uu: work arrays of its size) to the bracket of
    the inside points (:func:`_gap_g` > 0) that :func:`_aim_next` finds."""
    grid = t.size
    l_a, l_t, nl, u_a, u_t, nu = lists
    for _ in range(rounds):
        for j in range(grid):
            uu[j] = lo_ + (hi_ - lo_) * t[j]
        seen = 0
        while True:
            j, first, last = _aim_next(gv, seen, grid)
            if j < 0:
                break
            gv[j] = _gap_g(a_lit, t_lit, a_unl, t_unl, l_a, l_t, nl, u_a, u_t, nu, c, e1, e2, a,
                           n, cax, cay, caz, uu[j], sa_lo, sa_hi, slack)  # fmt: skip
            seen |= 1 << j
        lo_ = uu[max(first - 1, 0)]
        hi_ = uu[min(last + 1, grid - 1)]
    return lo_, hi_


@_jit
def ray_region_kernel(a_lit, t_lit, a_unl, t_unl, lists, c, e1, e2, a, ca, lo, hi, slack,
                      t, rounds, live, sa_lo, sa_hi):  # fmt: skip
    """The draws' search (:func:`_ray_search`) on given rays (for its test against the
    reference, limit3d_proposal._ray_in_region with ``aim``): on the draws where ``live``
    (N, M), lo, hi (N, M) shrunk in place to where the g test can pass (A's sin(lo_A -
    s), sin(hi_A + s) sa_lo, sa_hi (N, M))."""
    gv = np.empty(t.size)
    uu = np.empty(t.size)
    for n in range(ca.shape[0]):
        for m in range(ca.shape[1]):
            if not live[n, m]:
                continue
            lo[n, m], hi[n, m] = _ray_search(a_lit, t_lit, a_unl, t_unl, lists, c, e1, e2, a, n,
                                             ca[n, m, 0], ca[n, m, 1], ca[n, m, 2], lo[n, m],
                                             hi[n, m], slack[n], t, rounds, gv, uu, sa_lo[n, m],
                                             sa_hi[n, m])  # fmt: skip


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
def _ray_box(c0, c1, c2, p0, p1, p2, s0, s1, s2, a0, a1, a2, ext0, ext1, cax, cay, caz):
    """limit3d_proposal._ray_in_box for one ray: (lo, hi) of u where B's view of
    A + c_A / u lies in B's box (c, p, s: B's centre and frame e1, e2; a = A - B), from
    scalars (arrays passed would count references at every draw)."""
    ca_ = c0 * a0 + c1 * a1 + c2 * a2
    cc = cax * c0 + cay * c1 + caz * c2
    lo = 0.0
    hi = np.inf
    for j in range(5):
        if j == 0:
            k0, k1 = -cc, -ca_
        else:
            if j < 3:
                e0, e1, e2, x = p0, p1, p2, ext0
            else:
                e0, e1, e2, x = s0, s1, s2, ext1
            sgn = 1.0 if j % 2 == 1 else -1.0
            ce = cax * e0 + cay * e1 + caz * e2
            k1 = sgn * (e0 * a0 + e1 * a1 + e2 * a2) - x * ca_
            k0 = sgn * ce - x * cc
        root = -k0 / k1
        if k1 > 0:
            hi = _min(hi, root)
        if k1 < 0:
            lo = _max(lo, root)
        if k1 == 0 and k0 > 0:
            lo = np.inf
    return lo, hi


@_jit
def _uniform(base, s, j):
    """limit3d_proposal._uniforms' uniform of counter j in stream s, for a key whose
    hash times _M1 is ``base`` (as limit3d_region.uniforms_kernel: the same bits)."""
    z = _mix64(base + (np.uint64(j) + (np.uint64(s) << np.uint64(32))))
    return (np.float64(z >> np.uint64(11)) + 0.5) * 2.0**-53


# long: one draw of limit3d_healpix.HealpixProposal.sample up to the exact check (A's
# direction, A's model, B's box and region along the ray, g, prior, weight) is one loop
# body; split, it would pass a dozen scalars back and forth
@_jit_np
def healpix_draws_kernel(keys, streams, rows, th_lo, th_hi, box, ext, ext_b, slack, fa, ca_,
                         e1a, e2a, fb, cb, e1b, e2b, ab, pa, pb, u_min, u_max, s_half, g_max, r_min,
                         r_max, el_max, psi, multi, t, rounds, n_def, samples,
                         x, y, z, g, r, az, el, w, ca, alpha):  # fmt: skip
    """HealpixProposal.sample's draws before the exact check, one at a time, each given up
    at its first test that fails: (theta, phi) of A's direction from the uniforms
    (limit3d_proposal._batch_uniforms of the key hashes ``keys`` (N,) and ``streams``,
    ``samples`` draws of 4 each, the same bits; each drawn when first read: a draw given up
    early never draws its last two), inside A's box of centres and A's modelled region, u =
    1 / rho in B's box along the ray (:func:`_ray_box`), then narrowed to where the g test
    can pass (:func:`_ray_search` of :func:`_gap_g`), g where both eyes' modelled radii and
    the prior allow it, the prior and the weight. Of each batch of ``samples`` draws the
    first ``n_def`` take u uniform on B's box along the ray (the defensive share: the
    narrowed interval is a search's bracket, not a proven hull), the others on the narrowed
    interval; every weight divides by the two's mixture density at its u. fa, fb: each eye's
    affine forms (a_lit, t_lit, a_unl, t_unl, lists); ab = A - B; pa, pb the eyes' centres.
    Writes x, y, z, g, r, az, el, w, ca (N, M, 3) and alpha (N, M) where the weight is above
    0 (w 0 elsewhere, the others then unset); only the keys ``rows`` (N,) get draws."""
    al, tl, au, tu, la = fa
    bl, sl_, bu, su, lb = fb
    h2 = 0.5 * math.pi
    # the lists' arrays unpacked once (an unpacking in the loops would count references)
    la_a, la_t, la_n, la_ua, la_ut, la_nu = la
    lb_a, lb_t, lb_n, lb_ua, lb_ut, lb_nu = lb
    lam = n_def / samples
    mt = samples * streams.size
    # a key's draws that reach the ray search: their index and state (A's direction, its
    # sp, the box's u interval, A's sines), then their brackets
    q_m = np.empty(mt, np.int64)
    q_v = np.empty((mt, 8))
    q_h = np.empty((mt, 2))
    for n in range(keys.size):
        base = keys[n] * _M1
        sn = slack[n]
        dth = th_hi[n] - th_lo[n]
        dph = box[n, 3] - box[n, 2]
        live = rows[n] and dth > 0 and dph > 0
        vol0 = dth * dph
        nq = 0
        for m in range(mt):
            w[n, m] = 0.0
            if not live:
                continue
            s_m = streams[m // samples]
            j4 = 4 * (m % samples)
            th = th_lo[n] + dth * _uniform(base, s_m, j4)
            ph = box[n, 2] + dph * _uniform(base, s_m, j4 + 1)
            sp = math.sin(ph)
            cx, cy, cz = math.cos(ph), sp * math.cos(th), sp * math.sin(th)
            cc = cx * ca_[n, 0] + cy * ca_[n, 1] + cz * ca_[n, 2]
            dx = (cx * e1a[n, 0] + cy * e1a[n, 1] + cz * e1a[n, 2]) / cc
            dy = (cx * e2a[n, 0] + cy * e2a[n, 1] + cz * e2a[n, 2]) / cc
            if not (abs(dx) <= ext[n, 0] and abs(dy) <= ext[n, 1]):
                continue
            # _affine_flat written out (see _ray_searches)
            if math.isfinite(dx) and math.isfinite(dy):
                lo_a = -np.inf
                for k in range(la_n[n]):
                    fv = la_t[n, k, 0] * dx
                    fv = fv + la_t[n, k, 1] * dy
                    fv = la_a[n, k] - fv
                    lo_a = fv if fv > lo_a else lo_a
                hi2 = np.inf
                for k in range(la_nu[n]):
                    fw = la_ut[n, k, 0] * dx
                    fw = fw + la_ut[n, k, 1] * dy
                    fw = la_ua[n, k] - fw
                    hi2 = fw if fw < hi2 else hi2
                hi2 = hi2 + (dx * dx + dy * dy)
                hi_a = math.sqrt(_max(hi2, 0.0))
            else:
                lo_a, hi_a = _affine_at(al, tl, au, tu, n, dx, dy)
            if not hi_a - lo_a > -2.0 * sn:
                continue
            ulo, uhi = _ray_box(cb[n, 0], cb[n, 1], cb[n, 2], e1b[n, 0], e1b[n, 1], e1b[n, 2],
                                e2b[n, 0], e2b[n, 1], e2b[n, 2], ab[0], ab[1], ab[2], ext_b[n, 0],
                                ext_b[n, 1], cx, cy, cz)  # fmt: skip
            ulo = _max(ulo, u_min)
            uhi = _min(uhi, u_max)
            if not uhi > ulo:
                continue
            q_m[nq] = m
            q_v[nq, 0], q_v[nq, 1], q_v[nq, 2], q_v[nq, 3] = cx, cy, cz, sp
            q_v[nq, 4], q_v[nq, 5] = ulo, uhi
            q_v[nq, 6] = math.sin(_clip_nan(lo_a - sn, 0.0, h2))
            q_v[nq, 7] = math.sin(_clip_nan(hi_a + sn, 0.0, h2))
            nq += 1
        _ray_searches(bl, sl_, bu, su, lb_a, lb_t, lb_n, lb_ua, lb_ut, lb_nu, cb, e1b, e2b, ab, n,
                      q_v, nq, sn, t, rounds, q_h)  # fmt: skip
        for q in range(nq):
            m = q_m[q]
            cx, cy, cz, sp = q_v[q, 0], q_v[q, 1], q_v[q, 2], q_v[q, 3]
            ulo, uhi, sa_lo, sa_hi = q_v[q, 4], q_v[q, 5], q_v[q, 6], q_v[q, 7]
            hlo, hhi = q_h[q, 0], q_h[q, 1]
            s_m = streams[m // samples]
            j4 = 4 * (m % samples)
            if not hhi > hlo:  # a bracket of no width: the box's interval instead
                hlo, hhi = ulo, uhi
            u2 = _uniform(base, s_m, j4 + 2)
            if m % samples < n_def:
                uv = ulo + (uhi - ulo) * u2
            else:
                uv = hlo + (hhi - hlo) * u2
            qd = lam / (uhi - ulo)
            if uv >= hlo and uv <= hhi:
                qd += (1.0 - lam) / (hhi - hlo)
            rho = 1.0 / uv
            px, py, pz = pa[0] + rho * cx, pa[1] + rho * cy, pa[2] + rho * cz
            rr = math.sqrt(px * px + py * py + pz * pz)
            vx, vy, vz = px - pb[0], py - pb[1], pz - pb[2]
            rho_b = math.sqrt(vx * vx + vy * vy + vz * vz)
            vx, vy, vz = vx / rho_b, vy / rho_b, vz / rho_b
            cc = vx * cb[n, 0] + vy * cb[n, 1] + vz * cb[n, 2]
            bx = (vx * e1b[n, 0] + vy * e1b[n, 1] + vz * e1b[n, 2]) / cc
            by = (vx * e2b[n, 0] + vy * e2b[n, 1] + vz * e2b[n, 2]) / cc
            if math.isfinite(bx) and math.isfinite(by):  # _affine_flat written out
                lo_b = -np.inf
                for k in range(lb_n[n]):
                    fv = lb_t[n, k, 0] * bx
                    fv = fv + lb_t[n, k, 1] * by
                    fv = lb_a[n, k] - fv
                    lo_b = fv if fv > lo_b else lo_b
                hi2 = np.inf
                for k in range(lb_nu[n]):
                    fw = lb_ut[n, k, 0] * bx
                    fw = fw + lb_ut[n, k, 1] * by
                    fw = lb_ua[n, k] - fw
                    hi2 = fw if fw < hi2 else hi2
                hi2 = hi2 + (bx * bx + by * by)
                hi_b = math.sqrt(_max(hi2, 0.0))
            else:
                lo_b, hi_b = _affine_at(bl, sl_, bu, su, n, bx, by)
            g_lo = rr * s_half
            g_hi = g_max
            g_lo = _max(g_lo, rho * sa_lo)  # A's sines, as the search took them
            g_hi = _min(g_hi, rho * sa_hi)
            g_lo = _max(g_lo, rho_b * math.sin(_clip_nan(lo_b - sn, 0.0, h2)))
            g_hi = _min(g_hi, rho_b * math.sin(_clip_nan(hi_b + sn, 0.0, h2)))
            if not g_hi > g_lo:
                continue
            gg = g_lo + (g_hi - g_lo) * _uniform(base, s_m, j4 + 3)
            e = math.asin(_clip_nan(pz / rr, -1.0, 1.0))
            phi = math.atan2(py, px)
            dens = healpix_prior(rr, gg, e, phi, s_half, g_max, r_min, r_max, el_max, psi, multi)
            vol = vol0 * ((g_hi - g_lo) / qd)
            wt = dens * rho**4 * sp * vol
            if not (math.isfinite(wt) and wt > 0.0):
                continue
            x[n, m], y[n, m], z[n, m], g[n, m] = px, py, pz, gg
            r[n, m], az[n, m], el[n, m], w[n, m] = rr, phi, e, wt
            ca[n, m, 0], ca[n, m, 1], ca[n, m, 2] = cx, cy, cz
            alpha[n, m] = math.asin(_clip_nan(gg / rho, 0.0, 1.0))


#: rays searched side by side (:func:`_ray_searches`)
_LANES = 4


# long: four searches side by side with the model and the gap written out with scalars (a
# helper taking arrays counts atomic references per call: docs/limit3d.md, "hp31h")
@_jit_inline
def _ray_searches(a_lit, t_lit, a_unl, t_unl, l_a, l_t, nl, u_a, u_t, nu, c, e1, e2, a, n, qv, nq,
                  slack, t, rounds, out):  # fmt: skip
    """:func:`_ray_search` of the rays 0 .. nq - 1 of key n (qv[q]: c_A's x, y, z, sp, the
    box's lo, hi along the ray, A's sin(lo_A - s), sin(hi_A + s)), ``_LANES`` of them side
    by side: each takes the points :func:`_aim_next` asks for in turn, a point of each ray
    evaluated before the next of any, so the rays' chains of operations (a normalisation,
    B's model, two sines) overlap; each ray's points, values and bracket are its own
    search's (a point's value is a function of its u alone). out[q] = (lo, hi). B's model's
    lists as :func:`_gap_g` takes them; the lanes' values one flat array (lane i's at
    i * grid: a row as a view would count a reference at each step)."""
    grid = t.size
    h2 = 0.5 * math.pi
    gvs = np.empty(_LANES * grid)
    uus = np.empty((_LANES, grid))
    seen = np.zeros(_LANES, np.int64)
    pend = np.zeros(_LANES, np.int64)
    act = np.zeros(_LANES, np.bool_)
    for q0 in range(0, nq, _LANES):
        kk = min(_LANES, nq - q0)
        for i in range(kk):
            out[q0 + i, 0] = qv[q0 + i, 4]
            out[q0 + i, 1] = qv[q0 + i, 5]
        for _ in range(rounds):
            for i in range(kk):
                lo_, hi_ = out[q0 + i, 0], out[q0 + i, 1]
                for j in range(grid):
                    uus[i, j] = lo_ + (hi_ - lo_) * t[j]
                seen[i] = 0
                act[i] = True
            while True:
                more = False
                for i in range(kk):
                    if not act[i]:
                        continue
                    j, first, last = _aim_next_at(gvs, i * grid, seen[i], grid)
                    if j < 0:
                        act[i] = False
                        out[q0 + i, 0] = uus[i, max(first - 1, 0)]
                        out[q0 + i, 1] = uus[i, min(last + 1, grid - 1)]
                    else:
                        pend[i] = j
                        more = True
                if not more:
                    break
                for i in range(kk):
                    if act[i]:
                        q = q0 + i
                        j = pend[i]
                        # _gap_g written out: a call passing arrays, inlined or not, counts
                        # a reference on each at every evaluation (atomic operations that
                        # cost more than the evaluation); the same operations, same order
                        u = uus[i, j]
                        vx = qv[q, 0] + u * a[0]
                        vy = qv[q, 1] + u * a[1]
                        vz = qv[q, 2] + u * a[2]
                        nrm = math.sqrt(vx * vx + vy * vy + vz * vz)
                        vx, vy, vz = vx / nrm, vy / nrm, vz / nrm
                        cc = vx * c[n, 0] + vy * c[n, 1] + vz * c[n, 2]
                        x = vx * e1[n, 0] + vy * e1[n, 1] + vz * e1[n, 2]
                        y = vx * e2[n, 0] + vy * e2[n, 1] + vz * e2[n, 2]
                        dx = _clean(x / cc)
                        dy = _clean(y / cc)
                        if math.isfinite(dx) and math.isfinite(dy):  # _affine_flat's loops
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
                            hi = math.sqrt(_max(hi2, 0.0))
                        else:
                            lo, hi = _affine_at(a_lit, t_lit, a_unl, t_unl, n, dx, dy)
                        sb_lo = math.sin(_clip_nan(lo - slack, 0.0, h2))
                        sb_hi = math.sin(_clip_nan(hi + slack, 0.0, h2))
                        gv = _min(sb_hi, qv[q, 7] / nrm) - _max(sb_lo, qv[q, 6] / nrm)
                        gvs[i * grid + j] = gv
                        seen[i] |= 1 << j


def warm() -> None:
    """Compile (or load from the cache) the kernels for their one signature each."""
    c = np.ones((1, 3))
    n1 = np.zeros(1, np.int64)
    a2 = np.zeros((1, 1))
    a3 = np.zeros((1, 1, 2))
    out = np.zeros((1, 1))
    lists = (a2, a3, n1 + 1, a2, a3, n1 + 1)
    v3 = np.ones(3)
    ca = np.ones((1, 1, 3))
    bb = np.ones((1, 1), np.bool_)
    tt = np.linspace(0.0, 1.0, 3)
    ray_region_kernel(a2, a3, a2, a3, lists, c, c, c, v3, ca, out, out + 1, np.ones(1), tt, 1,
                      bb, out.copy(), out + 1)  # fmt: skip
    f = (a2, a3, a2, a3, lists)
    o = [np.zeros((1, 1)) for _ in range(8)]  # x, y, z, g, r, az, el, w
    one, b4 = np.ones(1), np.ones((1, 4))
    healpix_draws_kernel(np.ones(1, np.uint64), np.zeros(1, np.int64), np.ones(1, np.bool_),
                         one * 0, one, b4,
                         c[:, :2].copy(), c[:, :2].copy(), one, f, c, c, c, f, c, c, c, v3, v3,
                         v3, 0.01, np.inf, 0.1, 1.0, 1.0, 10.0, 1.0, 0.1, False, tt, 1, 0, 1,
                         o[0], o[1], o[2], o[3], o[4], o[5], o[6], o[7], ca.copy(),
                         out.copy())  # fmt: skip
