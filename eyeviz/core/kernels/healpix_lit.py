"""The float64 fast path of the spherical lit sets, compiled (numba), ball by ball.

A scalar transcription of :func:`eyeviz.core.healpix_fast._lit_runs_fast` and
:func:`eyeviz.core.healpix_fast._decide_cells` (docs/spherical.md, steps 1-5): the same
bounds, the same candidate and surely-lit ranges per ring, the same vertex, edge and
edge-sample tests with the same rounding bounds, and one more sample stage (4096 samples
per edge, the same bound) before a cell is left open. What the numpy path hands to mpmath or
to its special branches (a ball near the eye centre's sphere, a grazing cap, a cap below
1e6 rounding errors of its direction, a cell left open after the edge samples, a ring
whose lit cells are not one run) the kernel does not decide: it marks the ball, and
:func:`eyeviz.core.geometry3d._lit_runs_jit` sends the marked balls through the numpy
path. Lit sets are therefore those of the reference, exactly
(tests/core/test_kernels_healpix.py compares them).
Output: runs (start, length) per ball, sorted by start, never one index per facet.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

__all__ = ["lit_runs_kernel", "csr_kernel", "warm"]

_EPS = 2.0**-52
_DP = 64 * _EPS
_JRLL = np.array([2, 2, 2, 2, 3, 3, 3, 3, 4, 4, 4, 4], np.int64)
_JPLL = np.array([1, 3, 5, 7, 0, 2, 4, 6, 1, 3, 5, 7], np.int64)
_HALF_PI = 0.5 * math.pi
_SQ6 = math.sqrt(6.0)
_jit = njit(cache=True, error_model="numpy", nogil=True)


@_jit
def _jr_of_theta(theta):
    c = math.cos(theta)
    if c >= 2.0 / 3.0:
        return _SQ6 * math.sin(0.5 * theta)
    if c <= -2.0 / 3.0:
        return 4.0 - _SQ6 * math.cos(0.5 * theta)
    return 2.0 - 1.5 * c


@_jit
def _ang2pix(n, z, phi):
    """healpix.ang2pix_ring for one direction (the same float64 formulas)."""
    za = abs(z)
    tt = (phi * (1.0 / _HALF_PI)) % 4.0
    if tt >= 4.0:
        tt = 0.0
    if za <= 2.0 / 3.0:
        t1 = n * (0.5 + tt)
        t2 = n * z * 0.75
        jp = np.int64(math.floor(t1 - t2))
        jm = np.int64(math.floor(t1 + t2))
        ir = n + 1 + jp - jm
        kshift = 1 - (ir & 1)
        ip = ((jp + jm - n + kshift + 1 + 8 * n) >> 1) % (4 * n)
        return 2 * n * (n - 1) + (ir - 1) * 4 * n + ip
    tp = tt - math.floor(tt)
    tmp = n * math.sqrt(3.0 * (1.0 - za))
    jp = np.int64(math.floor(tp * tmp))
    jm = np.int64(math.floor((1.0 - tp) * tmp))
    ir = jp + jm + 1
    ip = min(np.int64(math.floor(tt * ir)), 4 * ir - 1)
    if z > 0:
        return 2 * ir * (ir - 1) + ip
    return 12 * n * n - 2 * ir * (ir + 1) + ip


@_jit
def _pix2xyf(n, p, ring, first):
    """healpix.pix2xyf of pixel p (of ring ``ring`` whose first pixel is ``first``)."""
    iphi = p - first + 1
    if ring < n:
        nr = ring
        kshift = 0
        face = (iphi - 1) // nr
    elif ring > 3 * n:
        nr = 4 * n - ring
        kshift = 0
        face = (iphi - 1) // nr + 8
    else:
        nr = n
        kshift = (ring + n) & 1
        ire = ring - n + 1
        irm = 2 * n + 2 - ire
        ifm = (iphi - (ire >> 1) + n - 1) // n
        ifp = (iphi - (irm >> 1) + n - 1) // n
        if ifp == ifm:
            face = ifp | 4
        elif ifp < ifm:
            face = ifp
        else:
            face = ifm + 8
    irt = ring - (2 + (face >> 2)) * n + 1
    ipt = 2 * iphi - _JPLL[face] * nr - kshift - 1
    if ipt >= 2 * n:
        ipt -= 8 * n
    return (ipt - irt) >> 1, (-ipt - irt) >> 1, face


@_jit
def _xyf2vec(n, px, py, face):
    """healpix.xyf2vec of one face point (pixel units)."""
    fx = px / n
    fy = py / n
    jr = _JRLL[face] - fx - fy
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
    t = _JPLL[face] * nr + fx - fy
    phi = (0.25 * math.pi) * t / nr if nr > 0 else 0.0
    return sth * math.cos(phi), sth * math.sin(phi), z


@_jit
def _edge_bound(n, face, fixed_is_y, fixed, lo):
    """healpix_fast._edge_bounds for one edge."""
    out = 2.0 / (n * n)
    if face < 4 or face >= 8:
        fx = fixed / n
        lo_f = lo / n
        north = face < 4
        a = 1.0 - fx if north else fx
        nr_min = 2.0 - fx - lo_f - 1.0 / n if north else fx + lo_f
        if nr_min < 1.0 and a > 0:
            out += 7.2 * a / max(nr_min, 1e-300) ** 2 / (n * n)
    return out


@_jit
def _edge_lower(fa, fb, mf):
    dd = fb - fa
    if abs(dd) <= 0.5 * mf:
        return 0.5 * (fa + fb) - 0.125 * mf - dd * dd / (2 * mf)
    return min(fa, fb)


@_jit
def _quarter(n, k):
    return min(min(k, n), 4 * n - k)


@_jit
def _tol(f, s2, ed, ds2):
    return 4 * (math.sqrt(f) + math.sqrt(s2)) * (_DP + ed) + ds2 + 1e-300


@_jit
def _cell_fs(n, i, j, shifted, c, sth, zr, unit, vc):
    """chord^2 from c to the N, W, S and E vertices of cell j of ring i (as
    healpix.vertex_lon places them), and whether the ring is polar."""
    lw = 2 * j - (0 if shifted else 1)
    ui = unit[i]
    ln = lw + 1
    ls = lw + 1
    un = ui
    us = ui
    pol = i <= n or i >= 3 * n
    if pol:  # healpix.vertex_lon
        K = _quarter(n, i)
        Kn = _quarter(n, i - 1)
        Ks = _quarter(n, i + 1)
        f = j // K
        p = j - f * K
        if Kn == K:
            ln = lw + 1
        elif Kn < K:
            ln = 2 * Kn * f + 2 * p
        else:
            ln = 2 * Kn * f + 2 * p + 2
        if Ks == K:
            ls = lw + 1
        elif Ks > K:
            ls = 2 * Ks * f + 2 * p + 2
        else:
            ls = 2 * Ks * f + 2 * p
        un = 0.25 * math.pi / max(Kn, 1) if Kn > 0 else 0.0
        us = 0.25 * math.pi / max(Ks, 1) if Ks > 0 else 0.0
    fN = _vdist_at(vc, n, i - 1, ln, sth[i - 1], zr[i - 1], ln * un, c)
    fW = _vdist_at(vc, n, i, lw, sth[i], zr[i], lw * ui, c)
    fS = _vdist_at(vc, n, i + 1, ls, sth[i + 1], zr[i + 1], ls * us, c)
    fE = _vdist_at(vc, n, i, lw + 2, sth[i], zr[i], (lw + 2) * ui, c)
    return fN, fW, fS, fE, pol


@_jit
def _decide_cell(n, i, j, pix, shifted, first, c, s2, ds2, ed, sth, zr, unit, vc):
    """healpix_fast._decide_cells for one cell (the ball's centre pixel is lit before):
    1 lit, 0 not lit, 2 left open (mpmath decides it in the reference). ``vc``: a vertex
    cache (:func:`vertex_cache`) or none (empty arrays)."""
    fN, fW, fS, fE, pol = _cell_fs(n, i, j, shifted, c, sth, zr, unit, vc)
    vmin = min(min(fN, fW), min(fS, fE))
    if vmin < s2 - _tol(vmin, s2, ed, ds2):
        return 1
    ix, iy, face = 0, 0, 0
    if pol:
        ix, iy, face = _pix2xyf(n, pix, i, first)
    # edges W-N, S-W, S-E, E-N: (fixed_is_y, fixed - its base, f_a, f_b); bit k of
    # ``opened`` says edge k is not cleared
    m0 = _edge_m(n, pol, face, True, iy + 1, ix)
    m1 = _edge_m(n, pol, face, False, ix, iy)
    m2 = _edge_m(n, pol, face, True, iy, ix)
    m3 = _edge_m(n, pol, face, False, ix + 1, iy)
    opened = (
        _not_clear(fW, fN, m0, s2, ed, ds2)
        | (_not_clear(fS, fW, m1, s2, ed, ds2) << 1)
        | (_not_clear(fS, fE, m2, s2, ed, ds2) << 2)
        | (_not_clear(fE, fN, m3, s2, ed, ds2) << 3)
    )
    if opened == 0:
        return 0
    if not pol:
        ix, iy, face = _pix2xyf(n, pix, i, first)
    fas = (fW, fS, fS, fE)
    fbs = (fN, fW, fE, fN)
    mfs = (m0, m1, m2, m3)
    for samples in (16, 256, 4096):
        for k in range(4):
            if not (opened >> k) & 1:
                continue
            r = _sample_edge(n, ix, iy, face, k, samples, c, s2, ds2, ed, fas[k], fbs[k], mfs[k])
            if r == 1:
                return 1
            if r == 0:
                opened &= ~(1 << k)
        if opened == 0:
            return 0
    return 2


@_jit
def _vdist_at(vc, n, r, l, sv, zv, ph, c):
    """:func:`_vdist` of the vertex l of ring level r (longitude ph = l times the level's
    unit, the same bits from whichever cell it is reached: _decide_cell), its coordinates
    from the cache ``vc`` = (tags, xyz) where it holds them (the same products of
    the same numbers, so the same bits), else computed (and kept there)."""
    tags, xyz = vc
    size = tags.shape[0]
    if size == 0:
        return _vdist(sv, zv, ph, c)
    key = r * (16 * n + 16) + l + 1
    h = (key * 0x9E3779B1) & (size - 1)
    if tags[h] != key:
        tags[h] = key
        xyz[h, 0] = sv * math.cos(ph)
        xyz[h, 1] = sv * math.sin(ph)
        xyz[h, 2] = zv
    vx = xyz[h, 0] - c[0]
    vy = xyz[h, 1] - c[1]
    vz = xyz[h, 2] - c[2]
    return vx * vx + vy * vy + vz * vz


@_jit
def _vdist(sv, zv, ph, c):
    """chord^2 from c to the vertex (sin theta, z, longitude)."""
    vx = sv * math.cos(ph) - c[0]
    vy = sv * math.sin(ph) - c[1]
    vz = zv - c[2]
    return vx * vx + vy * vy + vz * vz


@_jit
def _edge_m(n, pol, face, fixed_is_y, fixed, lo):
    """2.5 times the curvature bound of an edge (healpix_fast._decide_cells)."""
    if pol:
        return 2.5 * _edge_bound(n, face, fixed_is_y, float(fixed), float(lo))
    return 2.5 * 2.0 / (n * n)


@_jit
def _not_clear(fa, fb, mf, s2, ed, ds2):
    lower = _edge_lower(fa, fb, mf)
    clear = lower > s2 + _tol(max(lower, 0.0), s2, ed, ds2) + 8 * _EPS * (fa + fb + mf)
    return 0 if clear else 1


@_jit
def _sample_edge(n, ix, iy, face, k, samples, c, s2, ds2, ed, fa, fb, mf):
    """One edge-sample stage of _decide_cells on edge k (W-N, S-W, S-E, E-N):
    1 a sample is lit, 0 the edge is cleared, 2 still open."""
    fmin = min(fa, fb)
    for m in range(1, samples):
        t = m / samples
        if k == 0:
            vx, vy, vz = _xyf2vec(n, ix + t, float(iy + 1), face)
        elif k == 1:
            vx, vy, vz = _xyf2vec(n, float(ix), iy + t, face)
        elif k == 2:
            vx, vy, vz = _xyf2vec(n, ix + t, float(iy), face)
        else:
            vx, vy, vz = _xyf2vec(n, float(ix + 1), iy + t, face)
        f = (vx - c[0]) ** 2 + (vy - c[1]) ** 2 + (vz - c[2]) ** 2
        tl = 4 * (math.sqrt(f) + math.sqrt(s2)) * (_DP + ed) + ds2
        if f < s2 - tl:
            return 1
        fmin = min(fmin, f)
    lower = fmin - mf / (8 * samples * samples)
    lw0 = max(lower, 0.0)
    tle = 4 * (math.sqrt(lw0) + math.sqrt(s2)) * (_DP + ed) + ds2 + 1e-300
    return 2 if not (lower > s2 + tle) else 0


@_jit
def _arg_bound(cos_p, zc_p, rc_p, dnum, drel, zz, rr, upper):
    """Lower (upper) bound of the acos argument on z = zz (rr: its sin theta)."""
    den = rc_p * rr
    a = (cos_p - zc_p * zz) / den
    da = dnum / den + abs(a) * drel
    out = a + da if upper else a - da
    if not (math.isfinite(out) and den > 0):
        return math.inf if upper else -math.inf
    return out


@_jit
def _grow(buf, k):
    if k < buf.shape[0]:
        return buf
    new = np.empty(2 * buf.shape[0] + 16, np.int64)
    new[: buf.shape[0]] = buf
    return new


@_jit
def _ball(n, xb, yb, zb, gb, cx):
    """The per-ball steps of healpix_fast._lit_runs_fast before the rings, for one ball
    and the eye at (cx, 0, 0): (kind, ring parameters, i_min, i_max, alpha, pad); kind 0:
    go ring by ring, 1: the reference decides (near the eye centre's sphere, grazing or
    tiny caps), 3: the ball holds the eye centre (every facet lit). The ring parameters
    are those :func:`_ring` takes after ``i`` and before the ring tables; alpha is the
    cap's half-angle and pad bounds its error plus that of its centre's direction."""
    dx0 = xb - cx
    bv = dx0 - xb
    err = (xb - (dx0 - bv)) + (-cx - bv)
    errabs0 = abs(err) + 2.0**-1070
    big = max(max(abs(dx0), abs(yb)), max(abs(zb), gb))
    ex = math.frexp(big)[1]
    dx = math.ldexp(dx0, -ex)
    dy = math.ldexp(yb, -ex)
    dz = math.ldexp(zb, -ex)
    gs = math.ldexp(gb, -ex)
    errabs = math.ldexp(errabs0, -ex)
    d = math.sqrt(dx * dx + dy * dy + dz * dz)
    ed = 8 * _EPS + 4 * errabs / d
    dmg = (d - gs) * (d + gs)
    sep = 8 * _EPS * (d + gs) ** 2 + 4 * errabs * (d + gs)
    c = (0.0, 0.0, 1.0)
    none = (c, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, np.int64(0))
    if abs(dmg) <= sep or not (math.isfinite(dmg) and math.isfinite(sep)):
        return 1, none, np.int64(0), np.int64(-1), 0.0, 0.0  # near the eye centre's sphere
    if dmg < -sep:
        return 3, none, np.int64(0), np.int64(-1), 0.0, 0.0
    q = gs / d
    rdm = math.sqrt(max(dmg, 0.0))
    dcos = (4 * _EPS * d + 4 * errabs) * (d + gs) / (rdm * d)
    dcos = dcos + 4 * _EPS if math.isfinite(dcos) else 4.0
    cosa = rdm / d
    alpha = math.atan2(q, cosa)
    if dcos > 1e-9 or not alpha > 1e6 * ed:
        return 1, none, np.int64(0), np.int64(-1), 0.0, 0.0  # grazing or tiny caps
    s2 = 2 * q * q / (1 + cosa)
    ds2 = 2 * dcos + 8 * _EPS * s2
    dalpha = dcos / max(q, 1e-300) + 8 * _EPS
    rxy = math.hypot(dx, dy)
    rho_c = rxy / d
    z_c = dz / d
    theta_c = math.atan2(rxy, dz)
    phi_c = math.atan2(dy, dx)
    dphi = 4 * ed / max(rho_c, 1e-300) + 1e-12
    pad_t = dalpha + 4 * ed + 1e-12
    th_lo = min(max(theta_c - alpha - pad_t, 0.0), math.pi)
    th_hi = min(max(theta_c + alpha + pad_t, 0.0), math.pi)
    i_min = np.int64(math.floor(n * _jr_of_theta(th_lo) * (1 - 1e-12))) - 1
    i_max = np.int64(math.ceil(n * _jr_of_theta(th_hi) * (1 + 1e-12))) + 1
    i_min = min(max(i_min, np.int64(1)), 4 * n - 1)
    i_max = min(max(i_max, np.int64(1)), 4 * n - 1)
    zc_hi = math.cos(th_lo)
    zc_lo = math.cos(th_hi)
    c = (dx / d, dy / d, dz / d)
    cpix = _ang2pix(n, min(max(z_c, -1.0), 1.0) if d > 0 else 1.0, phi_c)
    dnum = dcos + 2 * ed + 4 * _EPS
    drel = 2 * ed / max(rho_c, 1e-300) + 8 * _EPS
    dph = dphi + 1e-9
    par = (c, cosa, z_c, rho_c, phi_c, zc_lo, zc_hi, dnum, drel, dph, s2, ds2, ed, cpix)
    return 0, par, i_min, i_max, alpha, pad_t


@_jit
def _ring_at(n, i, par, sth, zr, unit, first_t, nr_t, shifted_t, delta_t, o_t, vc):
    """:func:`_ring` of ring i with a ball's parameters ``par`` (:func:`_ball`)."""
    c, cosa, z_c, rho_c, phi_c, zc_lo, zc_hi, dnum, drel, dph, s2, ds2, ed, cpix = par
    return _ring(n, i, c, cosa, z_c, rho_c, phi_c, zc_lo, zc_hi, dnum, drel, dph, s2, ds2,
                 ed, cpix, sth, zr, unit, first_t[i], nr_t[i], shifted_t[i], delta_t[i],
                 o_t[i], vc)  # fmt: skip


# long: the steps of healpix_fast._lit_runs_fast for each ball in compiled code, in the same
# order, so the two read side by side
@_jit
def lit_runs_kernel(n, x, y, z, g, cx, sth, zr, unit, first_t, nr_t, shifted_t, delta_t, o_t):
    """(status, facets per ball, run starts, run lengths, run balls) for one eye.

    status[b] is 0 where the kernel decided ball b exactly, 1 where the numpy path must
    (its runs are then absent). Runs are sorted by ball, then start.
    """
    nb = x.shape[0]
    npix = 12 * n * n
    status = np.zeros(nb, np.int64)
    per = np.zeros(nb, np.int64)
    st = np.empty(64 + 8 * nb, np.int64)
    ln = np.empty(64 + 8 * nb, np.int64)
    bl = np.empty(64 + 8 * nb, np.int64)
    w = 0
    vc = (np.empty(0, np.int64), np.empty((0, 3)))  # no vertex cache
    for b in range(nb):
        w0 = w
        kind, par, i_min, i_max, _, _ = _ball(n, x[b], y[b], z[b], g[b], cx)
        if kind == 1:
            status[b] = 1  # the reference's exact branches
            continue
        if kind == 3:
            st[w], ln[w], bl[w] = 0, npix, b
            w += 1
            per[b] = npix
            continue
        ok = True
        for i in range(i_min, i_max + 1):
            kind, lo, hi = _ring_at(n, i, par, sth, zr, unit, first_t, nr_t, shifted_t,
                                    delta_t, o_t, vc)  # fmt: skip
            if kind == 2:
                ok = False
                break
            if kind == 0:
                continue
            nr = nr_t[i]
            lo_w = lo % nr
            length = hi - lo + 1
            end = lo_w + length
            st = _grow(st, w + 2)
            ln = _grow(ln, w + 2)
            bl = _grow(bl, w + 2)
            if end > nr:  # the piece at the ring's start comes first (sorted by start)
                st[w], ln[w], bl[w] = first_t[i], end - nr, b
                w += 1
                st[w], ln[w], bl[w] = first_t[i] + lo_w, nr - lo_w, b
            else:
                st[w], ln[w], bl[w] = first_t[i] + lo_w, length, b
            w += 1
            per[b] += length
        if not ok:
            w = w0
            per[b] = 0
            status[b] = 1
    return status, per, st[:w], ln[:w], bl[:w]


# long: one (ball, ring) pair of healpix_fast._lit_runs_fast in compiled code, in the same
# order, so the two read side by side
@_jit
def _ring(n, i, c, cos_p, zc_p, rc_p, pc, zc_lo, zc_hi, dnum, drel, dph, s2, ds2, ed,
          cpix, sth, zr, unit, first, nr, shifted, delta, o, vc):  # fmt: skip
    """One (ball, ring) pair of healpix_fast._lit_runs_fast: (0, 0, 0) nothing lit,
    (1, lo, hi) the lit cells lo .. hi (unwrapped), (2, 0, 0) the reference decides."""
    zb_lo, zb_hi, z_i = zr[i + 1], zr[i - 1], zr[i]
    za = max(zb_lo, zc_lo)
    zb = min(zb_hi, zc_hi)
    empty = za > zb
    zstar = zc_p / cos_p
    zs_in = zstar >= za and zstar <= zb
    rza = math.sqrt(max(1.0 - za * za, 0.0))
    rzb = math.sqrt(max(1.0 - zb * zb, 0.0))
    lo_a = _arg_bound(cos_p, zc_p, rc_p, dnum, drel, za, rza, False)
    lo_b = _arg_bound(cos_p, zc_p, rc_p, dnum, drel, zb, rzb, False)
    zs = zstar if zs_in else za
    lo_s = _arg_bound(cos_p, zc_p, rc_p, dnum, drel, zs, math.sqrt(max(1.0 - zs * zs, 0.0)), False)
    amin = min(min(lo_a, lo_b), lo_s)
    W = math.acos(min(max(amin, -1.0), 1.0)) + dph
    no_cand = empty or amin > 1.0
    full_c = W >= math.pi or amin <= -1.0
    jc_lo = np.int64(0)
    jc_hi = np.int64(-1)
    if not full_c:
        jc_lo = np.int64(math.ceil((pc - W) / delta - o - 1))
        jc_hi = np.int64(math.floor((pc + W) / delta - o))
        full_c = jc_hi - jc_lo + 1 >= nr
    hi_i = _arg_bound(cos_p, zc_p, rc_p, dnum, drel, z_i, sth[i], True)
    in_z = z_i > zc_lo and z_i < zc_hi
    has_s = in_z and hi_i < 1.0 and not no_cand
    ws = math.acos(min(max(hi_i, -1.0), 1.0)) - dph
    has_s = has_s and ws > 0
    full_s = has_s and hi_i <= -1.0
    js_lo = np.int64(0)
    js_hi = np.int64(-1)
    if has_s:
        js_lo = np.int64(math.floor((pc - ws) / delta - o - 1)) + 1
        js_hi = np.int64(math.ceil((pc + ws) / delta - o)) - 1
        has_s = js_hi >= js_lo
    full_s = full_s or (has_s and js_hi - js_lo + 1 >= nr)
    if full_s:
        js_lo, js_hi = np.int64(0), np.int64(nr - 1)
    if has_s and not full_c and not no_cand:
        js_lo = max(js_lo, jc_lo)
        js_hi = min(js_hi, jc_hi)
    has_s = has_s and js_hi >= js_lo
    if no_cand or full_s:
        if has_s and not no_cand:
            return 1, js_lo, js_hi
        return 0, 0, 0
    # the undecided cells: blocks [u1_lo, u1_hi] and [u2_lo, u2_hi] (unwrapped j)
    if full_c:
        u1_lo = js_hi + 1 if has_s else np.int64(0)
        u1_hi = js_lo + nr - 1 if has_s else np.int64(nr - 1)
        u2_lo, u2_hi = np.int64(1), np.int64(0)
    elif has_s:
        u1_lo, u1_hi, u2_lo, u2_hi = jc_lo, js_lo - 1, js_hi + 1, jc_hi
    else:
        u1_lo, u1_hi, u2_lo, u2_hi = jc_lo, jc_hi, np.int64(1), np.int64(0)
    big = np.int64(1) << 62
    lo = js_lo if has_s else big
    hi = js_hi if has_s else -big
    num = js_hi - js_lo + 1 if has_s else 0
    for blk in range(2):
        a, e = (u1_lo, u1_hi) if blk == 0 else (u2_lo, u2_hi)
        for uj in range(a, e + 1):
            jw = uj % nr
            pix = first + jw
            if pix == cpix:
                r = 1
            else:
                r = _decide_cell(n, i, jw, pix, shifted, first, c, s2, ds2, ed, sth, zr, unit,
                                 vc)  # fmt: skip
            if r == 2:
                return 2, 0, 0
            if r == 1:
                lo = min(lo, np.int64(uj))
                hi = max(hi, np.int64(uj))
                num += 1
    if num == 0:
        return 0, 0, 0
    if hi - lo + 1 != num:
        return 2, 0, 0  # not one run: the reference keeps it cell by cell
    return 1, lo, hi


@_jit
def csr_kernel(status, per, st, ln):
    """(indptr, indices) from the runs (geometry3d._runs_to_csr, compiled); no indices
    when a ball was handed back (geometry3d merges the reference's runs first)."""
    indptr = np.zeros(per.shape[0] + 1, np.int64)
    for b in range(per.shape[0]):
        indptr[b + 1] = indptr[b] + per[b]
    if status.any():
        return indptr, np.empty(0, np.int64)
    out = np.empty(indptr[-1], np.int64)
    k = 0
    for r in range(st.shape[0]):
        s = st[r]
        for j in range(ln[r]):
            out[k + j] = s + j
        k += ln[r]
    return indptr, out


def warm_inputs():
    """(nside 4, its ring tables in the kernels' argument order (sth, zr, unit, first,
    nr, shifted, delta, o), one ball): what the warm-ups compile the kernels on."""
    from eyeviz.core import healpix

    n = 4
    k = np.arange(4 * n + 1)
    sth, zr = healpix.ring_sz(n, k)
    q = np.minimum(np.minimum(k, n), 4 * n - k)
    unit = np.where(q > 0, 0.25 * math.pi / np.maximum(q, 1), 0.0)
    first, nr, shifted = healpix.ring_info(n, np.clip(k, 1, 4 * n - 1))
    delta, o = 2 * math.pi / nr, np.where(shifted, 0.0, -0.5)
    ball = tuple(np.array(v, np.float64) for v in ([0.0], [100.0], [5.0], [30.0]))
    return n, (sth, zr, unit, first, nr, shifted, delta, o), ball


def warm() -> None:
    """Compile (or load from the cache) :func:`lit_runs_kernel` and :func:`csr_kernel`
    for their one signature, on the ring tables of nside 4 (geometry3d's, built here from
    eyeviz.core.healpix)."""
    n, tabs, (x, y, z, g) = warm_inputs()
    status, per, st, ln, _ = lit_runs_kernel(n, x, y, z, g, 40.0, *tabs)
    csr_kernel(status, per, st, ln)
