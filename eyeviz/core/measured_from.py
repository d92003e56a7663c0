"""eyeviz's own eyes written as measured eyes: one ommatidium per facet (docs/eye_files.md).

A facet of the cell models (the planar ring's sectors, the HEALPix sphere's cells) sees a
ball iff the ball meets the cone from the *eye centre* over the facet's *cell*. Its
measured version is the acceptance cone of :mod:`eyeviz.core.measured`:

- lens p_i = centre + l u_i on the eye's surface, u_i the unit direction of the cell's
  centre (HEALPix: :func:`eyeviz.core.healpix.centers`, RING order, so facet i of the
  measured eye is RING pixel i; planar: the sector's bisector at angle (k + 1/2) gamma,
  in the plane z = 0);
- axis a_i = u_i;
- full acceptance angle = the facet's width: gamma = 2 pi / m for the ring (the sector's
  angle, exactly), and sqrt(4 pi / npix) for HEALPix (the side of a square of the cell's
  solid angle, HEALPix's usual "pixel size"); the acceptance disc is then about the disc
  inscribed in the cell (a HEALPix cell is a curvilinear rhombus of that side);
- focal offset l: the cone's tip behind the lens lies at the eye centre, as the cell
  model's cones, so a CompoundRay rendering of the file samples the same directions.

The lit sets then differ from the cell model's in two ways (the figure
``docs/img/measured_vs_cells.png``): the cone is a disc, not the cell (a ball touching
only a cell's corner lights the cell but misses its inscribed disc; a ball between
discs can light nothing), and its apex is the lens, l in front of the centre (a
translated cone lies inside the original one, so near balls light fewer facets).
"""

from __future__ import annotations

import math

import numpy as np

from eyeviz.core import healpix
from eyeviz.core.geometry import EyePair
from eyeviz.core.geometry3d import EyePair3D
from eyeviz.core.measured import MeasuredEye, MeasuredEyePair

__all__ = ["as_measured", "healpix_width"]


def healpix_width(nside: int) -> float:
    """The acceptance angle given to a HEALPix cell: sqrt(4 pi / (12 nside^2))."""
    return math.sqrt(4 * math.pi / healpix.npix(nside))


def _eye(center_x: float, l: float, u: np.ndarray, acc: float, name: str) -> MeasuredEye:
    pos = u * l
    pos[:, 0] += center_x
    n = u.shape[0]
    return MeasuredEye(pos, u, np.full(n, acc), np.full(n, l), name=name)


def as_measured(eyes) -> MeasuredEyePair:
    """The measured version of an :class:`EyePair3D` (one ommatidium per HEALPix cell) or
    of an :class:`EyePair` (a ring of m ommatidia in the plane z = 0); a
    :class:`MeasuredEyePair` is returned as it is. Any other model whose facets are
    acceptance cones enters by its ``facets(eye)`` (lens positions, axes, full acceptance
    angles of eye ``"A"`` or ``"B"``, as :meth:`MeasuredEyePair.facets`): the door through
    which a new eye model in space reaches the pipeline (docs/extending.md)."""
    if isinstance(eyes, MeasuredEyePair):
        return eyes
    facets = getattr(eyes, "facets", None)
    if callable(facets) and not isinstance(eyes, (EyePair3D, EyePair)):
        eyes = []
        for w in "AB":
            pos, ax, acc = facets(w)[:3]
            eyes.append(MeasuredEye(pos, ax, acc, name=w))
        a, b = eyes
        kind = getattr(eyes, "kind", type(eyes).__name__)
        return MeasuredEyePair(a, b, name=f"{kind} eyes", source=f"eyeviz {kind} model")
    if isinstance(eyes, EyePair3D):
        u = healpix.centers(eyes.nside)
        u = u / np.linalg.norm(u, axis=1)[:, None]
        acc = healpix_width(eyes.nside)
        name = f"HEALPix nside {eyes.nside}, h {eyes.h:g}, l {eyes.l:g}"
    elif isinstance(eyes, EyePair):
        phi = (np.arange(eyes.m) + 0.5) * eyes.gamma
        u = np.stack([np.cos(phi), np.sin(phi), np.zeros(eyes.m)], axis=1)
        acc = eyes.gamma
        name = f"planar ring m {eyes.m}, h {eyes.h:g}, l {eyes.l:g}"
    else:
        raise TypeError(
            f"as_measured: expected an eyeviz eye pair or a model with facets(eye), "
            f"got {type(eyes).__name__}"
        )
    a = _eye(-eyes.h, eyes.l, u.copy(), acc, "A")
    b = _eye(eyes.h, eyes.l, u.copy(), acc, "B")
    return MeasuredEyePair(a, b, name=name, source=f"eyeviz {eyes.kind} model")
