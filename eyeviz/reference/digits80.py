"""High-precision reference for the geometry: Eq. 11 evaluated with mpmath.

An independent, slow implementation used to judge the fast core and the paper's literal
float formulas. Each feature is converted from its float inputs exactly, Eq. 11 is
evaluated with ``dps`` significant digits (default 80) beyond those needed to hold the
inputs exactly, and a value within ``10**-(dps - 20)`` of an integer n is taken to be n:
a tangent direction exactly on a boundary belongs to the sector that starts there (Eq. 8).
"""

from __future__ import annotations

from fractions import Fraction

import mpmath
import numpy as np

__all__ = ["reference_interval", "reference_intervals"]


def reference_interval(
    x: float, y: float, g: float, cx: float, m: int, dps: int = 80
) -> tuple[int, int]:
    """Normalised (L, R) of one eye for one feature; whole eye is (0, m - 1)."""
    # enough digits to hold x - cx, y and g exactly, then dps more: a value that is not a
    # tie lies further from an integer than inputs this fine can come
    bits = max(
        max(abs(q.numerator).bit_length(), q.denominator.bit_length())
        for q in (Fraction(x) - Fraction(cx), Fraction(y), Fraction(g))
    )
    dps = dps + int(bits * 0.302) + 10
    with mpmath.workdps(dps):
        dx = mpmath.mpf(x) - mpmath.mpf(cx)
        dy = mpmath.mpf(y)
        gg = mpmath.mpf(g)
        r2 = dx * dx + dy * dy
        if r2 <= gg * gg:
            return 0, m - 1
        r = mpmath.sqrt(r2)
        phi = mpmath.atan2(dy, dx)
        if phi < 0:
            phi += 2 * mpmath.pi
        alpha = mpmath.asin(gg / r)
        k = m / (2 * mpmath.pi)
        tie = mpmath.mpf(10) ** (20 - dps)
        floors = []
        for t in ((phi - alpha) * k, (phi + alpha) * k):
            n = mpmath.nint(t)
            floors.append(int(n) if abs(t - n) < tie else int(mpmath.floor(t)))
    lo, hi = floors
    L = lo % m
    return L, hi - lo + L


def reference_intervals(eyes, x, y, g, dps: int = 80) -> tuple[np.ndarray, ...]:
    """(LA, RA, LB, RB) like :meth:`EyePair.intervals`, one feature at a time."""
    xs, ys, gs = (np.asarray(v, dtype=np.float64).ravel() for v in np.broadcast_arrays(x, y, g))
    out = np.empty((4, xs.size), np.int64)
    for i, (xi, yi, gi) in enumerate(zip(xs.tolist(), ys.tolist(), gs.tolist(), strict=True)):
        out[0:2, i] = reference_interval(xi, yi, gi, -eyes.h, eyes.m, dps)
        out[2:4, i] = reference_interval(xi, yi, gi, eyes.h, eyes.m, dps)
    return tuple(out)
