"""One feature at a time in Python floats: the fast path of :class:`EyePair` for live drags.

A drag moves one feature per frame; the vectorised methods of
:mod:`eyeviz.core.geometry` pay ~40-100 µs of numpy call overhead whatever the number of
features. These functions decide the same predicates for a single feature in ~2-5 µs and
give the same answers: each one evaluates the vectorised fast path's own expression (the
same IEEE operations in the same order, or for Eq. 11 the same libm-accurate atan2 and
asin, whose few-ulp errors the rounding bound already covers) and checks the same
rounding bound. Whatever the bound cannot clear is not guessed:

- :func:`intervals_one` returns ``None`` and the caller asks ``EyePair.intervals`` (whose
  per-element path and exact fallback decide it);
- :func:`in_bfv_one` and :func:`overlaps_one` hand it to the same exact predicates of
  :mod:`eyeviz.core.exact` the vectorised methods use.

Inputs are converted to float64 and must be finite with g > 0 (:func:`intervals_one`
returns ``None`` otherwise, so the vectorised method refuses them with its own message).
"""

from __future__ import annotations

import math

from eyeviz.core import exact
from eyeviz.core.geometry import _Q_SAFE, _TINY_SCALE, _TOL_BASE, _TOL_GRAZE, _U, EyePair

__all__ = ["in_bfv_one", "intervals_one", "overlaps_one", "valid_feature"]


def valid_feature(x: float, y: float, g: float) -> bool:
    """Finite x, y, g with g > 0: what ``EyePair``'s methods accept."""
    return math.isfinite(x) and math.isfinite(y) and math.isfinite(g) and g > 0


def intervals_one(pair: EyePair, x: float, y: float, g: float) -> tuple[int, int, int, int] | None:
    """(LA, RA, LB, RB) of one feature (Prop. 2, Eq. 11), or ``None`` when the rounding bound
    of ``EyePair._fast_intervals`` does not clear it (an endpoint within the bound of a sector
    boundary, g / r_E > 0.75, r_E^2 out of range, or invalid input): then call
    ``pair.intervals``, which decides such features exactly."""
    try:
        x, y, g = float(x), float(y), float(g)  # float32 or int inputs: float64 arithmetic
    except (TypeError, ValueError, OverflowError):
        return None
    if not valid_feature(x, y, g):
        return None
    k, m = pair._k, pair.m
    tol0 = (_TOL_BASE + _TOL_GRAZE / (1 - _Q_SAFE)) * _U * m
    yy = y * y
    out: list[int] = []
    for cx in (-pair.h, pair.h):
        dx = x - cx
        r2 = dx * dx + yy
        if not 1e-290 <= r2 <= 1e300:
            return None
        q = g / math.sqrt(r2)
        if not q <= _Q_SAFE:
            return None
        pk = math.atan2(y, dx) * k
        ak = math.asin(q) * k
        t_lo, t_hi = pk - ak, pk + ak
        f_lo, f_hi = math.floor(t_lo), math.floor(t_hi)
        c_lo, c_hi = t_lo - f_lo, t_hi - f_hi
        if not (tol0 <= c_lo <= 1 - tol0 and tol0 <= c_hi <= 1 - tol0):
            return None
        # phi in (-pi, pi] and alpha <= pi/2: f_lo > -m, one wrap at most
        L = f_lo + m if f_lo < 0 else f_lo
        out += (L, f_hi - f_lo + L)
    return out[0], out[1], out[2], out[3]


def in_bfv_one(pair: EyePair, x: float, y: float, g: float) -> bool:
    """The closed disc lies in the binocular field of view (Prop. 4, Eq. 17): the
    expression and bound of ``EyePair.in_bfv``, the exact predicate where it is near."""
    h, l = pair.h, pair.l
    x, y, g = float(x), float(y), float(g)
    w = math.sqrt((h - l) * (h + l))
    wy, lx, gh = w * y, l * x, g * h
    right = wy - lx - gh
    left = wy + lx - gh
    scale = abs(wy) + abs(lx) + abs(gh)
    tol = 16 * _U * scale
    near = abs(right) <= tol or abs(left) <= tol
    near = near or not scale >= _TINY_SCALE or not math.isfinite(scale)
    if near or not 2.0**-400 < w < 2.0**400:
        return bool(exact.exact_in_bfv(x, y, g, h, l))
    return right >= 0 and left >= 0


def overlaps_one(pair: EyePair, x: float, y: float, g: float) -> tuple[bool, bool]:
    """Per eye (A, B): the closed feature disc meets the closed eye disc of radius l; the
    expression and bound of ``EyePair.overlaps_eye``, the exact predicate where it is near."""
    x, y, g = float(x), float(y), float(g)
    res = []
    for cx in (-pair.h, pair.h):
        dx = x - cx
        d2 = dx * dx + y * y
        s = g + pair.l
        rhs = s * s
        tot = d2 + rhs
        near = abs(d2 - rhs) <= 16 * _U * tot
        if near or not tot >= _TINY_SCALE or not math.isfinite(tot):
            res.append(bool(exact.exact_overlaps(x, y, g, cx, pair.l)))
        else:
            res.append(d2 <= rhs)
    return res[0], res[1]
