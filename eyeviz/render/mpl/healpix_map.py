"""What only the HEALPix eyes' maps need (the generic map painter is
:mod:`eyeviz.render.mpl.facet_map`, fed by :class:`eyeviz.model.facet_patches.HealpixPatches`).

- :func:`facet_lonlat`: the cells' outlines in (lon, lat), ``step`` points per edge
  (:func:`eyeviz.core.healpix.boundaries`);
- :func:`draw_eye_map`: every cell of one eye on a Mollweide axes seen from outside (lon 0
  = +x at the centre), the equator drawn over the facets: that ring is the planar eye at
  z = 0 (docs/spherical.md); the README's figure of the spherical eyes
  (scripts/figure_spherical.py) draws it;
- :func:`pixel_at`: the RING index under a point of a seen-from-inside map
  (:func:`eyeviz.render.mpl.facet_map.draw_eye_view`), by
  :func:`eyeviz.core.healpix.ang2pix_ring` (exact; astropy-healpix's ``lonlat_to_healpix``
  agrees off the cells' boundaries, tests/app/test_panels3d.py).

matplotlib is imported by the caller's figure; this module only adds artists to an axes.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from matplotlib.axes import Axes
from matplotlib.collections import PolyCollection

from eyeviz.core import healpix
from eyeviz.model.facet_patches import HealpixPatches
from eyeviz.render.mpl.facet_map import EDGE, UNLIT, facet_at, outline_lonlat

__all__ = ["UNLIT", "draw_eye_map", "facet_lonlat", "pixel_at"]


def facet_lonlat(nside: int, pix, step: int = 2) -> np.ndarray:
    """(k, 4 step, 2) (lon, lat) in radians of the facets ``pix``, lon continuous along each
    outline and wrapped so that its first vertex lies in [-pi, pi)."""
    return outline_lonlat(healpix.boundaries(nside, np.asarray(pix, np.int64), step))[0]


def draw_eye_map(
    ax: Axes,
    nside: int,
    lit: Sequence[np.ndarray],
    colors: Sequence[str],
    *,
    step: int = 2,
    equator: str = "#222222",
) -> PolyCollection:
    """Every facet of one eye on ``ax`` (a Mollweide axes): unlit facets light grey, the
    facets in ``lit[i]`` in ``colors[i]`` (a later feature wins, as in the planar app)."""
    n_pix = healpix.npix(nside)
    face = np.full(n_pix, UNLIT, dtype=object)
    for idx, color in zip(lit, colors, strict=True):
        face[np.asarray(idx, np.int64)] = color
    poly = facet_lonlat(nside, np.arange(n_pix), step)
    lon = poly[..., 0]
    over = lon.max(axis=-1) > math.pi
    extra = poly[over].copy()
    extra[..., 0] -= 2 * math.pi
    verts = np.concatenate([poly, extra])
    fc = np.concatenate([face, face[over]])
    coll = PolyCollection(list(verts), facecolors=list(fc), edgecolors=EDGE, linewidths=0.3)
    ax.add_collection(coll, autolim=False)  # the map is the whole sphere already
    ax.plot([-math.pi, math.pi], [0.0, 0.0], color=equator, lw=0.8)
    ax.grid(False)
    ax.set_xticks([])
    ax.set_yticks([])
    return coll


def pixel_at(nside: int, px, py, *, lon0: float = math.pi / 2, flip: bool = True) -> np.ndarray:
    """RING index of the facet under points (px, py) of a seen-from-inside map in the
    Mollweide plane (:func:`eyeviz.render.mpl.facet_map.mollweide_inverse`), -1 outside
    the map."""
    return facet_at(HealpixPatches(nside), px, py, lon0=lon0, flip=flip)
