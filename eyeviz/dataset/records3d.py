"""The sparse 3D data set record (a leaf module: numpy and the 3D domain only).

:class:`Dataset3D` holds rows of Algorithm 1 in 3D (docs/spherical.md): a ball of radius
g centred at (r, azimuth, elevation) about the origin, and per eye the RING indices of
the HEALPix facets it lights, in CSR form (row i's facets of eye A are
``indices_a[indptr_a[i]:indptr_a[i + 1]]``, sorted). The same record is one generated
chunk (:mod:`eyeviz.dataset.algorithm1_3d`) and a whole data set read back
(:mod:`eyeviz.dataset.sparse3d`).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from eyeviz.core.domain import Domain3D

__all__ = ["Dataset3D", "index_dtype", "spherical_to_xyz"]


def index_dtype(npix: int) -> np.dtype:
    """int32 when every RING index fits (npix <= 2^31), int64 beyond."""
    return np.dtype(np.int32) if npix <= 2**31 else np.dtype(np.int64)


def spherical_to_xyz(
    r: np.ndarray, azimuth: np.ndarray, elevation: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """x = r cos(el) cos(az), y = r cos(el) sin(az), z = r sin(el) (x right, y forward,
    z up; az is the planar phi, measured from +x in the plane z = 0)."""
    c = np.cos(elevation)
    return r * c * np.cos(azimuth), r * c * np.sin(azimuth), r * np.sin(elevation)


@dataclass
class Dataset3D:
    """Rows (lit_a, lit_b, r, azimuth, elevation, g) of the sparse 3D data set.

    ``indptr_a``/``indptr_b``: int64 (n + 1,), starting at 0; ``indices_a``/``indices_b``:
    RING indices in [0, npix), strictly increasing within a row (:func:`index_dtype`);
    ``r``, ``azimuth``, ``elevation`` (radians), ``g``: float64 (n,); ``x``, ``y``, ``z``:
    the centre the lit sets were computed at, :func:`spherical_to_xyz` of (r, azimuth,
    elevation) as evaluated when generated (kept, so a lit set can be checked exactly
    whatever a platform's sin and cos round to).
    ``params``: the generation parameters (mode, seed; ``responses``, the kind, when the
    rows carry graded responses). ``values_a``/``values_b``: None, or float64 in [0, 1]
    aligned with ``indices_a``/``indices_b``, each lit facet's response
    (docs/responses.md).
    """

    indptr_a: np.ndarray
    indices_a: np.ndarray
    indptr_b: np.ndarray
    indices_b: np.ndarray
    r: np.ndarray
    azimuth: np.ndarray
    elevation: np.ndarray
    g: np.ndarray
    x: np.ndarray
    y: np.ndarray
    z: np.ndarray
    domain: Domain3D = field(default_factory=Domain3D)
    params: dict = field(default_factory=dict)
    values_a: np.ndarray | None = None
    values_b: np.ndarray | None = None

    def __len__(self) -> int:
        return int(self.r.shape[0])

    def lit(self, i: int) -> tuple[np.ndarray, np.ndarray]:
        """Row i's lit facets (lit_a, lit_b), sorted RING indices."""
        a = self.indices_a[self.indptr_a[i] : self.indptr_a[i + 1]]
        b = self.indices_b[self.indptr_b[i] : self.indptr_b[i + 1]]
        return a, b

    def bitmaps(self, start: int = 0, stop: int | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Dense bool (k, n_A) and (k, n_B) bitmaps of rows start..stop-1 (npix bytes per
        row and eye: take few rows at a time at large nside)."""
        stop = len(self) if stop is None else stop
        out = []
        for indptr, indices, npix in (
            (self.indptr_a, self.indices_a, self.domain.facet_counts[0]),
            (self.indptr_b, self.indices_b, self.domain.facet_counts[1]),
        ):
            k = stop - start
            bm = np.zeros((k, npix), bool)
            lo, hi = int(indptr[start]), int(indptr[stop])
            rows = np.repeat(np.arange(k), np.diff(indptr[start : stop + 1]))
            bm[rows, indices[lo:hi]] = True
            out.append(bm)
        return out[0], out[1]

    @staticmethod
    def concat(parts: list[Dataset3D]) -> Dataset3D:
        """The rows of ``parts`` one after another (domain and params of the first)."""
        if not parts:
            raise ValueError("cannot concatenate an empty list of data sets")
        first = parts[0]

        def ptr(name: str) -> np.ndarray:
            outs, base = [np.zeros(1, np.int64)], 0
            for p in parts:
                ip = getattr(p, name)
                outs.append(ip[1:] + base)
                base += int(ip[-1])
            return np.concatenate(outs)

        def cat(name: str) -> np.ndarray:
            return np.concatenate([getattr(p, name) for p in parts])

        def values(name: str) -> np.ndarray | None:
            return None if getattr(first, name) is None else cat(name)

        return Dataset3D(
            ptr("indptr_a"),
            cat("indices_a"),
            ptr("indptr_b"),
            cat("indices_b"),
            cat("r"),
            cat("azimuth"),
            cat("elevation"),
            cat("g"),
            cat("x"),
            cat("y"),
            cat("z"),
            first.domain,
            dict(first.params),
            values("values_a"),
            values("values_b"),
        )
