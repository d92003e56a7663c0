"""An eye's HEALPix facets on a Mollweide map, lit facets in their features' colours.

Each facet is one polygon (its boundary sampled ``step`` points per edge by
:func:`eyeviz.core.healpix.boundaries`). Longitude is the model's (0 = +x, counter-clockwise
seen from above, docs/conventions.md), wrapped to [-pi, pi) for matplotlib's Mollweide
axes, so forward (+y) is at lon = pi/2, right of the map's centre; a facet across the wrap
is drawn on both sides and clipped by the map's outline. The equator, the ring that is
the planar eye at z = 0 (docs/spherical.md), is drawn over the facets.

matplotlib is imported by the caller's figure; this module only adds artists to an axes.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from matplotlib.axes import Axes
from matplotlib.collections import PolyCollection

from eyeviz.core import healpix

__all__ = ["facet_lonlat", "draw_eye_map"]

UNLIT = "#eeeeee"
EDGE = "#b0b0b0"


def facet_lonlat(nside: int, pix, step: int = 2) -> np.ndarray:
    """(k, 4 step, 2) (lon, lat) in radians of the facets ``pix``, lon continuous along each
    outline and wrapped so that its first vertex lies in [-pi, pi)."""
    v = healpix.boundaries(nside, np.asarray(pix, np.int64), step)
    lon = np.arctan2(v[..., 1], v[..., 0])
    lat = np.arcsin(np.clip(v[..., 2], -1.0, 1.0))
    # a vertex at a pole has no longitude; Mollweide draws a pole as one point whatever
    # its longitude, so it takes the next vertex's and the outline stays continuous
    pole = np.hypot(v[..., 0], v[..., 1]) < 1e-12
    lon = np.where(pole, np.roll(lon, -1, axis=-1), lon)
    lon = np.unwrap(lon, axis=-1)
    first = (lon[..., :1] + math.pi) % (2 * math.pi) - math.pi
    lon = lon - lon[..., :1] + first
    return np.stack([lon, lat], axis=-1)


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
