"""The compiled chord search over one eye's unit axes: the twin of the cKDTree query of
:mod:`eyeviz.core.measured_index` (which stays the reference: ``EYEVIZ_JIT=0``); the scan
itself is :func:`eyeviz.core.kernels.measured_lit.scan_kernel`.

The unit axes are binned in nested cubic grids over [-1, 1]^3 of cell side 2^(1-k),
k = 0 .. LEVELS-1 (a facet's cell at each level, keys sorted). A ball with chord radius
rho about its direction d reads the finest level whose side is at least rho (at most
3 x 3 x 3 cells) and keeps the facets of those cells with |u_i - d| <= rho in float64: the
radius carries a slack of 1e-9, far above the rounding of these few operations, so the
set is the same superset the tree gives (the same facets up to that slack).
"""

from __future__ import annotations

import numpy as np

__all__ = ["AxisGrid", "LEVELS"]

LEVELS = 10  # as eyeviz.core.kernels.measured_lit
_SHIFT = (56, 36, 18)


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
        from eyeviz.core.kernels.measured_lit import scan_kernel as scan

        cx, cy, cz, g = balls
        nb = cx.size
        ux, uy, uz = self.pu
        keys, starts, counts, perm = self.keys, self.starts, self.counts, self.perm
        cnt, out = scan(cx, cy, cz, g, centre, lens, alpha, keys, starts, counts, ux, uy, uz, perm)
        return np.repeat(np.arange(nb), cnt), out
