"""Per eye model, the facets the 3D view draws: HEALPix cells or measured facet patches.

The 3D view's eye painter (:mod:`eyeviz.render.vtk.eyes3d`) knows one interface,
:class:`EyeSurface`, and :func:`surface_of` gives it for the scene's pair:

- :class:`HealpixSurface` (:class:`eyeviz.core.geometry3d.EyePair3D`): each facet a HEALPix
  cell on the sphere of radius l about (+-h, 0, 0) (:func:`eyeviz.model.shapes3d.facet_mesh`),
  with the level of detail of :data:`eyeviz.model.shapes3d.FULL_MAX_NSIDE` (beyond it the
  lit facets are drawn per ball over a smooth sphere), the equator and the BFV's cones;
- :class:`MeasuredSurface` (:class:`eyeviz.core.measured.MeasuredEyePair`): each
  ommatidium a hexagon around its lens, in the plane fitted to its six nearest lenses
  (the local eye surface; its normal turned to the facet's optical axis), one vertex
  towards the nearest lens, of circumradius 0.6 times the mean distance to the six
  nearest (a hexagonal lattice's cell has circumradius d / sqrt(3) = 0.577 d: a little
  larger, so the patches close over the lattice's irregularities). One mesh per eye, cell i
  is ommatidium i, always drawn in full (a few thousand facets an eye).

No VTK here: points and VTK face arrays (docs/architecture.md: renderers never compute
geometry).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Protocol

import numpy as np

from eyeviz.core.geometry3d import EyePair3D
from eyeviz.core.measured import MeasuredEye, MeasuredEyePair
from eyeviz.model import shapes3d

__all__ = ["EyeSurface", "HealpixSurface", "MeasuredSurface", "hexagon_mesh", "surface_of"]

Vec = tuple[float, float, float]


class EyeSurface(Protocol):
    """What the 3D view draws of a pair's two eyes (eye 0 = A, 1 = B)."""

    @property
    def key(self) -> tuple:
        """Changes when the drawn eyes change (the painter rebuilds its meshes)."""
        ...

    @property
    def full(self) -> bool:
        """Every facet a cell of one mesh per eye (else lit patches per ball, :meth:`patch`)."""
        ...

    @property
    def centres(self) -> tuple[Vec, Vec]:
        """Each eye's centre: the tangent cones' apex, the label's and the close-up's place."""
        ...

    @property
    def radius(self) -> float:
        """Each eye's size: the radius of a ball about its centre holding its facets."""
        ...

    @property
    def nside(self) -> int | None:
        """The HEALPix nside (edges drawn up to a bound), None for measured eyes."""
        ...

    @property
    def underlay(self) -> float | None:
        """Radius of the smooth sphere drawn just under the facets, or None."""
        ...

    @property
    def equator(self) -> float | None:
        """Radius of the ring drawn for the planar eye's row of facets, or None."""
        ...

    @property
    def bfv(self) -> bool:
        """The HEALPix BFV's cones (psi = asin(l / h)) apply."""
        ...

    @property
    def caption(self) -> str: ...

    def counts(self) -> tuple[int, int]: ...

    def mesh(self, e: int) -> tuple[np.ndarray, np.ndarray]:
        """(points, VTK faces) of eye ``e``: cell i is facet i."""
        ...

    def patch(self, e: int, pix: np.ndarray, lift: float) -> tuple[np.ndarray, np.ndarray]:
        """(points, faces) of the facets ``pix`` of eye ``e`` raised to ``lift`` x radius
        (only when not :attr:`full`)."""
        ...


@dataclass(frozen=True)
class HealpixSurface:
    """HEALPix cells on the spheres of radius l about (+-h, 0, 0) (docs/spherical.md)."""

    pair: EyePair3D

    @property
    def key(self) -> tuple:
        return ("spherical", self.pair.h, self.pair.l, self.pair.nside)

    @property
    def full(self) -> bool:
        return self.pair.nside <= shapes3d.FULL_MAX_NSIDE

    @property
    def centres(self) -> tuple[Vec, Vec]:
        return ((-self.pair.h, 0.0, 0.0), (self.pair.h, 0.0, 0.0))

    @property
    def radius(self) -> float:
        return float(self.pair.l)

    @property
    def nside(self) -> int:
        return int(self.pair.nside)

    @property
    def underlay(self) -> float:
        # inside the flat facets' centres: a facet's sagitta is < 1 - cos(1.2 / nside)
        n = self.pair.nside
        return self.pair.l * (min(0.997, math.cos(1.2 / n)) if self.full else 0.999)

    @property
    def equator(self) -> float:
        return self.pair.l * 1.012

    @property
    def bfv(self) -> bool:
        return True

    @property
    def caption(self) -> str:
        p = self.pair
        return f"the eyes close up: nside {p.nside}\n{p.npix:,} facets each" + (
            "" if self.full else ",\nthe lit ones drawn"
        )

    def counts(self) -> tuple[int, int]:
        return (self.pair.npix, self.pair.npix)

    def mesh(self, e: int) -> tuple[np.ndarray, np.ndarray]:
        return shapes3d.facet_mesh(self.pair.nside, self.centres[e], self.pair.l)

    def patch(self, e: int, pix: np.ndarray, lift: float) -> tuple[np.ndarray, np.ndarray]:
        dn, dpix = shapes3d.patch_facets(self.pair.nside, pix)
        return shapes3d.facet_mesh(dn, self.centres[e], self.pair.l * lift, dpix, step=1)


def hexagon_mesh(eye: MeasuredEye, k: int = 6, scale: float = 0.6) -> tuple[np.ndarray, np.ndarray]:
    """(points (6 n, 3), VTK faces) of one measured eye: ommatidium i the hexagon of cell
    i (see the module docstring); ``k`` neighbours fit the local plane."""
    pos = np.asarray(eye.positions, dtype=np.float64)
    n = pos.shape[0]
    ax = eye.unit_axes
    if n < 3:  # no plane to fit: hexagons across the axes, of a nominal size
        normal = ax
        size = np.full(n, 0.01 if n < 2 else 0.3 * float(np.linalg.norm(pos[1] - pos[0])))
        toward = np.zeros_like(pos)
    else:
        from scipy.spatial import cKDTree  # measured eyes only (a HEALPix scene: not loaded)

        kk = min(k + 1, n)
        dist, idx = cKDTree(pos).query(pos, kk)
        nb = pos[idx[:, 1:]]  # (n, kk - 1, 3)
        rel = nb - nb.mean(axis=1, keepdims=True)
        cov = np.einsum("nki,nkj->nij", rel, rel)
        _, vecs = np.linalg.eigh(cov)
        normal = vecs[:, :, 0]  # the least-variance direction: the surface normal
        flip = (normal * ax).sum(axis=1) < 0
        normal[flip] *= -1.0
        size = scale * dist[:, 1:].mean(axis=1)
        toward = nb[:, 0] - pos
    # e1: towards the nearest lens within the plane (any in-plane direction if degenerate)
    e1 = toward - (toward * normal).sum(axis=1, keepdims=True) * normal
    ref = np.where((np.abs(normal[:, 2]) < 0.9)[:, None], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0])
    fallback = np.cross(normal, ref)
    weak = np.linalg.norm(e1, axis=1) < 1e-12
    e1[weak] = fallback[weak]
    e1 /= np.linalg.norm(e1, axis=1, keepdims=True)
    e2 = np.cross(normal, e1)
    t = np.arange(6) * (math.pi / 3.0)
    pts = pos[:, None, :] + size[:, None, None] * (
        np.cos(t)[None, :, None] * e1[:, None, :] + np.sin(t)[None, :, None] * e2[:, None, :]
    )
    faces = np.empty((n, 7), dtype=np.int64)
    faces[:, 0] = 6
    faces[:, 1:] = np.arange(6 * n, dtype=np.int64).reshape(n, 6)
    return pts.reshape(-1, 3), faces.ravel()


@dataclass(frozen=True)
class MeasuredSurface:
    """Measured ommatidia as hexagonal patches at their lenses (the module docstring)."""

    pair: MeasuredEyePair
    _meshes: dict = field(default_factory=dict, repr=False, compare=False)

    @property
    def key(self) -> tuple:
        return ("measured", self.pair.fingerprint)

    @property
    def full(self) -> bool:
        return True

    @property
    def centres(self) -> tuple[Vec, Vec]:
        return self.pair.centers

    @property
    def radius(self) -> float:
        return float(self.pair.l)

    @property
    def nside(self) -> None:
        return None

    @property
    def underlay(self) -> None:
        return None

    @property
    def equator(self) -> None:
        return None

    @property
    def bfv(self) -> bool:
        return False

    @property
    def caption(self) -> str:
        a, b = self.pair.facet_counts
        return f"the eyes close up: {self.pair.name}\n{a:,} + {b:,} facets"

    def counts(self) -> tuple[int, int]:
        return self.pair.facet_counts

    def mesh(self, e: int) -> tuple[np.ndarray, np.ndarray]:
        if e not in self._meshes:
            self._meshes[e] = hexagon_mesh(self.pair.eye("AB"[e]))
        return self._meshes[e]

    def patch(self, e: int, pix: np.ndarray, lift: float) -> tuple[np.ndarray, np.ndarray]:
        raise NotImplementedError("measured eyes are drawn in full")


def surface_of(pair: EyePair3D | MeasuredEyePair) -> EyeSurface:
    """The :class:`EyeSurface` of a spherical-side pair (one per measured pair: its
    hexagons are computed once)."""
    if isinstance(pair, EyePair3D):
        return HealpixSurface(pair)
    got = pair._cache.get("surface")
    if got is None:
        got = pair._cache["surface"] = MeasuredSurface(pair)
    return got
