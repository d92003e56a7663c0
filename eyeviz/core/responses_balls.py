"""A ball as a cap of directions seen from a point, to the last bit where it matters.

The ball (c, g) seen from a point p covers the directions within b = asin(g / |v|) of
v = c - p when |v| > g, the open hemisphere about v when |v| = g (b = pi / 2), and every
direction when |v| < g (b = pi). Near |v| = g, b = atan2(g, sqrt(|v|^2 - g^2)) is
ill-conditioned in |v|^2 - g^2, so that difference is evaluated as an exact expansion of
the float inputs (error-free sums and products: its sign is exact, its value correct to
a few units in the last place), not as fl(|v|)^2 - g^2 (docs/responses.md).
"""

from __future__ import annotations

import math

import numpy as np

from eyeviz.core.exact import _expansion

__all__ = ["ball_cap", "two_diff"]

_SPLIT = 134217729.0  # 2^27 + 1, Dekker's splitter


def two_diff(a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(s, e) with s + e == a - b exactly, s = fl(a - b) (Knuth's two-sum)."""
    s = a - b
    bb = s - a
    e = (a - (s - bb)) + (-b - bb)
    return s, e


def _two_prod(a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(p, e) with p + e == a * b exactly (Dekker; |a|, |b| well inside the range)."""
    p = a * b
    ca = _SPLIT * a
    ah = ca - (ca - a)
    al = a - ah
    cb = _SPLIT * b
    bh = cb - (cb - b)
    bl = b - bh
    e = ((ah * bh - p) + ah * bl + al * bh) + al * bl
    return p, e


def _sum_exact(terms: list[np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """(value, sign) of a sum of floats: a nonoverlapping expansion (error-free), its
    sign that of the largest non-zero component, its value summed smallest first."""
    e = _expansion(terms)
    sign = np.zeros(e[0].shape)
    for comp in reversed(e):
        sign = np.where(sign == 0, np.sign(comp), sign)
    value = np.zeros(e[0].shape)
    for comp in e:
        value = value + comp
    return value, sign


def ball_cap(c: tuple[np.ndarray, ...], p: tuple[np.ndarray, ...], g: np.ndarray):
    """Per pair: (v, b) with v = fl(c - p) per component (a tuple) and b the angular
    radius of the ball's cap of directions seen from p (pi when p is inside the ball,
    pi / 2 exactly when p is on its sphere). c, p: tuples of coordinate arrays (2 or 3).
    Where |v| > 2g, b = asin(g / |v|) (well conditioned there); nearer, the expansion."""
    hi, lo = zip(*(two_diff(ci, pi) for ci, pi in zip(c, p, strict=True)), strict=True)
    with np.errstate(over="ignore", under="ignore", invalid="ignore", divide="ignore"):
        norm = np.sqrt(sum(h * h for h in hi))
        q = g / norm
        b = np.arcsin(np.minimum(q, 1.0))
    near = ~((q < 0.5) & np.isfinite(norm) & (norm > 2.0**-480) & (norm < 2.0**480))
    if near.any():
        i = np.flatnonzero(near)
        b[i] = _near_cap(tuple(h[i] for h in hi), tuple(v[i] for v in lo), g[i])
    return tuple(hi), b


def _near_cap(hi: tuple[np.ndarray, ...], lo: tuple[np.ndarray, ...], g: np.ndarray):
    """b from the exact expansion of |v|^2 - g^2 (v = hi + lo exactly)."""
    with np.errstate(over="ignore", under="ignore", invalid="ignore", divide="ignore"):
        big = np.maximum.reduce([np.abs(h) for h in hi] + [np.abs(g)])
        ex = np.frexp(big)[1]
        hs = [np.ldexp(h, -ex) for h in hi]
        ls = [np.ldexp(v, -ex) for v in lo]
        gs = np.ldexp(g, -ex)
        terms: list[np.ndarray] = []
        for h, v in zip(hs, ls, strict=True):
            terms.extend(_two_prod(h, h))
            p2, e2 = _two_prod(h, v)
            terms.extend((2 * p2, 2 * e2))
            terms.extend(_two_prod(v, v))
        gp, ge = _two_prod(gs, gs)
        terms.extend((-gp, -ge))
        d, sign = _sum_exact(terms)
        b = np.arctan2(gs, np.sqrt(np.maximum(d, 0.0)))
    return np.where(sign < 0, math.pi, np.where(sign == 0, math.pi / 2, b))
