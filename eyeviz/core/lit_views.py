"""What the spherical-side eye models derive alike from their lit sets: one ball's lit
facets, dense bitmaps and Definition 1, from ``lit_csr`` and ``facet_counts`` (the
HEALPix :class:`eyeviz.core.geometry3d.EyePair3D` and the measured
:class:`eyeviz.core.measured.MeasuredEyePair`)."""

from __future__ import annotations

from typing import Any

import numpy as np

__all__ = ["LitSetViews"]


def _shape(x, y, z, g) -> tuple[int, ...]:
    """The broadcast shape of the balls' arrays (``lit_csr`` flattens it)."""
    return np.broadcast_shapes(*(np.shape(v) for v in (x, y, z, g)))


class LitSetViews:
    """``lit``, ``bitmaps`` and ``visible`` on top of a model's ``lit_csr``."""

    facet_counts: Any  # (n_A, n_B), the model's

    def lit_csr(self, x, y, z, g) -> tuple[tuple[np.ndarray, np.ndarray], ...]:
        raise NotImplementedError

    def lit(self, x, y, z, g) -> tuple[np.ndarray, np.ndarray]:
        """One ball: (lit_a, lit_b), sorted int64 facet indices."""
        for name, v in zip("xyzg", (x, y, z, g), strict=True):
            if np.ndim(v) != 0:
                raise ValueError(f"{name} must be a scalar for lit(); use lit_csr for arrays")
        (pa, ia), (pb, ib) = self.lit_csr(x, y, z, g)
        return ia[pa[0] : pa[1]], ib[pb[0] : pb[1]]

    def bitmaps(self, x, y, z, g) -> tuple[np.ndarray, np.ndarray]:
        """(omega_a, omega_b) bool of shapes (..., n_A) and (..., n_B)."""
        csr = self.lit_csr(x, y, z, g)  # validates the balls (one-line errors)
        shape = _shape(x, y, z, g)
        res = []
        for (indptr, idx), n in zip(csr, self.facet_counts, strict=True):
            nb = indptr.size - 1
            bm = np.zeros((nb, n), bool)
            bm[np.repeat(np.arange(nb), np.diff(indptr)), idx] = True
            res.append(bm.reshape(shape + (n,)))
        return res[0], res[1]

    def visible(self, x, y, z, g) -> tuple[np.ndarray, np.ndarray]:
        """Definition 1 per eye: the ball lights at least two facets (vis_a, vis_b)."""
        (pa, _), (pb, _) = self.lit_csr(x, y, z, g)  # validates the balls
        shape = _shape(x, y, z, g)
        return (np.diff(pa) >= 2).reshape(shape), (np.diff(pb) >= 2).reshape(shape)
