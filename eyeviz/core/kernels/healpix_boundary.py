"""The boundary cells' decision of the compiled lit sets (numba): is a HEALPix cell's
closure within a cap?

:func:`eyeviz.core.healpix_fast._decide_cells` (docs/spherical.md, step 4) for one cell,
in scalar code: the chord^2 from the cap's centre to the cell's four vertices (from the
per-ring tables and integer longitudes, as ``healpix.vertex_lon`` places them), lit when
one lies inside by the rounding bound, not lit when every edge's interpolation bound
clears the cap by it, else the edges sampled (16, 256, then 4096 points, the same
bound); a cell still open is left to the reference. :mod:`.healpix_lit` and
:mod:`.healpix_match` call these functions (most are inlined into their kernels, so both
stamp their numba cache with this file's source: :func:`stamp_with`).
"""

from __future__ import annotations

import hashlib
import math
import os

import numpy as np
from numba import njit
from numba.core import caching

__all__ = ["stamp_with", "warm"]

_EPS = 2.0**-52
_DP = 64 * _EPS
_JRLL = np.array([2, 2, 2, 2, 3, 3, 3, 3, 4, 4, 4, 4], np.int64)
_JPLL = np.array([1, 3, 5, 7, 0, 2, 4, 6, 1, 3, 5, 7], np.int64)
_jit = njit(cache=True, error_model="numpy", nogil=True)
#: inlined into the caller's numba IR: a call that passes arrays costs their reference
#: counts (atomic operations), which in the per-cell and per-ring loops cost more than
#: the arithmetic (measured: 1.4x on the lit sets)
_jit_inline = njit(cache=True, error_model="numpy", nogil=True, inline="always")

#: module file -> the other source files its numba cache is stamped with (stamp_with)
_STAMPED: dict[str, tuple[str, ...]] = {}


class _Stamped(caching.InTreeCacheLocator):
    """numba's in-tree cache for the modules of :data:`_STAMPED`, stamped with a sha256
    of their source and their callees' (numba's own stamp is the file's time and size)."""

    @classmethod
    def from_function(cls, py_func, py_file):
        if os.path.abspath(py_file) not in _STAMPED:
            return None
        return super().from_function(py_func, py_file)

    def get_source_stamp(self):
        digest = hashlib.sha256()
        here = os.path.abspath(self._py_file)
        for path in (here, *_STAMPED[here]):
            with open(path, "rb") as f:
                digest.update(f.read())
        return digest.hexdigest()


def stamp_with(module_file: str, *sources: str) -> None:
    """Stamp numba's in-tree cache of the kernels of ``module_file`` with the source of
    ``sources`` as well as its own. numba checks only the caller's file: a kernel that
    inlines or calls another module's functions would otherwise keep a stale copy of
    them after an edit there. Call it at the top of the kernel module, before its first
    decorated function (numba picks a function's cache locator when it is decorated)."""
    _STAMPED[os.path.abspath(module_file)] = tuple(os.path.abspath(s) for s in sources)
    if _Stamped not in caching.CacheImpl._locator_classes:
        caching.CacheImpl._locator_classes.insert(0, _Stamped)


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


@_jit_inline
def _cell_lons(n, i, j, shifted, ui):
    """The longitude indices of the W, N and S vertices of cell j of ring i (as
    healpix.vertex_lon places them; E is W + 2), the units of N's and S's ring levels
    (W's is ``ui``), and whether the ring is polar."""
    lw = 2 * j - (0 if shifted else 1)
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
    return lw, ln, ls, un, us, pol


@_jit_inline
def _cell_fs(n, i, j, shifted, c, sth, zr, unit, vc):
    """chord^2 from c to the N, W, S and E vertices of cell j of ring i, and whether the
    ring is polar."""
    ui = unit[i]
    lw, ln, ls, un, us, pol = _cell_lons(n, i, j, shifted, ui)
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
    return _decide_fs(n, i, pix, first, c, s2, ds2, ed, fN, fW, fS, fE, pol)


@_jit_inline
def _decide_fs(n, i, pix, first, c, s2, ds2, ed, fN, fW, fS, fE, pol):
    """:func:`_decide_cell` from the chord^2 to the cell's vertices."""
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


@_jit_inline
def _vdist_at(vc, n, r, l, sv, zv, ph, c):
    """:func:`_vdist` of the vertex l of ring level r (longitude ph = l times the level's
    unit, the same bits from whichever cell it is reached: _decide_cell), its coordinates
    from the cache ``vc`` = (tags, xyz) where it holds them (the same products of
    the same numbers, so the same bits), else computed (and kept there)."""
    if vc is None:  # compiled away: no cache, and no reference counts of its arrays
        return _vdist(sv, zv, ph, c)
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


@_jit_inline
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


def warm() -> None:
    """Nothing to compile here: these functions are compiled into the kernels of
    :mod:`.healpix_lit` and :mod:`.healpix_match` (and cached with them)."""
