"""An eye's facets on a Mollweide map, for any eye model: one painter, fed by a facet
outline provider (:mod:`eyeviz.model.facet_patches`: HEALPix cells of the spherical
eyes, Voronoi patches of a measured eye's axes; docs/facet_maps.md).

Each facet is one polygon, its outline from the provider. Longitude is the model's (0 =
+x, counter-clockwise seen from above, docs/conventions.md). :func:`draw_eye_view` shows an
eye seen from inside, as the 3D figure (:mod:`eyeviz.render.mpl.figure3d`) and the app's
Facets panel draw it: longitude ``lon0`` (forward, pi/2) at the map's centre and mirrored,
so that the eye's right is on the map's right. A facet across the map's edge (the seam,
straight behind) is drawn on both sides and clipped by the map's outline; a patch that
holds a pole (its outline winds once round it) is closed along two meridians through
that pole, so each of its copies covers its side of the seam. Above
:data:`MAX_ALL_FACETS` facets per eye only the lit facets are drawn, as polygons over a
solid background of the unlit sphere: the whole eye at nside 180 is 388,800 polygons, far
too heavy for an SVG or PDF.

The maps' axes are :class:`MapAxes` (Mollweide without resampling). The way back from a
point of a map to a facet, for the app's hover: :func:`mollweide_inverse` (the
projection's closed-form inverse), :func:`model_lonlat` (the inverse of
:func:`view_lonlat`) and :func:`facet_at`, which asks the provider.

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

from eyeviz.model.facet_patches import FacetPatches

__all__ = [
    "MAX_ALL_FACETS",
    "POLE_POINTS",
    "MapAxes",
    "compound_path",
    "draw_eye_view",
    "facet_at",
    "map_width",
    "model_lonlat",
    "mollweide",
    "mollweide_inverse",
    "outline_lonlat",
    "view_lonlat",
    "view_polys",
]

UNLIT = "#eeeeee"
EDGE = "#b0b0b0"
#: Facets per eye above which :func:`draw_eye_view` draws only the lit facets (nside 32).
MAX_ALL_FACETS = 12_288
#: Points along each of the two meridians that close a patch round a pole.
POLE_POINTS = 8


class MapAxes(MollweideAxes):
    """Mollweide axes that do not resample paths: matplotlib's split every segment into 75
    (a facet of 8 vertices became 600, an SVG of the teaching scene 23 MB); the facets'
    outlines are already sampled along their edges, and curved lines are drawn sampled."""

    name = "eyeviz_mollweide"
    RESOLUTION = 1


def compound_path(verts: np.ndarray, counts: np.ndarray | None = None) -> Path:
    """One path of many closed polygons (k, n, 2), polygon i of its first ``counts[i]``
    points (default all n): drawn and written (SVG, PDF) as one element, not k (the lit
    facets of one colour on a map never overlap)."""
    k, n = verts.shape[:2]
    closed = np.concatenate([verts, verts[:, :1]], axis=1)
    codes = np.full((k, n + 1), Path.LINETO, dtype=Path.code_type)
    codes[:, 0] = Path.MOVETO
    codes[:, -1] = Path.CLOSEPOLY
    if counts is None or np.all(counts == n):
        return Path(closed.reshape(-1, 2), codes.ravel())
    keep = np.arange(n + 1)[None, :] < np.asarray(counts)[:, None]
    keep[:, -1] = True  # the closing point
    return Path(closed[keep], codes[keep])


def map_width(patches: FacetPatches) -> int:
    """Points per outline on the map: the provider's, and the two meridians and a point
    of a patch round a pole when the provider's patches may hold one."""
    return patches.width + (2 * POLE_POINTS + 1 if getattr(patches, "may_wind", False) else 0)


def outline_lonlat(
    v: np.ndarray, counts: np.ndarray | None = None, *, wind: bool = False
) -> tuple[np.ndarray, np.ndarray]:
    """(k, w, 2) (lon, lat) in radians of outlines ``v`` (k, n, 3) on the unit sphere, lon
    continuous along each outline and wrapped so that its first vertex lies in [-pi, pi),
    and the points that count per outline. ``wind``: an outline that winds round a pole is
    closed along the meridians of its first point (+- 2 pi) through that pole, and every
    outline gets 2 POLE_POINTS + 1 more points (padded with its last)."""
    lon = np.arctan2(v[..., 1], v[..., 0])
    lat = np.arcsin(np.clip(v[..., 2], -1.0, 1.0))
    # a vertex at a pole has no longitude; Mollweide draws a pole as one point whatever
    # its longitude, so it takes the next vertex's and the outline stays continuous
    pole = np.hypot(v[..., 0], v[..., 1]) < 1e-12
    lon = np.where(pole, np.roll(lon, -1, axis=-1), lon)
    lon = np.unwrap(lon, axis=-1)
    first = (lon[..., :1] + math.pi) % (2 * math.pi) - math.pi
    lon = lon - lon[..., :1] + first
    n = v.shape[-2]
    cnt = np.full(v.shape[0], n, np.int64) if counts is None else np.asarray(counts, np.int64)
    if not wind:
        return np.stack([lon, lat], axis=-1), cnt
    extra = 2 * POLE_POINTS + 1
    out = np.empty((v.shape[0], n + extra, 2))
    out[:, :n, 0], out[:, :n, 1] = lon, lat
    out[:, n:] = out[:, n - 1 : n]
    # the closing step from the last point to the first, and the winding it completes
    close = (lon[:, 0] - lon[:, -1] + math.pi) % (2 * math.pi) - math.pi
    turn = lon[:, -1] + close - lon[:, 0]
    winds = np.flatnonzero(np.abs(turn) > math.pi)
    for i in winds:  # a few patches at most (those round a pole)
        c = int(cnt[i])
        lon0, lat0 = lon[i, 0], lat[i, 0]
        pole_lat = math.copysign(math.pi / 2, float(np.mean(v[i, :c, 2])))
        down = np.linspace(lat0, pole_lat, POLE_POINTS)
        seq = np.concatenate(
            [
                [[lon0 + turn[i], lat0]],
                np.column_stack([np.full(POLE_POINTS, lon0 + turn[i]), down]),
                np.column_stack([np.full(POLE_POINTS, lon0), down[::-1]]),
            ]
        )
        out[i, c : c + extra] = seq
        out[i, c + extra :] = seq[-1]
        cnt[i] = c + extra
    return out, cnt


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


def facet_at(
    patches: FacetPatches, px, py, *, lon0: float = math.pi / 2, flip: bool = True
) -> np.ndarray:
    """The facet under points (px, py) of a :func:`draw_eye_view` map in the Mollweide
    plane (see :func:`mollweide_inverse`), -1 off the map or off every patch."""
    lon, lat, inside = mollweide_inverse(px, py)
    mlon, mlat = model_lonlat(lon, lat, lon0=lon0, flip=flip)
    pix = patches.at(mlon, mlat)
    return np.where(inside, pix, -1)


def view_polys(
    patches: FacetPatches, idx, *, lon0: float = math.pi / 2, flip: bool = True
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Map outlines (k', w, 2) of the facets ``idx`` as :func:`draw_eye_view` draws them,
    which of ``idx`` cross the map's edge (drawn a second time, appended) and the points
    that count per outline (k',)."""
    v, counts = patches.outlines(np.asarray(idx, np.int64))
    wind = getattr(patches, "may_wind", False)
    poly, cnt = outline_lonlat(v, counts, wind=wind)  # lon continuous along each outline
    lon = poly[..., 0] - lon0
    if flip:
        lon = -lon
    lo = lon.min(axis=-1, keepdims=True)
    lon = lon + ((lo + math.pi) % (2 * math.pi) - math.pi - lo)  # westmost in [-pi, pi)
    poly = np.stack([lon, poly[..., 1]], axis=-1)
    over = lon.max(axis=-1) > math.pi
    extra = poly[over].copy()
    extra[..., 0] -= 2 * math.pi
    return np.concatenate([poly, extra]), over, np.concatenate([cnt, cnt[over]])


def _trimmed(verts: np.ndarray, counts: np.ndarray) -> list[np.ndarray]:
    return [p[:c] for p, c in zip(verts, counts, strict=True)]


def draw_eye_view(
    ax: Axes,
    patches: FacetPatches,
    lit: Sequence[np.ndarray],
    colors: Sequence[str],
    *,
    lon0: float = math.pi / 2,
    flip: bool = True,
    all_facets: bool | None = None,
    equator: str = "#222222",
) -> PolyCollection | PathCollection:
    """One eye on ``ax`` (a Mollweide axes) seen from inside: the facets in ``lit[i]`` in
    ``colors[i]`` (a later feature wins), the equator drawn. ``all_facets`` (default: at
    most :data:`MAX_ALL_FACETS` facets per eye) draws every facet with its outline;
    otherwise only the lit facets are drawn, without outlines, one compound path per
    colour, over the unlit sphere drawn as one solid background."""
    n_pix = patches.n
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
    verts, over, counts = view_polys(patches, pix, lon0=lon0, flip=flip)
    fc = np.concatenate([face, face[over]])
    coll: PolyCollection | PathCollection
    if all_facets:
        coll = PolyCollection(
            _trimmed(verts, counts), facecolors=list(fc), edgecolors=EDGE, linewidths=0.3
        )
    else:  # one compound path per colour, no outline (0.3 pt would hide a facet of 0.003 in)
        names = sorted(set(fc.tolist()))
        paths = [compound_path(verts[fc == c], counts[fc == c]) for c in names]
        coll = PathCollection(paths, facecolors=names, edgecolors="none")
    ax.add_collection(coll, autolim=False)  # the map is the whole sphere already
    ax.plot([-math.pi, math.pi], [0.0, 0.0], color=equator, lw=0.6)
    ax.grid(False)
    ax.set_xticks([])
    ax.set_yticks([])
    return coll
