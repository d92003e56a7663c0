"""The compiled chord search over one eye's unit axes: the numba twin of the cKDTree
query of :mod:`eyeviz.core.measured_index` (which stays the reference: ``EYEVIZ_JIT=0``).

The unit axes are binned in nested cubic grids over [-1, 1]^3 of cell side 2^(1-k),
k = 0 .. LEVELS-1 (a facet's cell at each level, keys sorted). A ball with chord radius
rho about its direction d reads the finest level whose side is at least rho (at most
3 x 3 x 3 cells) and keeps the facets of those cells with |u_i - d| <= rho in float64: the
radius carries a slack of 1e-9, far above the rounding of these few operations, so the
set is the same superset the tree gives (the same facets up to that slack).
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["AxisGrid", "LEVELS"]

LEVELS = 10
_SLACK = 1e-9  # as measured_index
_SHIFT = (56, 36, 18)  # level, x, y (z in the low bits)


def _scan(cx, cy, cz, g, centre, lens, alpha, keys, starts, counts, pux, puy, puz, perm,
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


_COMPILED: list = []


class AxisGrid:
    """Candidate facets by chord radius, compiled (see the module docstring)."""

    def __init__(self, unit_axes: np.ndarray) -> None:
        n = unit_axes.shape[0]
        self.n = n
        keys, perms = [], []
        for k in range(LEVELS):
            side = 2.0 ** (1 - k)
            cells = np.clip(np.floor((unit_axes + 1.0) / side), 0, (1 << k) - 1).astype(np.int64)
            key = (
                (np.int64(k) << _SHIFT[0])
                | (cells[:, 0] << _SHIFT[1])
                | (cells[:, 1] << _SHIFT[2])
                | cells[:, 2]
            )
            order = np.argsort(key, kind="stable")
            keys.append(key[order])
            perms.append(order)
        allkeys = np.concatenate(keys)
        self.keys, self.starts, self.counts = np.unique(
            allkeys, return_index=True, return_counts=True
        )
        self.perm = np.concatenate(perms).astype(np.int64)
        self.pu = [np.ascontiguousarray(c[self.perm]) for c in unit_axes.T]

    def candidates(self, balls, centre, lens: float, alpha: float):
        """(ball, facet) pairs: the facets within the search radius of
        :class:`eyeviz.core.measured_index.AxisIndex` (about the eye's ``centre``, lens
        bound ``lens``, largest half acceptance ``alpha``) of each ball."""
        if not _COMPILED:
            import numba

            _COMPILED.append(numba.njit(cache=True, nogil=True)(_scan))
        scan = _COMPILED[0]
        nb = balls[0].size
        cnt = np.zeros(nb, np.int64)
        args = (*balls, centre, lens, alpha, self.keys, self.starts, self.counts, *self.pu)
        scan(*args, self.perm, cnt, np.zeros(0, np.int64), False)
        offs = np.cumsum(cnt) - cnt
        out = np.empty(int(cnt[-1] + offs[-1]) if nb else 0, np.int64)
        scan(*args, self.perm, offs, out, True)
        return np.repeat(np.arange(nb), cnt), out
