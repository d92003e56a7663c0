"""Test trajectories of the paper's Section 6 (Figure 14), as pure point generators.

Each generator returns ``(x, y)`` float64 arrays of ``n`` feature centres, uniformly
spaced along the part of the trajectory where a feature of radius ``g`` lies entirely in
the binocular field of view (Prop. 4, Eq. 17). Points sit at the midpoints of ``n``
equal cells, so none rests exactly on the BFV boundary.

The BFV of Prop. 4 is the cone ``w*y - l*|x| >= g*h`` with ``w = sqrt(h^2 - l^2)``; its
edges leave the origin at the angles psi and pi - psi (psi = asin(l/h), Eq. 12).
With the paper's h = 40, l = 20 that is the 120 degree cone of Section 6, where a
horizontal line at distance r cuts a segment of length 2*tan(60 deg)*r ~ 3.5 r and a
circle of radius r an arc of 2*pi*r/3 ~ 2.1 r.

This module imports numpy and the standard library only.
"""

from __future__ import annotations

import math

import numpy as np

from eyeviz.core.domain import DEFAULTS
from eyeviz.core.validation import check_int, check_positive

__all__ = ["PAPER_COUNTS", "horizontal", "circular", "vertical", "paper_count"]

_H, _L = float(DEFAULTS["h"]), float(DEFAULTS["l"])  # Table 3

# Section 6: features per trajectory as a function of the distance r and the radius g.
PAPER_COUNTS = {
    "horizontal": "1.5 r / g",
    "circular": "r / g",
    "vertical": "4500 / g",
}


def _check_positive(name: str, value) -> float:
    return check_positive(name, value)


def _check_n(n) -> int:
    return check_int("n", n, ge=1)


def _check_eyes(h, l) -> tuple[float, float]:
    h = _check_positive("h", h)
    l = _check_positive("l", l)
    if l >= h:
        raise ValueError(f"h must be > l, got h={h!r}, l={l!r}")
    return h, l


def _cells(lo: float, hi: float, n: int) -> np.ndarray:
    return lo + (np.arange(n, dtype=np.float64) + 0.5) * ((hi - lo) / n)


def horizontal(r, g, n, *, h: float = _H, l: float = _L) -> tuple[np.ndarray, np.ndarray]:
    """Figure 14a: the line y = r, restricted to where a disc of radius g is in the BFV.

    A centre (x, r) is in the BFV when ``l*|x| <= w*r - g*h`` (Eq. 17).
    """
    r, g, n = _check_positive("r", r), _check_positive("g", g), _check_n(n)
    h, l = _check_eyes(h, l)
    w = math.sqrt((h - l) * (h + l))
    half = (w * r - g * h) / l
    if half <= 0:
        raise ValueError(f"a feature of radius g={g} never lies in the BFV on the line y={r}")
    x = _cells(-half, half, n)
    return x, np.full(n, r)


def circular(r, g, n, *, h: float = _H, l: float = _L) -> tuple[np.ndarray, np.ndarray]:
    """Figure 14b: the circle of radius r about the origin, inside the BFV.

    On the circle, ``w*y - l*|x| = h*r*sin(phi - psi)`` for phi <= pi/2 (and the mirror image
    for phi >= pi/2), so the disc is in the BFV when
    ``psi + asin(g/r) <= phi <= pi - psi - asin(g/r)``.
    """
    r, g, n = _check_positive("r", r), _check_positive("g", g), _check_n(n)
    h, l = _check_eyes(h, l)
    if g >= r:
        raise ValueError(f"g must be < r on a circular trajectory, got g={g}, r={r}")
    psi = math.asin(l / h)
    lo = psi + math.asin(g / r)
    hi = math.pi - lo
    if hi <= lo:
        raise ValueError(f"a feature of radius g={g} never lies in the BFV on the circle r={r}")
    phi = _cells(lo, hi, n)
    return r * np.cos(phi), r * np.sin(phi)


def vertical(
    g, n, start: float = 1000.0, stop: float = 10000.0, *, h: float = _H, l: float = _L
) -> tuple[np.ndarray, np.ndarray]:
    """Figure 14c: the central axis x = 0 from y = start to y = stop (length 9000 in Section 6).

    The part below ``y = g*h/w`` (where the disc would leave the BFV) is cut off.
    """
    g, n = _check_positive("g", g), _check_n(n)
    start, stop = _check_positive("start", start), _check_positive("stop", stop)
    h, l = _check_eyes(h, l)
    if stop <= start:
        raise ValueError(f"stop must be > start, got start={start}, stop={stop}")
    w = math.sqrt((h - l) * (h + l))
    lo = max(start, g * h / w)
    if lo >= stop:
        raise ValueError(
            f"a feature of radius g={g} never lies in the BFV on y in [{start}, {stop}]"
        )
    return np.zeros(n), _cells(lo, stop, n)


def paper_count(
    kind: str, g: float, r: float | None = None, *, lo: int = 1, hi: int | None = None
) -> int:
    """Features per trajectory as Section 6 states (1.5r/g, r/g, 4500/g), clipped to [lo, hi]."""
    g = _check_positive("g", g)
    if kind == "horizontal":
        c = 1.5 * _check_positive("r", r) / g
    elif kind == "circular":
        c = _check_positive("r", r) / g
    elif kind == "vertical":
        c = 4500.0 / g
    else:
        raise ValueError(f"kind must be one of {sorted(PAPER_COUNTS)}, got {kind!r}")
    n = max(lo, int(round(c)))
    return n if hi is None else min(n, hi)
