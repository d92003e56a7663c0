"""The measured eyes' hot paths compiled (numba): the certified decision of
:mod:`eyeviz.core.measured_fast` and the chord search of :mod:`eyeviz.core.measured_grid`.

Scalar transcriptions, one (ball, facet) pair or one ball at a time, without temporaries:
the same formulas and the same error bounds as the numpy reference (``_certified`` and the
cKDTree search of :mod:`eyeviz.core.measured_index`), which ``EYEVIZ_JIT=0`` runs instead.
numba compiles without fast-math, so every operation rounds as IEEE float64 does (a fused
multiply-add, if LLVM chose one, only shrinks an error); tests/core/test_measured.py
compares the two paths.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

__all__ = ["certified_kernel", "key_check_kernel", "scan_kernel", "warm", "LEVELS"]

_U = 2.0**-53
_LO, _HI = 2.0**-480, 2.0**480
LEVELS = 10
_SLACK = 1e-9  # as measured_index
_SHIFT = (56, 36, 18)  # level, x, y (z in the low bits)
_jit = njit(cache=True, nogil=True)


_inline = njit(cache=True, nogil=True, inline="always")


@_inline
def _certify_at(cx, cy, cz, gb, p0, p1, p2, a0, a1, a2, nn, cc, ss, exact):
    """(seen, sure, lens) of the ball (c, g) and a facet given by its values (lens p, unit
    axis a, nrm, cos and sin of its half acceptance angle, exact_only): the certified
    float64 test of :mod:`eyeviz.core.measured_fast` (``seen`` the answer where
    ``sure``), and whether its lens lies in the closed ball: 1 surely, 0 surely not, 2
    not decided here."""
    vx, vy, vz = cx - p0, cy - p1, cz - p2
    mag = max(abs(vx), abs(vy), abs(vz))
    if mag == 0.0:  # c = p exactly: the lens is in the ball
        return True, True, 1
    if not (_LO <= mag <= _HI and gb <= _HI) or exact:
        return False, False, 2
    v2 = vx * vx + vy * vy + vz * vz
    g2 = gb * gb
    da = v2 - g2
    ba = 16 * _U * (v2 + g2)
    s = vx * a0 + vy * a1 + vz * a2
    wx = vy * a2 - vz * a1
    wy = vz * a0 - vx * a2
    wz = vx * a1 - vy * a0
    q = math.sqrt(wx * wx + wy * wy + wz * wz)
    vn = math.sqrt(v2) * (1 + 4 * _U) * nn
    e = s * cc + q * ss
    be = 32 * _U * vn
    m = q * cc - s * ss - gb * nn
    bm = 32 * _U * (vn + gb * nn)
    yes = da <= -ba or (e >= be and m <= -bm)
    no = da > ba and (e < -be or m > bm)
    lens = 1 if da <= -ba else (0 if da > ba else 2)
    return yes, yes or no, lens


@_jit
def _certify(cx, cy, cz, gb, px, py, pz, ax, ay, az, nrm, cs, sn, exact_only, i):
    """:func:`_certify_at` of facet i of the eye's arrays."""
    return _certify_at(cx, cy, cz, gb, px[i], py[i], pz[i], ax[i], ay[i], az[i], nrm[i], cs[i],
                       sn[i], exact_only[i])  # fmt: skip


@_jit
def certified_kernel(
    cx, cy, cz, g, bi, fi, px, py, pz, ax, ay, az, nrm, cs, sn, exact_only, seen, sure
):
    for k in range(bi.size):
        b = bi[k]
        seen[k], sure[k], _ = _certify(cx[b], cy[b], cz[b], g[b], px, py, pz, ax, ay, az, nrm,
                                       cs, sn, exact_only, fi[k])  # fmt: skip


_REL = 1e-9  # the slack of the key's bound, relative and in radians (as measured_index)


@_jit
def _key_spread(cx, cy, cz, g, s, e, ox, oy, oz):
    """Of the balls s..e-1: their mean direction w from o (unit), the largest angle A of
    a ball's direction from w, the largest g and the least distance D from o, each with
    a relative slack of 1e-9 (and 1e-9 rad) beyond its rounding; D = 0 where any is not
    finite."""
    wx, wy, wz, big, near = 0.0, 0.0, 0.0, 0.0, math.inf
    for b in range(s, e):
        dx, dy, dz = cx[b] - ox, cy[b] - oy, cz[b] - oz
        d = math.sqrt(dx * dx + dy * dy + dz * dz)
        if not (d > 0.0 and d < math.inf and g[b] < math.inf):
            return 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
        wx, wy, wz = wx + dx / d, wy + dy / d, wz + dz / d
        big, near = max(big, g[b]), min(near, d)
    wn = math.sqrt(wx * wx + wy * wy + wz * wz)
    if not wn > 0.0:
        return 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    wx, wy, wz = wx / wn, wy / wn, wz / wn
    top = 0.0
    for b in range(s, e):
        dx, dy, dz = cx[b] - ox, cy[b] - oy, cz[b] - oz
        top = max(top, _angle(dx, dy, dz, wx, wy, wz))
    return wx, wy, wz, top * (1 + _REL) + _REL, big * (1 + _REL), near * (1 - _REL), 1.0


@_jit
def _angle(x, y, z, wx, wy, wz):
    """The angle between (x, y, z) and the unit w, from atan2 (accurate near 0 and pi)."""
    cx_, cy_, cz_ = y * wz - z * wy, z * wx - x * wz, x * wy - y * wx
    return math.atan2(math.sqrt(cx_ * cx_ + cy_ * cy_ + cz_ * cz_), x * wx + y * wy + z * wz)


@_jit
def _reach(alpha, g, d, e):
    """An upper bound of alpha + asin(g / (d - e)) + asin(e / d) (measured_index: the
    largest angle between a facet's axis and the direction from o of a ball it sees, its
    lens within e of o, the ball at d > e + g from o), or inf where d <= e + g."""
    if not d > (e + g) * (1 + _REL):
        return math.inf
    r = alpha + math.asin(min(1.0, g / (d - e))) + math.asin(min(1.0, e / d))
    return r * (1 + _REL) + _REL


# long: the key's facet list (a bound over all its balls, then each facet's own) and the
# balls' certified tests against it are one pass per key; split, they would share a
# dozen per-key scalars and three scratch arrays
@_jit
def key_check_kernel(cx, cy, cz, g, bounds, px, py, pz, ax, ay, az, nrm, cs, sn, exact_only,
                     ux, uy, uz, half, centre, lens, kp, ki, res):  # fmt: skip
    """One eye's part of the exact check of a chunk's draws (balls c, g; key n's balls at
    bounds[n]..bounds[n + 1] - 1), folded into ``res`` (1 a hit so far, 0 not a hit, 2
    not decided here: the index and ``lit_csr`` decide).

    measured_index's argument, about o (the mean lens of the key's lit facets; kp, ki:
    the keys' lit facets, CSR, sorted): facet j (lens within e_j of o, half acceptance
    alpha_j) sees no ball at distance D > e_j + g from o whose direction from o lies
    more than alpha_j + asin(g / (D - e_j)) + asin(e_j / D) from its axis. Per key, over
    its balls (w their mean direction from o, A the largest angle from w, G the largest
    g, D0 the least distance), a facet whose axis lies more than A + that bound at (G,
    D0) from w sees none of them: the others, the key's list (the eye's lens bound
    ``lens`` about ``centre`` rules most facets out first), are
    sorted by k_j = angle(a_j, w) - alpha_j - asin(e_j / D0). A ball (direction at
    angle A_b from w, distance D_b, radius g) then sees none with k_j > A_b + asin(g /
    (D_b - E)) (E the list's largest e_j), so only the list's first facets get the
    certified test of measured_fast (:func:`_certify`): the ball must see exactly the
    key's lit ones, and none of their lenses may lie in it (an unseen facet's lens does
    not). Every bound carries a relative slack of 1e-9 (and 1e-9 rad)."""
    nf = px.size
    lst = np.empty(nf, np.int64)
    islit = np.empty(nf, np.bool_)
    kj = np.empty(nf)
    kl = np.empty(nf)
    # the key's list sorted by k_j, each facet's values side by side, read in order by
    # every ball (read through the sort and the list from the eye's arrays, the balls'
    # tests took about 4 times as long: docs/limit3d.md, bee33f)
    vals = np.empty((nf, 11))
    flags = np.empty((nf, 2), np.bool_)
    amax = 0.0
    for j in range(nf):
        amax = max(amax, half[j])
    for n in range(bounds.size - 1):
        s, e = bounds[n], bounds[n + 1]
        l0, l1 = kp[n], kp[n + 1]
        if s == e:
            continue
        ok = l1 > l0
        ox, oy, oz = 0.0, 0.0, 0.0
        for t in range(l0, l1):
            ox, oy, oz = ox + px[ki[t]], oy + py[ki[t]], oz + pz[ki[t]]
        if ok:
            ox, oy, oz = ox / (l1 - l0), oy / (l1 - l0), oz / (l1 - l0)
        wx, wy, wz, top, big, near, fine = _key_spread(cx, cy, cz, g, s, e, ox, oy, oz)
        dc = math.sqrt((ox - centre[0]) ** 2 + (oy - centre[1]) ** 2 + (oz - centre[2]) ** 2)
        cut = top + _reach(amax, big, near, (lens + dc) * (1 + _REL))
        ok = ok and fine > 0.0 and cut < math.pi
        n_l, t, emax = 0, l0, 0.0
        if ok:
            cosc = math.cos(cut) - _REL
            for j in range(nf):
                if ux[j] * wx + uy[j] * wy + uz[j] * wz < cosc:
                    continue
                ej = math.sqrt((px[j] - ox) ** 2 + (py[j] - oy) ** 2 + (pz[j] - oz) ** 2)
                ej = ej * (1 + _REL)
                th = _angle(ux[j], uy[j], uz[j], wx, wy, wz)
                if th - top > _reach(half[j], big, near, ej):
                    continue
                while t < l1 and ki[t] < j:
                    t += 1
                k = th - half[j] - math.asin(min(1.0, ej / near))
                lst[n_l], islit[n_l], kj[n_l] = j, t < l1 and ki[t] == j, k - _REL * (1 + abs(k))
                kl[n_l] = math.inf
                if islit[n_l] and not exact_only[j] and ej < near:
                    k = th - half[j] + math.asin(ej / near)
                    kl[n_l] = k + _REL * (1 + abs(k))
                emax = max(emax, ej)
                n_l += 1
        by = np.argsort(kj[:n_l])
        for q in range(n_l):
            t, f = by[q], lst[by[q]]
            vals[q, 0], vals[q, 1], vals[q, 2] = px[f], py[f], pz[f]
            vals[q, 3], vals[q, 4], vals[q, 5] = ax[f], ay[f], az[f]
            vals[q, 6], vals[q, 7], vals[q, 8] = nrm[f], cs[f], sn[f]
            vals[q, 9], vals[q, 10] = kj[t], kl[t]
            flags[q, 0], flags[q, 1] = islit[t], exact_only[f]
        for b in range(s, e):
            if res[b] == 0:
                continue
            if not ok:
                res[b] = 2
                continue
            dx, dy, dz = cx[b] - ox, cy[b] - oy, cz[b] - oz
            db = math.sqrt(dx * dx + dy * dy + dz * dz) * (1 - _REL)
            reach, safe = math.inf, -math.inf
            if db > (emax + g[b]) * (1 + _REL):
                ab = _angle(dx, dy, dz, wx, wy, wz)
                reach = ab + math.asin(min(1.0, g[b] / (db - emax)))
                reach = reach * (1 + _REL) + _REL
                # no lens of the list in the ball; a lit facet with kl_j <= safe sees it
                dh = (db / (1 - _REL)) * (1 + _REL) + emax
                safe = math.asin(g[b] / (dh * (1 + _REL))) * (1 - _REL) - _REL
                safe = safe - (ab * (1 + _REL) + _REL)
            verdict, n_lit = 1, 0
            for q in range(n_l):
                if vals[q, 9] > reach:
                    break
                lit_q = flags[q, 0]
                n_lit += lit_q
                if vals[q, 10] <= safe:  # a lit facet that surely sees the ball
                    continue
                seen, sure, inside = _certify_at(cx[b], cy[b], cz[b], g[b], vals[q, 0],
                                                 vals[q, 1], vals[q, 2], vals[q, 3], vals[q, 4],
                                                 vals[q, 5], vals[q, 6], vals[q, 7], vals[q, 8],
                                                 flags[q, 1])  # fmt: skip
                if not sure:
                    verdict = 2
                elif seen != lit_q or (seen and inside == 1):
                    verdict = 0
                    break
                elif seen and inside == 2:
                    verdict = 2
            if n_lit < l1 - l0:  # a lit facet ruled out: not seen
                verdict = 0
            res[b] = 0 if verdict == 0 else max(res[b], verdict)


@_jit
def _scan_pass(cx, cy, cz, g, centre, lens, alpha, keys, starts, counts, pux, puy, puz, perm,
          offs, out, fill):  # fmt: skip
    nfacet = pux.size // LEVELS
    for b in range(cx.size):
        # the search radius of measured_index.AxisIndex.search; r = 8: every facet
        ux, uy, uz, r = 0.0, 0.0, 0.0, 8.0
        dx, dy, dz = cx[b] - centre[0], cy[b] - centre[1], cz[b] - centre[2]
        big = max(abs(dx), abs(dy), abs(dz))
        if big > 0.0 and big < math.inf:
            dx, dy, dz = dx / big, dy / big, dz / big
            nd = math.sqrt(dx * dx + dy * dy + dz * dz)
            dist = nd * big
            if dist < math.inf and dist > (lens + g[b]) * (1 + _SLACK):
                beta = math.asin(min(1.0, g[b] / (dist - lens)))
                gam = math.asin(min(1.0, lens / dist))
                ang = (alpha + beta + gam) * (1 + _SLACK) + _SLACK
                if ang < math.pi:
                    ux, uy, uz = dx / nd, dy / nd, dz / nd
                    r = 2 * math.sin(ang / 2) + _SLACK
        n = 0
        if r >= 4.0:  # every facet
            if fill:
                for i in range(nfacet):
                    out[offs[b] + i] = i
            n = nfacet
        else:
            lev = min(max(int(math.floor(1.0 - math.log2(r))), 0), LEVELS - 1)
            side = 2.0 ** (1 - lev)
            top = (1 << lev) - 1
            x0 = min(max(int(math.floor((ux - r + 1.0) / side)), 0), top)
            x1 = min(max(int(math.floor((ux + r + 1.0) / side)), 0), top)
            y0 = min(max(int(math.floor((uy - r + 1.0) / side)), 0), top)
            y1 = min(max(int(math.floor((uy + r + 1.0) / side)), 0), top)
            z0 = min(max(int(math.floor((uz - r + 1.0) / side)), 0), top)
            z1 = min(max(int(math.floor((uz + r + 1.0) / side)), 0), top)
            r2 = r * r
            for ix in range(x0, x1 + 1):
                for iy in range(y0, y1 + 1):
                    base = (lev << _SHIFT[0]) | (ix << _SHIFT[1]) | (iy << _SHIFT[2])
                    j = np.searchsorted(keys, base | z0)
                    while j < keys.size and keys[j] <= (base | z1):
                        for p in range(starts[j], starts[j] + counts[j]):
                            dx, dy, dz = pux[p] - ux, puy[p] - uy, puz[p] - uz
                            if dx * dx + dy * dy + dz * dz <= r2:
                                if fill:
                                    out[offs[b] + n] = perm[p]
                                n += 1
                        j += 1
        if not fill:
            offs[b] = n


@_jit
def scan_kernel(cx, cy, cz, g, centre, lens, alpha, keys, starts, counts, pux, puy, puz, perm):
    """(count per ball, facets) within each ball's search radius: a counting pass, then a
    filling pass into one array (one call from Python)."""
    cnt = np.zeros(cx.size, np.int64)
    none = np.zeros(0, np.int64)
    _scan_pass(cx, cy, cz, g, centre, lens, alpha, keys, starts, counts, pux, puy, puz, perm,
               cnt, none, False)  # fmt: skip
    offs = np.cumsum(cnt) - cnt
    out = np.empty(cnt.sum(), np.int64)
    _scan_pass(cx, cy, cz, g, centre, lens, alpha, keys, starts, counts, pux, puy, puz, perm,
               offs, out, True)  # fmt: skip
    return cnt, out


def warm() -> None:
    """Compile (or load from the cache) the kernels for their one signature each."""
    f = np.zeros(1)
    i = np.zeros(1, np.int64)
    b = np.zeros(1, np.bool_)
    certified_kernel(f, f, f, f + 1, i, i, f, f, f, f + 1, f, f, f + 1, f + 1, f, b,
                     b.copy(), b.copy())  # fmt: skip
    keys = np.zeros(1, np.int64)
    pu = np.zeros(LEVELS)
    perm = np.zeros(LEVELS, np.int64)
    scan_kernel(f, f, f, f + 1, np.zeros(3), 0.5, 0.1, keys, i, i + 1, pu, pu, pu, perm)
    bounds = np.array([0, 1], np.int64)
    key_check_kernel(f + 2, f, f, f + 1, bounds, f, f, f, f + 1, f, f, f + 1, f + 1, f, b,
                     f + 1, f, f, f + 0.1, np.zeros(3), 0.5, bounds, i.copy(),
                     np.ones(1, np.int64))  # fmt: skip
