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

from eyeviz.core.kernels import healpix_boundary
from eyeviz.core.kernels.healpix_boundary import (
    _EPS,
    _cell_lons,
    _decide_fs,
    _jit,
    _jit_inline,
    _vdist_at,
    stamp_with,
)

# before the first kernel: this module's cache carries healpix_boundary.py's source too
stamp_with(__file__, healpix_boundary.__file__)

__all__ = ["lit_runs_kernel", "csr_kernel", "empty_indices", "warm"]

_HALF_PI = 0.5 * math.pi
_SQ6 = math.sqrt(6.0)


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
def _arg_bound(cos_p, zc_p, rc_p, dnum, drel, zz, rr, upper):
    """Lower (upper) bound of the acos argument on z = zz (rr: its sin theta)."""
    den = rc_p * rr
    a = (cos_p - zc_p * zz) / den
    da = dnum / den + abs(a) * drel
    out = a + da if upper else a - da
    if not (math.isfinite(out) and den > 0):
        return math.inf if upper else -math.inf
    return out


@_jit_inline
def _cap_steps(xb, yb, zb, gb, cx):
    """The first steps of :func:`_ball`, shared with healpix_match._cap (the same
    operations, so the same bits): the ball's centre relative to the eye at (cx, 0, 0),
    scaled by a power of two, and its cap. Returns (kind, dx, dy, dz, d, ed, q, cosa,
    alpha, dcos, s2, ds2, dalpha); kind 0: a cap, 1: the reference decides (near the eye
    centre's sphere, grazing or tiny caps), 3: the ball holds the eye centre; past kind,
    only dx, dy, dz, d and ed are set where kind is not 0."""
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
    if abs(dmg) <= sep or not (math.isfinite(dmg) and math.isfinite(sep)):
        return 1, dx, dy, dz, d, ed, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    if dmg < -sep:
        return 3, dx, dy, dz, d, ed, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    q = gs / d
    rdm = math.sqrt(max(dmg, 0.0))
    dcos = (4 * _EPS * d + 4 * errabs) * (d + gs) / (rdm * d)
    dcos = dcos + 4 * _EPS if math.isfinite(dcos) else 4.0
    cosa = rdm / d
    alpha = math.atan2(q, cosa)
    if dcos > 1e-9 or not alpha > 1e6 * ed:
        return 1, dx, dy, dz, d, ed, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    s2 = 2 * q * q / (1 + cosa)
    ds2 = 2 * dcos + 8 * _EPS * s2
    dalpha = dcos / max(q, 1e-300) + 8 * _EPS
    return 0, dx, dy, dz, d, ed, q, cosa, alpha, dcos, s2, ds2, dalpha


@_jit
def _ball(n, xb, yb, zb, gb, cx):
    """The per-ball steps of healpix_fast._lit_runs_fast before the rings, for one ball
    and the eye at (cx, 0, 0): (kind, ring parameters, i_min, i_max, alpha, pad); kind 0:
    go ring by ring, 1: the reference decides (near the eye centre's sphere, grazing or
    tiny caps), 3: the ball holds the eye centre (every facet lit). The ring parameters
    are those :func:`_ring` takes after ``i`` and before the ring tables; alpha is the
    cap's half-angle and pad bounds its error plus that of its centre's direction."""
    kind, dx, dy, dz, d, ed, q, cosa, alpha, dcos, s2, ds2, dalpha = _cap_steps(xb, yb, zb, gb, cx)
    if kind != 0:
        c = (0.0, 0.0, 1.0)
        none = (c, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, np.int64(0))
        return kind, none, np.int64(0), np.int64(-1), 0.0, 0.0
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
def _lower(par, zz):
    """The lower bound of the acos argument (:func:`_arg_bound`) on z = zz."""
    c, cosa, z_c, rho_c, phi_c, zc_lo, zc_hi, dnum, drel, dph, s2, ds2, ed, cpix = par
    return _arg_bound(cosa, z_c, rho_c, dnum, drel, zz, math.sqrt(max(1.0 - zz * zz, 0.0)), False)


@_jit_inline
def _band_lower(par, zz, k, zk, memo):
    """:func:`_lower` at zz (the band edge max(zr[k], zc_lo) or min(zr[k], zc_hi)),
    taken from ``memo`` (the last two levels k computed unclipped: k1, v1, k2, v2) when
    zz is zr[k] and k is there (the same inputs, so the same bits), else computed."""
    k1, v1, k2, v2 = memo
    if zz != zk:
        return _lower(par, zz), memo
    if k == k2:
        return v2, memo
    if k == k1:
        return v1, memo
    v = _lower(par, zz)
    return v, (k2, v2, k, v)


_NO_MEMO = (np.int64(-9), 0.0, np.int64(-9), 0.0)


@_jit_inline
def _ring_at(n, i, par, sth, zr, unit, first_t, nr_t, shifted_t, delta_t, o_t, vc, memo):
    """:func:`_ring` of ring i with a ball's parameters ``par`` (:func:`_ball`)."""
    c, cosa, z_c, rho_c, phi_c, zc_lo, zc_hi, dnum, drel, dph, s2, ds2, ed, cpix = par
    za = max(zr[i + 1], zc_lo)
    zb = min(zr[i - 1], zc_hi)
    if za > zb:
        return 0, np.int64(0), np.int64(0), memo
    # level i - 1 first: ring i - 2 computed it, ring i + 1 looks up level i + 1
    lo_b, memo = _band_lower(par, zb, i - 1, zr[i - 1], memo)
    lo_a, memo = _band_lower(par, za, i + 1, zr[i + 1], memo)
    zstar = z_c / cosa
    lo_s = lo_a
    if zstar >= za and zstar <= zb and zstar != za:
        lo_s = _lower(par, zstar)
    amin = min(min(lo_a, lo_b), lo_s)
    if amin > 1.0:
        return 0, np.int64(0), np.int64(0), memo
    kind, lo, hi = _ring(n, i, c, cosa, z_c, rho_c, phi_c, zc_lo, zc_hi, dnum, drel, dph, s2,
                         ds2, ed, cpix, sth, zr, unit, first_t[i], nr_t[i], shifted_t[i],
                         delta_t[i], o_t[i], vc, amin)  # fmt: skip
    return kind, lo, hi, memo


@_jit
def _grown(buf, k):
    new = np.empty(max(2 * buf.shape[0], k) + 16, np.int64)
    new[: buf.shape[0]] = buf
    return new


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
    vc = None  # no vertex cache (match_kernel passes one)
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
        need = w + 2 * (i_max - i_min + 1) + 2
        if need > st.shape[0]:
            st, ln, bl = _grown(st, need), _grown(ln, need), _grown(bl, need)
        ok = True
        memo = _NO_MEMO
        for i in range(i_min, i_max + 1):
            kind, lo, hi, memo = _ring_at(n, i, par, sth, zr, unit, first_t, nr_t, shifted_t,
                                          delta_t, o_t, vc, memo)  # fmt: skip
            if kind == 2:
                ok = False
                break
            if kind == 0:
                continue
            nr = nr_t[i]
            lo_w = lo % nr
            length = hi - lo + 1
            end = lo_w + length
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
@_jit_inline
def _ring(n, i, c, cos_p, zc_p, rc_p, pc, zc_lo, zc_hi, dnum, drel, dph, s2, ds2, ed,
          cpix, sth, zr, unit, first, nr, shifted, delta, o, vc, amin):  # fmt: skip
    """One (ball, ring) pair of healpix_fast._lit_runs_fast: (0, 0, 0) nothing lit,
    (1, lo, hi) the lit cells lo .. hi (unwrapped), (2, 0, 0) the reference decides."""
    z_i = zr[i]
    W = math.acos(max(amin, -1.0)) + dph
    full_c = W >= math.pi or amin <= -1.0
    jc_lo = np.int64(0)
    jc_hi = np.int64(-1)
    if not full_c:
        jc_lo = np.int64(math.ceil((pc - W) / delta - o - 1))
        jc_hi = np.int64(math.floor((pc + W) / delta - o))
        full_c = jc_hi - jc_lo + 1 >= nr
    hi_i = _arg_bound(cos_p, zc_p, rc_p, dnum, drel, z_i, sth[i], True)
    has_s = z_i > zc_lo and z_i < zc_hi and hi_i < 1.0
    full_s = False
    js_lo = np.int64(0)
    js_hi = np.int64(-1)
    if has_s:
        ws = math.acos(max(hi_i, -1.0)) - dph
        has_s = ws > 0
        full_s = has_s and hi_i <= -1.0
        if has_s:
            js_lo = np.int64(math.floor((pc - ws) / delta - o - 1)) + 1
            js_hi = np.int64(math.ceil((pc + ws) / delta - o)) - 1
            has_s = js_hi >= js_lo
    full_s = full_s or (has_s and js_hi - js_lo + 1 >= nr)
    if full_s:
        js_lo, js_hi = np.int64(0), np.int64(nr - 1)
    if has_s and not full_c:
        js_lo = max(js_lo, jc_lo)
        js_hi = min(js_hi, jc_hi)
    has_s = has_s and js_hi >= js_lo
    if full_s:
        if has_s:
            return 1, js_lo, js_hi
        return 0, np.int64(0), np.int64(0)
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
    ui = unit[i]
    s_i, z_i = sth[i], zr[i]
    for blk in range(2):
        a, e = (u1_lo, u1_hi) if blk == 0 else (u2_lo, u2_hi)
        jw = a % nr
        have = False  # fE of the cell before (this cell's fW: the same vertex and bits)
        fE = 0.0
        for uj in range(a, e + 1):
            pix = first + jw
            lw, ln, ls, un, us, pol = _cell_lons(n, i, jw, shifted, ui)
            fN = _vdist_at(vc, n, i - 1, ln, sth[i - 1], zr[i - 1], ln * un, c)
            fW = fE if have else _vdist_at(vc, n, i, lw, s_i, z_i, lw * ui, c)
            fS = _vdist_at(vc, n, i + 1, ls, sth[i + 1], zr[i + 1], ls * us, c)
            fE = _vdist_at(vc, n, i, lw + 2, s_i, z_i, (lw + 2) * ui, c)
            have = True
            r = 1  # the centre's cell is lit
            if pix != cpix:
                r = _decide_fs(n, i, pix, first, c, s2, ds2, ed, fN, fW, fS, fE, pol)
            if r == 2:
                return 2, np.int64(0), np.int64(0)
            if r == 1:
                lo = min(lo, np.int64(uj))
                hi = max(hi, np.int64(uj))
                num += 1
            jw += 1
            if jw == nr:
                jw = 0
                have = False  # the vertex past the wrap has another longitude's bits
    if num == 0:
        return 0, np.int64(0), np.int64(0)
    if hi - lo + 1 != num:
        return 2, np.int64(0), np.int64(0)  # not one run: the reference keeps it cell by cell
    return 1, lo, hi


@_jit
def csr_kernel(per, st, ln, out):
    """The CSR indptr of the runs (geometry3d._runs_to_csr, compiled), their indices
    written into ``out`` (per.sum() int64, the caller's: :func:`empty_indices`)."""
    indptr = np.zeros(per.shape[0] + 1, np.int64)
    for b in range(per.shape[0]):
        indptr[b + 1] = indptr[b] + per[b]
    k = 0
    for r in range(st.shape[0]):
        s = st[r]
        for j in range(ln[r]):
            out[k + j] = s + j
        k += ln[r]
    return indptr


#: Indices up to this many come from numpy's allocator, which asks Linux for huge pages
#: (madvise) for arrays over 4 MB: fresh 4 KiB pages' faults cost more than writing the
#: indices (nside 180, 1000 balls: 13 -> 6 us a ball). Past about 128 MB the kernel
#: compacts memory to find huge pages on a process's first use, 2-3x slower than small
#: pages here (measured: 9-11 ns an index against 3.5-4), so larger ones take numba's.
HUGE_PAGES_UP_TO = 1 << 24


def empty_indices(k: int) -> np.ndarray:
    """An uninitialised int64 array of k indices for :func:`csr_kernel`."""
    return np.empty(k, np.int64) if k <= HUGE_PAGES_UP_TO else _empty_small_pages(k)


@_jit
def _empty_small_pages(k):
    return np.empty(k, np.int64)


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
    csr_kernel(per, st, ln, empty_indices(int(per.sum())))
    _empty_small_pages(1)
