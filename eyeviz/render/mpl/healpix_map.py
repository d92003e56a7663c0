"""An eye's HEALPix facets on a Mollweide map, lit facets in their features' colours.

Each facet is one polygon (its boundary sampled ``step`` points per edge by
:func:`eyeviz.core.healpix.boundaries`). Longitude is the model's (0 = +x, counter-clockwise
seen from above, docs/conventions.md), wrapped to [-pi, pi) for matplotlib's Mollweide
axes, so forward (+y) is at lon = pi/2, right of the map's centre; a facet across the wrap
is drawn on both sides and clipped by the map's outline. The equator, the ring that is
the planar eye at z = 0 (docs/spherical.md), is drawn over the facets.

:func:`draw_eye_view` is the same map seen from inside the eye, as the 3D figure
(:mod:`eyeviz.render.mpl.figure3d`) draws it: longitude ``lon0`` (forward, pi/2) at the
map's centre and mirrored, so that the eye's right is on the map's right. Above
:data:`MAX_ALL_FACETS` facets per eye (nside > 32) it draws only the lit facets, as
polygons over a solid background of the unlit sphere: the whole eye at nside 180 is
388,800 polygons, far too heavy for an SVG or PDF.

matplotlib is imported by the caller's figure; this module only adds artists to an axes.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from matplotlib.axes import Axes
from matplotlib.collections import PolyCollection

from eyeviz.core import healpix

__all__ = ["MAX_ALL_FACETS", "draw_eye_map", "draw_eye_view", "facet_lonlat", "view_lonlat"]

UNLIT = "#eeeeee"
EDGE = "#b0b0b0"
#: Facets per eye above which :func:`draw_eye_view` draws only the lit facets (nside 32).
MAX_ALL_FACETS = 12_288


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


def view_lonlat(lon, lat, *, lon0: float = math.pi / 2, flip: bool = True):
    """Map coordinates of model (lon, lat): ``lon - lon0`` (negated when ``flip``), wrapped
    to [-pi, pi); lat unchanged."""
    x = np.asarray(lon, np.float64) - lon0
    if flip:
        x = -x
    return (x + math.pi) % (2 * math.pi) - math.pi, np.asarray(lat, np.float64)


def _view_polys(
    nside: int, pix, step: int, lon0: float, flip: bool
) -> tuple[np.ndarray, np.ndarray]:
    """(k', 4 step, 2) map outlines of the facets ``pix`` and which of them cross the map's
    edge: those appear twice (once on each side, clipped by the outline)."""
    poly = facet_lonlat(nside, pix, step)  # lon continuous along each outline
    lon = poly[..., 0] - lon0
    if flip:
        lon = -lon
    lo = lon.min(axis=-1, keepdims=True)
    lon = lon + ((lo + math.pi) % (2 * math.pi) - math.pi - lo)  # westmost in [-pi, pi)
    poly = np.stack([lon, poly[..., 1]], axis=-1)
    over = lon.max(axis=-1) > math.pi
    extra = poly[over].copy()
    extra[..., 0] -= 2 * math.pi
    return np.concatenate([poly, extra]), over


def draw_eye_view(
    ax: Axes,
    nside: int,
    lit: Sequence[np.ndarray],
    colors: Sequence[str],
    *,
    lon0: float = math.pi / 2,
    flip: bool = True,
    all_facets: bool | None = None,
    step: int = 2,
    equator: str = "#222222",
) -> PolyCollection:
    """One eye on ``ax`` (a Mollweide axes) seen from inside: the facets in ``lit[i]`` in
    ``colors[i]`` (a later feature wins), the equator drawn. ``all_facets`` (default: at
    most :data:`MAX_ALL_FACETS` facets per eye) draws every facet with its outline;
    otherwise only the lit facets are drawn, without outlines, over the unlit sphere
    drawn as one solid background."""
    n_pix = healpix.npix(nside)
    if all_facets is None:
        all_facets = n_pix <= MAX_ALL_FACETS
    if all_facets:
        pix = np.arange(n_pix)
        face = np.full(n_pix, UNLIT, dtype=object)
        for idx, color in zip(lit, colors, strict=True):
            face[np.asarray(idx, np.int64)] = color
    else:
        # the unlit sphere: the map's outline filled, as an artist of its own (a figure
        # saved transparent empties the axes' background patch), edges sampled
        lat = np.linspace(-math.pi / 2, math.pi / 2, 91)
        outline = np.concatenate(
            [np.stack([np.full_like(lat, math.pi), lat], -1),
             np.stack([np.full_like(lat, -math.pi), lat[::-1]], -1)]
        )  # fmt: skip
        ax.add_collection(
            PolyCollection([outline], facecolors=UNLIT, edgecolors="none"), autolim=False
        )
        owner: dict[int, str] = {}
        for idx, color in zip(lit, colors, strict=True):
            owner.update(dict.fromkeys(np.asarray(idx, np.int64).tolist(), color))
        pix = np.fromiter(owner, np.int64, len(owner))
        face = np.array(list(owner.values()), dtype=object)
    verts, over = _view_polys(nside, pix, step, lon0, flip)
    fc = np.concatenate([face, face[over]])
    if all_facets:
        coll = PolyCollection(list(verts), facecolors=list(fc), edgecolors=EDGE, linewidths=0.3)
    else:  # an outline at 0.3 pt would hide a facet of 0.003 in
        coll = PolyCollection(list(verts), facecolors=list(fc), edgecolors="none")
    ax.add_collection(coll, autolim=False)  # the map is the whole sphere already
    ax.plot([-math.pi, math.pi], [0.0, 0.0], color=equator, lw=0.6)
    ax.grid(False)
    ax.set_xticks([])
    ax.set_yticks([])
    return coll
