"""Brute-force reference of the measured eyes' lit sets and lens overlaps (tests only).

Independent of :mod:`eyeviz.core.measured_fast` and :mod:`eyeviz.core.measured_exact`:
every facet of the eye, the textbook distance from a point to a closed circular cone
(theta = angle(v, a) from atan2(|v x a|, v . a), alpha = dr / 2):

    dist = 0                      if theta <= alpha,
           |v| sin(theta - alpha)  if alpha < theta < alpha + pi / 2,
           |v|                     otherwise (the apex is nearest),

and "seen" iff dist <= g. A float64 screen decides the pairs whose |dist - g| exceeds
1e-7 (|v| + g) (more than 10^8 times its rounding error) when the components of v and a
lie in [1e-140, 1e140] and g <= 1e140; every other pair is evaluated in mpmath at 60 and
then 300 digits, and a pair still within 10^-280 (|v| + g) of a tie raises instead of
guessing. |v| <= g (the lens in the ball) is decided first, in rationals: it is the only
tie that occurs exactly.
"""

from __future__ import annotations

from fractions import Fraction

import mpmath
import numpy as np

__all__ = ["reference_lit", "reference_lens_in_ball"]


def _dist_mp(c, g, p, a, dr, dps: int):
    with mpmath.workdps(dps):
        v = [mpmath.mpf(float(ci)) - mpmath.mpf(float(pi)) for ci, pi in zip(c, p, strict=True)]
        ax = [mpmath.mpf(float(x)) for x in a]
        dot = sum(vi * ai for vi, ai in zip(v, ax, strict=True))
        cr = (
            v[1] * ax[2] - v[2] * ax[1],
            v[2] * ax[0] - v[0] * ax[2],
            v[0] * ax[1] - v[1] * ax[0],
        )
        theta = mpmath.atan2(mpmath.sqrt(sum(x * x for x in cr)), dot)
        vn = mpmath.sqrt(sum(x * x for x in v))
        beyond = theta - mpmath.mpf(float(dr)) / 2
        if beyond <= 0:
            dist = mpmath.mpf(0)
        elif beyond < mpmath.pi / 2:
            dist = vn * mpmath.sin(beyond)
        else:
            dist = vn
        return dist - mpmath.mpf(float(g)), vn + mpmath.mpf(float(g))


def _seen_mp(c, g, p, a, dr) -> bool:
    v2 = sum((Fraction(float(ci)) - Fraction(float(pi))) ** 2 for ci, pi in zip(c, p, strict=True))
    if v2 <= Fraction(float(g)) ** 2:
        return True
    for dps, tol in ((60, 45), (300, 280)):
        diff, scale = _dist_mp(c, g, p, a, dr, dps)
        with mpmath.workdps(dps):
            if abs(diff) > scale * mpmath.mpf(10) ** (-tol):
                return bool(diff < 0)
    raise ArithmeticError(f"reference: cannot decide ball {c}, {g} against facet {p}, {a}")


def _screen(c, g, pos, ax, acc):
    """Float64 distances minus g and their decision margins for one ball and all facets."""
    v = np.asarray(c, dtype=np.float64)[None, :] - pos
    vn = np.sqrt((v * v).sum(axis=1))
    cross = np.cross(v, ax)
    theta = np.arctan2(np.sqrt((cross * cross).sum(axis=1)), (v * ax).sum(axis=1))
    beyond = theta - acc / 2
    dist = np.where(beyond <= 0, 0.0, np.where(beyond < np.pi / 2, vn * np.sin(beyond), vn))
    mags = np.concatenate([np.abs(v), np.abs(ax)], axis=1)
    mags = np.where(mags == 0, 1.0, mags)
    tame = (mags.min(axis=1) >= 1e-140) & (mags.max(axis=1) <= 1e140) & (g <= 1e140)
    return dist - g, 1e-7 * (vn + g), tame


def reference_lit(positions, axes, acceptance, c, g: float) -> np.ndarray:
    """Sorted indices of the facets (lens positions, axes, full acceptance angles) that see
    the closed ball (c, g), by brute force (see the module docstring)."""
    pos = np.asarray(positions, dtype=np.float64)
    ax = np.asarray(axes, dtype=np.float64)
    acc = np.asarray(acceptance, dtype=np.float64)
    with np.errstate(all="ignore"):
        diff, margin, tame = _screen(c, g, pos, ax, acc)
    sure = tame & np.isfinite(diff) & (np.abs(diff) > margin)
    seen = sure & (diff < 0)
    for i in np.flatnonzero(~sure).tolist():
        seen[i] = _seen_mp(c, g, pos[i], ax[i], acc[i])
    return np.flatnonzero(seen).astype(np.int64)


def reference_lens_in_ball(positions, c, g: float) -> bool:
    """The closed ball (c, g) contains one of the lens positions (rationals throughout)."""
    pos = np.asarray(positions, dtype=np.float64)
    with np.errstate(all="ignore"):
        d2 = ((np.asarray(c, dtype=np.float64)[None, :] - pos) ** 2).sum(axis=1)
        diff, margin = d2 - g * g, 1e-7 * (d2 + g * g)
        tame = (d2 >= 1e-200) & (d2 <= 1e200) & (1e-100 <= g <= 1e100)
    if (tame & (diff < -margin)).any():
        return True
    G2 = Fraction(float(g)) ** 2
    C = [Fraction(float(x)) for x in c]
    for p in pos[~(tame & (diff > margin))].tolist():
        if sum((ci - Fraction(pi)) ** 2 for ci, pi in zip(C, p, strict=True)) <= G2:
            return True
    return False
