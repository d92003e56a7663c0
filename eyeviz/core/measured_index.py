"""A spatial index over one measured eye's axes: candidate facets for a ball
(docs/measured.md, "The index").

If facet i (lens p_i = o + e_i, |e_i| <= L about a centre o, half acceptance alpha_i)
sees the ball (c, g) and |d| > L + g with d = c - o, then

    angle(a_i, d) <= alpha_i + asin(g / (|d| - L)) + asin(L / |d|):

a point x of the ball in the cone has angle(x - p_i, a_i) <= alpha_i; x lies within
g of c, which is at least |d| - L > g from p_i, so angle(x - p_i, c - p_i) <=
asin(g / (|d| - L)); and c - p_i = d - e_i, so angle(c - p_i, d) <= asin(L / |d|).
The search radius R is that sum with the largest alpha (and a relative slack of 1e-9,
far above the float rounding of the index); a ball with |d| <= L + g (near the eye or
enclosing lenses), or R >= pi, takes every facet. Candidates are the facets whose unit
axis u_i has chord |u_i - d / |d|| <= 2 sin(R / 2): a superset of the seen ones, which
the exact decision then sorts out.

The chord search is scipy's cKDTree over the unit axes, built once per eye (the pair
caches it); its own rounding (1e-16) is far below the slack. With numba the same search
runs compiled over nested grids (:mod:`eyeviz.core.measured_grid`); ``EYEVIZ_JIT=0``
keeps the tree.
"""

from __future__ import annotations

import itertools
import math

import numpy as np

from eyeviz.core.measured_grid import AxisGrid

__all__ = ["AxisIndex"]

_SLACK = 1e-9
_EVERY = 3.0  # a chord radius above 2: every unit axis


class AxisIndex:
    """Candidate facets of one eye for many balls at once (see the module docstring)."""

    def __init__(self, unit_axes: np.ndarray, centre: np.ndarray, lens_bound: float,
                 alpha_max: float) -> None:  # fmt: skip
        from scipy.spatial import cKDTree  # here: a HEALPix scene never loads scipy.spatial

        self.n = int(unit_axes.shape[0])
        self.tree = cKDTree(unit_axes)
        self._unit = unit_axes
        self._grid: AxisGrid | None = None
        self.centre = np.asarray(centre, dtype=np.float64)
        self.lens = float(lens_bound)
        self.alpha = float(alpha_max)

    def search(self, cx, cy, cz, g) -> tuple[np.ndarray, np.ndarray]:
        """(direction (B, 3) unit, chord radius (B,)) per ball; radius inf: every facet."""
        d = np.stack([cx - self.centre[0], cy - self.centre[1], cz - self.centre[2]], axis=1)
        with np.errstate(all="ignore"):
            big = np.abs(d).max(axis=1)
            dn = d / big[:, None]
            nd = np.sqrt((dn * dn).sum(axis=1))
            dist = nd * big
            unit = dn / nd[:, None]
            far = np.isfinite(dist) & (dist > (self.lens + g) * (1 + _SLACK))
            gap = np.where(far, dist - self.lens, 1.0)
            beta = np.arcsin(np.minimum(1.0, np.where(far, g / gap, 1.0)))
            gam = np.arcsin(np.minimum(1.0, np.where(far, self.lens / dist, 1.0)))
            r = (self.alpha + beta + gam) * (1 + _SLACK) + _SLACK
            rho = 2 * np.sin(np.minimum(r, math.pi) / 2) + _SLACK
        every = ~far | (r >= math.pi) | ~np.isfinite(unit).all(axis=1)
        rho[every] = np.inf
        unit[every] = 0.0
        return unit, rho

    def candidates(self, cx, cy, cz, g, *, jit: bool = False) -> tuple[np.ndarray, np.ndarray]:
        """(ball, facet) pairs: every facet within the search radius of each ball, grouped
        by ball (facets unsorted); ``jit``: the compiled grid instead of the tree."""
        if jit:
            if self._grid is None:
                self._grid = AxisGrid(self._unit)
            return self._grid.candidates((cx, cy, cz, g), self.centre, self.lens, self.alpha)
        unit, rho = self.search(cx, cy, cz, g)
        rr = np.where(np.isfinite(rho), rho, _EVERY)
        if unit.shape[0] == 1:
            fi = np.asarray(self.tree.query_ball_point(unit[0], rr[0]), dtype=np.int64)
            return np.zeros(fi.size, np.int64), fi
        res = self.tree.query_ball_point(unit, rr, return_sorted=False)
        cnt = np.fromiter(map(len, res), np.int64, len(res))
        fi = np.fromiter(itertools.chain.from_iterable(res), np.int64, int(cnt.sum()))
        return np.repeat(np.arange(len(res)), cnt), fi
