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

The axes are binned in nested cubic grids over [-1, 1]^3 of cell side 2^(1-k),
k = 0 .. LEVELS-1 (numpy only: a search of sorted cell keys). A ball's query uses the
finest level whose cell side is at least twice the chord radius: at most 2 x 2 x 2 cells.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["AxisIndex", "LEVELS"]

LEVELS = 12
FINER = 1
_SLACK = 1e-9
_DOT_SLACK = 1e-5  # the float32 chord test: its rounding is below 1e-6
_SHIFT = (56, 36, 18)  # level, x, y (z in the low bits)


class AxisIndex:
    """Candidate facets of one eye for many balls at once (see the module docstring)."""

    def __init__(self, unit_axes: np.ndarray, centre: np.ndarray, lens_bound: float,
                 alpha_max: float) -> None:  # fmt: skip
        n = unit_axes.shape[0]
        self.n = n
        self.ux, self.uy, self.uz = (np.ascontiguousarray(c) for c in unit_axes.T)
        self.centre = np.asarray(centre, dtype=np.float64)
        self.lens = float(lens_bound)
        self.alpha = float(alpha_max)
        keys, perms = [], []
        for k in range(LEVELS):
            cells = self._cells(unit_axes, k)
            key = self._key(k, cells[:, 0], cells[:, 1], cells[:, 2])
            order = np.argsort(key, kind="stable")
            keys.append(key[order])
            perms.append(order)
        keys.append(np.full(n, np.int64(LEVELS) << _SHIFT[0]))  # the pseudo-cell "every facet"
        perms.append(np.arange(n))
        allkeys = np.concatenate(keys)
        self.keys, first, self.counts = np.unique(allkeys, return_index=True, return_counts=True)
        self.starts = first
        self.perm = np.concatenate(perms)
        self.pu = [np.ascontiguousarray(c[self.perm], dtype=np.float32) for c in unit_axes.T]

    @staticmethod
    def _cells(p: np.ndarray, k: int) -> np.ndarray:
        side = 2.0 ** (1 - k)
        return np.clip(np.floor((p + 1.0) / side), 0, (1 << k) - 1).astype(np.int64)

    @staticmethod
    def _key(k, ix, iy, iz):
        return (np.int64(k) << _SHIFT[0]) | (ix << _SHIFT[1]) | (iy << _SHIFT[2]) | iz

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

    def cells(self, unit: np.ndarray, rho: np.ndarray) -> tuple[np.ndarray, ...]:
        """Per ball the cells to read: (ball, start, count) of the non-empty ones."""
        nb = unit.shape[0]
        every = ~np.isfinite(rho)
        r = np.where(every, 1.0, rho)
        lev = np.clip(np.floor(FINER - np.log2(r)), 0, LEVELS - 1).astype(np.int64)
        side = np.ldexp(2.0, -lev)[:, None]
        top = (np.int64(1) << lev)[:, None] - 1
        lo = np.clip(np.floor((unit - r[:, None] + 1.0) / side), 0, top).astype(np.int64)
        hi = np.clip(np.floor((unit + r[:, None] + 1.0) / side), 0, top).astype(np.int64)
        span = hi - lo + 1
        ncell = np.where(every, 1, span.prod(axis=1))
        ball = np.repeat(np.arange(nb), ncell)
        local = np.arange(ball.size) - np.repeat(np.cumsum(ncell) - ncell, ncell)
        nyz = (span[:, 1] * span[:, 2])[ball]
        ix = lo[ball, 0] + local // nyz
        rem = local % nyz
        nz = span[ball, 2]
        iy = lo[ball, 1] + rem // nz
        iz = lo[ball, 2] + rem % nz
        key = self._key(lev[ball], ix, iy, iz)
        key[every[ball]] = np.int64(LEVELS) << _SHIFT[0]
        pos = np.minimum(np.searchsorted(self.keys, key), self.keys.size - 1)
        hit = self.keys[pos] == key
        return ball[hit], self.starts[pos[hit]], self.counts[pos[hit]]

    def every(self, nb: int) -> tuple[np.ndarray, ...]:
        """(ball, start, count) of the pseudo-cell "every facet" for balls 0 .. nb-1: the
        brute-force pass."""
        return np.arange(nb), np.full(nb, self.starts[-1]), np.full(nb, self.n)

    def expand(self, ball, start, count) -> tuple[np.ndarray, np.ndarray]:
        """(ball, position in the index's order) of every facet in the given cells; the
        facet is ``perm[position]``."""
        tot = int(count.sum())
        off = np.repeat(start - (np.cumsum(count) - count), count)
        return np.repeat(ball, count), off + np.arange(tot)

    def chord_ok(self, bi, pos, dirs, thr) -> np.ndarray:
        """The candidates within the chord radius of their ball's direction: u . d >= thr,
        thr = 1 - rho^2 / 2 - 1e-5 (:meth:`query`), in float32."""
        dot = self.pu[0].take(pos) * dirs[0].take(bi)
        dot += self.pu[1].take(pos) * dirs[1].take(bi)
        dot += self.pu[2].take(pos) * dirs[2].take(bi)
        return dot >= thr.take(bi)

    def query(
        self, cx, cy, cz, g
    ) -> tuple[np.ndarray, tuple[np.ndarray, ...], np.ndarray, np.ndarray]:
        """(unit directions (B, 3), their columns in float32, dot thresholds, chord radii)
        of the balls: what :meth:`cells` and :meth:`chord_ok` read."""
        unit, rho = self.search(cx, cy, cz, g)
        with np.errstate(invalid="ignore"):
            thr = np.where(np.isfinite(rho), 1 - rho * rho / 2 - _DOT_SLACK, -np.inf)
        dirs = tuple(np.ascontiguousarray(c, dtype=np.float32) for c in unit.T)
        return unit, dirs, thr, rho
