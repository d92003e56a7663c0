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

The maps' axes are :class:`MapAxes` (Mollweide without resampling). The way back from a
point of a map to a facet, for the app's hover (issue 22): :func:`mollweide_inverse` (the
projection's closed-form inverse), :func:`model_lonlat` (the inverse of
:func:`view_lonlat`) and :func:`pixel_at`, which maps the direction with
:func:`eyeviz.core.healpix.ang2pix_ring` (exact; astropy-healpix's ``lonlat_to_healpix``
agrees off the cells' boundaries, tests/app/test_panels3d.py).

matplotlib is imported by the caller's figure; this module only adds artists to an axes.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from matplotlib.axes import Axes
from matplotlib.collections import PathCollection, PolyCollection
from matplotlib.path import Path
from matplotlib.projections.geo import MollweideAxes

from eyeviz.core import healpix

__all__ = [
    "MAX_ALL_FACETS",
    "MapAxes",
    "compound_path",
    "draw_eye_map",
    "draw_eye_view",
    "facet_lonlat",
    "model_lonlat",
    "mollweide",
    "mollweide_inverse",
    "pixel_at",
    "view_lonlat",
    "view_polys",
]

UNLIT = "#eeeeee"
EDGE = "#b0b0b0"
#: Facets per eye above which :func:`draw_eye_view` draws only the lit facets (nside 32).
MAX_ALL_FACETS = 12_288


class MapAxes(MollweideAxes):
    """Mollweide axes that do not resample paths: matplotlib's split every segment into 75
    (a facet of 8 vertices became 600, an SVG of the teaching scene 23 MB); the facets'
    outlines are already sampled along their edges, and curved lines are drawn sampled."""

    name = "eyeviz_mollweide"
    RESOLUTION = 1


def compound_path(verts: np.ndarray) -> Path:
    """One path of many closed polygons (k, n, 2): drawn and written (SVG, PDF) as one
    element, not k (the lit facets of one colour on a map never overlap)."""
    k, n = verts.shape[:2]
    closed = np.concatenate([verts, verts[:, :1]], axis=1).reshape(-1, 2)
    codes = np.full((k, n + 1), Path.LINETO, dtype=Path.code_type)
    codes[:, 0] = Path.MOVETO
    codes[:, -1] = Path.CLOSEPOLY
    return Path(closed, codes.ravel())


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


def model_lonlat(x, y, *, lon0: float = math.pi / 2, flip: bool = True):
    """The inverse of :func:`view_lonlat`: model (lon in [0, 2 pi), lat) of map
    coordinates (x, y)."""
    x = np.asarray(x, np.float64)
    lon = lon0 - x if flip else lon0 + x
    return np.mod(lon, 2 * math.pi), np.asarray(y, np.float64)


def mollweide(lon, lat) -> tuple[np.ndarray, np.ndarray]:
    """Mollweide plane coordinates of (lon, lat), laid out as matplotlib's (x in
    [-2 sqrt 2, 2 sqrt 2], y in [-sqrt 2, sqrt 2]): x = (2 sqrt 2 / pi) lon cos theta,
    y = sqrt 2 sin theta, 2 theta + sin 2 theta = pi sin lat solved to float64 precision
    (matplotlib's own transform stops within about 5e-4 rad of theta, which folds a band
    of the map near the equator; the app's maps are drawn with this one, so a point under
    the mouse inverts exactly by :func:`mollweide_inverse`)."""
    lon = np.asarray(lon, np.float64)
    lat = np.asarray(lat, np.float64)
    target = math.pi * np.sin(lat)
    # near a pole 2 theta + sin 2 theta ~ pi - (4/3) e^3 (e = pi/2 - |theta|): a start
    # from the series keeps Newton fast where the derivative 4 cos^2 theta vanishes
    colat = math.pi / 2 - np.abs(lat)
    theta = np.where(
        colat < 0.2, np.sign(lat) * (math.pi / 2 - np.cbrt(3 * math.pi * colat**2 / 8)), lat
    )
    for _ in range(20):  # quadratic convergence: 3 to 5 steps from these starts
        f = 2 * theta + np.sin(2 * theta) - target
        df = 4 * np.cos(theta) ** 2
        step = np.where(df > 1e-300, f / np.where(df > 1e-300, df, 1.0), 0.0)
        theta = np.clip(theta - step, -math.pi / 2, math.pi / 2)
        if not np.any(np.abs(step) > 1e-15):
            break
    theta = np.where(colat == 0, np.sign(lat) * (math.pi / 2), theta)
    r2 = math.sqrt(2.0)
    return (2 * r2 / math.pi) * lon * np.cos(theta), r2 * np.sin(theta)


def mollweide_inverse(px, py) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(lon, lat, inside) of points of the Mollweide plane (see :func:`mollweide`):
    theta = asin(y / sqrt 2), lon = pi x / (2 sqrt 2 cos theta), lat = asin((2 theta +
    sin 2 theta) / pi). ``inside`` is False outside the map's ellipse (lon and lat are
    then clipped, not meaningful)."""
    px = np.asarray(px, np.float64)
    py = np.asarray(py, np.float64)
    r2 = math.sqrt(2.0)
    inside = (px / (2 * r2)) ** 2 + (py / r2) ** 2 <= 1.0 + 1e-12  # the rim: rounding
    theta = np.arcsin(np.clip(py / r2, -1.0, 1.0))
    c = np.cos(theta)
    with np.errstate(divide="ignore", invalid="ignore"):
        lon = np.where(c > 0, math.pi * px / (2 * r2 * np.where(c > 0, c, 1.0)), 0.0)
    lon = np.clip(lon, -math.pi, math.pi)
    lat = np.arcsin(np.clip((2 * theta + np.sin(2 * theta)) / math.pi, -1.0, 1.0))
    return lon, lat, inside


def pixel_at(nside: int, px, py, *, lon0: float = math.pi / 2, flip: bool = True) -> np.ndarray:
    """RING index of the facet under points (px, py) of a :func:`draw_eye_view` map in
    the Mollweide plane (see :func:`mollweide_inverse`), -1 outside the map."""
    lon, lat, inside = mollweide_inverse(px, py)
    mlon, mlat = model_lonlat(lon, lat, lon0=lon0, flip=flip)
    pix = healpix.ang2pix_ring(nside, np.sin(mlat), mlon)
    return np.where(inside, pix, -1)


def view_polys(
    nside: int, pix, step: int = 2, *, lon0: float = math.pi / 2, flip: bool = True
) -> tuple[np.ndarray, np.ndarray]:
    """Map outlines (k', 4 step, 2) of the facets ``pix`` as :func:`draw_eye_view` draws
    them and which of ``pix`` cross the map's edge (drawn a second time, appended)."""
    return _view_polys(nside, pix, step, lon0, flip)


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
) -> PolyCollection | PathCollection:
    """One eye on ``ax`` (a Mollweide axes) seen from inside: the facets in ``lit[i]`` in
    ``colors[i]`` (a later feature wins), the equator drawn. ``all_facets`` (default: at
    most :data:`MAX_ALL_FACETS` facets per eye) draws every facet with its outline;
    otherwise only the lit facets are drawn, without outlines, one compound path per
    colour, over the unlit sphere drawn as one solid background."""
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
    coll: PolyCollection | PathCollection
    if all_facets:
        coll = PolyCollection(list(verts), facecolors=list(fc), edgecolors=EDGE, linewidths=0.3)
    else:  # one compound path per colour, no outline (0.3 pt would hide a facet of 0.003 in)
        names = sorted(set(fc.tolist()))
        paths = [compound_path(verts[fc == c]) for c in names]
        coll = PathCollection(paths, facecolors=names, edgecolors="none")
    ax.add_collection(coll, autolim=False)  # the map is the whole sphere already
    ax.plot([-math.pi, math.pi], [0.0, 0.0], color=equator, lw=0.6)
    ax.grid(False)
    ax.set_xticks([])
    ax.set_yticks([])
    return coll
