"""The HEALPix ``cell`` responses' quadrature compiled (numba): a pair-by-pair scalar
transcription of :func:`eyeviz.core.responses_cells.integrate` (docs/responses.md).

The same cell and cap at each colatitude (``_Cells.parts``), the same pieces (the cut
points are computed by the reference's ``_cuts`` and passed in), the same crossings (the
12 edge gaps sampled on 17 points per piece, each sign change bisected 40 times), the same
Gauss-Legendre rules (16 nodes checked against 12) and acceptance test per piece, split
in halves up to 60 times. Only the order of the sums differs (depth first here, round by
round there): tests/core/test_kernels_cells.py compares the two pair by pair. numba
compiles without fast-math, so every operation rounds as IEEE float64 does.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

__all__ = ["cell_fraction_kernel", "warm"]

_jit = njit(cache=True, nogil=True)
_TOL = 1e-12  # as responses_cells
_THIN = 1e-11
_FLOOR = 1e-14
_MAX_DEPTH = 60
_SAMPLES = 17  # as responses_cells
_BISECT = 40
_TWO_PI = 2 * math.pi
_SQ6 = math.sqrt(6.0)
_Z23 = 2.0 / 3.0


@_jit
def _parts(t, phf, yc, xc, gap_pole, delta, tc, b):
    """(lo, hi, omega, whole, none) at colatitude t, as ``_Cells.parts``."""
    z = math.cos(t)
    az = abs(z)
    polar = az > _Z23
    sig = _SQ6 * math.sin(min(t, math.pi - t) / 2) if polar else 1.0
    depth = math.pi / 4 * sig if polar else math.pi / 2 - 3 * math.pi / 8 * az
    sz = 1.0 if z > 0 else (-1.0 if z < 0 else 0.0)
    ys = sz * (math.pi / 2 - depth)
    gap = gap_pole if ys * yc > 0 else math.inf
    hw = min(delta - abs(ys - yc), gap + depth)
    hw = max(hw, 0.0)
    if sig > 0:
        lo = phf + (xc - hw - phf) / sig
        hi = phf + (xc + hw - phf) / sig
    else:
        lo = phf - math.pi / 4
        hi = phf + math.pi / 4
    whole = (t <= b - tc) or (t >= 2 * math.pi - tc - b) or (b >= math.pi)
    none = (not whole) and ((t >= tc + b) or (t <= tc - b))
    if whole:
        omega = math.pi
    elif none:
        omega = 0.0
    else:
        s = (t + tc + b) / 2
        den = math.sin(s) * math.sin(s - b)
        num = math.sin(s - t) * math.sin(s - tc)
        q = num / den if den != 0.0 else (math.copysign(math.inf, num) if num != 0.0 else math.nan)
        if q != q:
            omega = 0.0
        else:
            omega = 2 * math.atan(math.sqrt(max(q, 0.0)))
    return lo, hi, omega, whole, none


@_jit
def _width(t, phf, yc, xc, gap_pole, delta, tc, pc, b):
    lo, hi, omega, whole, none = _parts(t, phf, yc, xc, gap_pole, delta, tc, b)
    if whole:
        return hi - lo
    if none:
        return 0.0
    out = 0.0
    for sh in (-_TWO_PI, 0.0, _TWO_PI):
        v = min(hi, pc + omega + sh) - max(lo, pc - omega + sh)
        if v > 0:
            out += v
    return min(out, hi - lo)


@_jit
def _gaps(t, out, phf, yc, xc, gap_pole, delta, tc, pc, b):
    """The 12 edge gaps at t into ``out``: pc + sg omega + sh - (lo or hi), the
    reference's order (sg outer, then the shift, then lo/hi)."""
    lo, hi, omega, _, _ = _parts(t, phf, yc, xc, gap_pole, delta, tc, b)
    e = 0
    for sg in (-1.0, 1.0):
        for sh in (-_TWO_PI, 0.0, _TWO_PI):
            out[e] = pc + sg * omega + sh - lo
            out[e + 1] = pc + sg * omega + sh - hi
            e += 2


@_jit
def _neg(v):
    """np.signbit for a non-NaN float."""
    return v < 0 or (v == 0 and math.copysign(1.0, v) < 0)


@_jit
def _piece(lo, hi, x, w, phf, yc, xc, gap_pole, delta, tc, pc, b):
    m, h = (lo + hi) / 2, (hi - lo) / 2
    acc = 0.0
    for i in range(x.size):
        s = (x[i] + 1) * math.pi / 2
        t = m - h * math.cos(s)
        f = _width(t, phf, yc, xc, gap_pole, delta, tc, pc, b) * math.sin(t)
        acc += f * (h * math.sin(s)) * w[i]
    return acc * (math.pi / 2)


# long: one pair's crossings, then its adaptive quadrature on an explicit stack, in one loop
# body so that numba keeps every scalar in registers; split, a dozen scalars would pass
@_jit
def cell_fraction_kernel(pts, phf, yc, xc, gap_pole, delta, tc, pc, b, area, xf, wf, xc_, wc_, out):
    """Per pair k: out[k] the share (not clipped); returns the number of pairs whose
    pieces did not reach the tolerance within 60 halvings (0: all did)."""
    failed = 0
    cut = np.empty(pts.shape[1] + 12 * _SAMPLES)
    g0 = np.empty(12)
    g1 = np.empty(12)
    gm = np.empty(12)
    stack_lo = np.empty(2 * _MAX_DEPTH + 4)
    stack_hi = np.empty(2 * _MAX_DEPTH + 4)
    stack_d = np.empty(2 * _MAX_DEPTH + 4, np.int64)
    for k in range(pts.shape[0]):
        a1, a2, a3, a4, a5, a6 = phf[k], yc[k], xc[k], gap_pole[k], tc[k], pc[k]
        bk = b[k]
        top = pts[k, 0]
        bot = top
        for j in range(pts.shape[1]):
            if pts[k, j] == pts[k, j]:
                bot = pts[k, j]
        span = bot - top
        total = 0.0
        for j in range(pts.shape[1] - 1):
            plo, phi_ = pts[k, j], pts[k, j + 1]
            if not (plo == plo and phi_ == phi_ and phi_ > plo):
                continue
            # the piece's crossings: sign changes of the 12 gaps on _SAMPLES points
            nc = 0
            cut[nc] = plo
            nc += 1
            cut[nc] = phi_
            nc += 1
            m0, h0 = (plo + phi_) / 2, (phi_ - plo) / 2
            _gaps(m0 - h0, g0, a1, a2, a3, a4, delta, a5, a6, bk)
            for i in range(1, _SAMPLES):
                s1 = math.pi * i / (_SAMPLES - 1)
                _gaps(m0 - h0 * math.cos(s1), g1, a1, a2, a3, a4, delta, a5, a6, bk)
                for e in range(12):
                    if _neg(g0[e]) != _neg(g1[e]):
                        sa_, sb_ = math.pi * (i - 1) / (_SAMPLES - 1), s1
                        neg_a = _neg(g0[e])
                        for _ in range(_BISECT):
                            sm = (sa_ + sb_) / 2
                            _gaps(m0 - h0 * math.cos(sm), gm, a1, a2, a3, a4, delta, a5, a6, bk)
                            if _neg(gm[e]) == neg_a:
                                sa_ = sm
                            else:
                                sb_ = sm
                        cut[nc] = m0 - h0 * math.cos((sa_ + sb_) / 2)
                        nc += 1
                for e in range(12):
                    g0[e] = g1[e]
            cs = np.sort(cut[:nc])
            for i in range(nc - 1):
                lo0, hi0 = cs[i], cs[i + 1]
                if not hi0 > lo0:
                    continue
                sp = 0
                stack_lo[0], stack_hi[0], stack_d[0] = lo0, hi0, 0
                sp = 1
                while sp > 0:
                    sp -= 1
                    lo, hi, d = stack_lo[sp], stack_hi[sp], stack_d[sp]
                    fine = _piece(lo, hi, xf, wf, a1, a2, a3, a4, delta, a5, a6, bk)
                    coarse = _piece(lo, hi, xc_, wc_, a1, a2, a3, a4, delta, a5, a6, bk)
                    good = abs(fine - coarse) <= area * max(_TOL * (hi - lo) / span, _FLOOR)
                    good = good or (hi - lo) <= _THIN * span
                    if good:
                        total += fine
                    elif d + 1 >= _MAX_DEPTH:
                        failed += 1
                        sp = 0
                    else:
                        mid = (lo + hi) / 2
                        stack_lo[sp], stack_hi[sp], stack_d[sp] = mid, hi, d + 1
                        stack_lo[sp + 1], stack_hi[sp + 1], stack_d[sp + 1] = lo, mid, d + 1
                        sp += 2
        out[k] = total / area
    return failed


def warm() -> None:
    """Compile (or load from the cache) :func:`cell_fraction_kernel` for its one
    signature: a cap's edge across one nside-4 cell (any numbers would do)."""
    one = np.ones(1)
    x = np.polynomial.legendre.leggauss(4)
    pts = np.array([[1.0, 1.05, 1.1] + [math.nan] * 8])
    out = np.zeros(1)
    cell_fraction_kernel(
        pts, 0.8 * one, 0.5 * one, 0.8 * one, math.inf * one, 0.2, 1.05 * one, 0.8 * one,
        0.03 * one, 0.26, x[0], x[1], x[0], x[1], out,
    )  # fmt: skip
