"""The paper's formulas taken literally, in a chosen float type (for the stability report).

Prop. 5 (Eq. 22-25, arccos form, valid for 0 <= phi <= pi) converts the feature centre
to each eye's polar coordinates and Prop. 2 (Eq. 11) gives the lit interval, exactly as
Algorithm 1 steps 13-16 write them. Nothing is guarded: NaN from arccos/arcsin out of
range propagates and is reported as a difference. This is the baseline eyeviz's core is
measured against, not something eyeviz uses.
"""

from __future__ import annotations

import numpy as np

__all__ = ["paper_intervals"]


def paper_intervals(h: float, m: int, x, y, g, dtype=np.float64) -> tuple[np.ndarray, ...]:
    """(LA, RA, LB, RB) by Eq. 11 and 22-25 in ``dtype``; invalid rows get L = R = -1."""
    ft = np.dtype(dtype).type
    x, y, g = (np.asarray(v, dtype=dtype) for v in (x, y, g))
    h_, k = ft(h), ft(m) / (ft(2) * ft(np.pi))
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        r = np.sqrt(x * x + y * y)
        phi = np.arctan2(y, x)
        phi = np.where(phi < 0, phi + ft(2) * ft(np.pi), phi).astype(dtype)
        c = r * np.cos(phi)
        rB = np.sqrt(h_ * h_ + r * r - ft(2) * h_ * r * np.cos(phi))
        phiB = ft(np.pi) - np.arccos((h_ - c) / rB)
        rA = np.sqrt(h_ * h_ + r * r + ft(2) * h_ * r * np.cos(phi))
        phiA = np.arccos((h_ + c) / rA)
        out = []
        for rE, phiE in ((rA, phiA), (rB, phiB)):
            a = np.arcsin(g / rE)
            lo = np.floor(k * (phiE - a))
            hi = np.floor(k * (phiE + a))
            bad = ~(np.isfinite(lo) & np.isfinite(hi))
            lo_i = np.where(bad, 0, lo).astype(np.int64)
            hi_i = np.where(bad, 0, hi).astype(np.int64)
            L = np.mod(lo_i, m)
            R = hi_i - lo_i + L
            whole = R - L >= m - 1
            L = np.where(whole, 0, L)
            R = np.where(whole, m - 1, R)
            out += [np.where(bad, -1, L), np.where(bad, -1, R)]
    return tuple(out)
