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

__all__ = ["certified_kernel", "scan_kernel", "warm", "LEVELS"]

_U = 2.0**-53
_LO, _HI = 2.0**-480, 2.0**480
LEVELS = 10
_SLACK = 1e-9  # as measured_index
_SHIFT = (56, 36, 18)  # level, x, y (z in the low bits)
_jit = njit(cache=True, nogil=True)


@_jit
def certified_kernel(
    cx, cy, cz, g, bi, fi, px, py, pz, ax, ay, az, nrm, cs, sn, exact_only, seen, sure
):
    for k in range(bi.size):
        b, i = bi[k], fi[k]
        gb = g[b]
        vx, vy, vz = cx[b] - px[i], cy[b] - py[i], cz[b] - pz[i]
        mag = max(abs(vx), abs(vy), abs(vz))
        if mag == 0.0:  # c = p exactly: the lens is in the ball
            seen[k], sure[k] = True, True
            continue
        if not (_LO <= mag <= _HI and gb <= _HI) or exact_only[i]:
            seen[k], sure[k] = False, False
            continue
        a0, a1, a2 = ax[i], ay[i], az[i]
        v2 = vx * vx + vy * vy + vz * vz
        g2 = gb * gb
        da = v2 - g2
        ba = 16 * _U * (v2 + g2)
        s = vx * a0 + vy * a1 + vz * a2
        wx = vy * a2 - vz * a1
        wy = vz * a0 - vx * a2
        wz = vx * a1 - vy * a0
        q = math.sqrt(wx * wx + wy * wy + wz * wz)
        cc, ss, nn = cs[i], sn[i], nrm[i]
        vn = math.sqrt(v2) * (1 + 4 * _U) * nn
        e = s * cc + q * ss
        be = 32 * _U * vn
        m = q * cc - s * ss - gb * nn
        bm = 32 * _U * (vn + gb * nn)
        yes = da <= -ba or (e >= be and m <= -bm)
        no = da > ba and (e < -be or m > bm)
        seen[k], sure[k] = yes, yes or no


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
    """Compile (or load from the cache) both kernels for their one signature."""
    f = np.zeros(1)
    i = np.zeros(1, np.int64)
    b = np.zeros(1, np.bool_)
    certified_kernel(f, f, f, f + 1, i, i, f, f, f, f + 1, f, f, f + 1, f + 1, f, b,
                     b.copy(), b.copy())  # fmt: skip
    keys = np.zeros(1, np.int64)
    pu = np.zeros(LEVELS)
    perm = np.zeros(LEVELS, np.int64)
    scan_kernel(f, f, f, f + 1, np.zeros(3), 0.5, 0.1, keys, i, i + 1, pu, pu, pu, perm)
