"""Each facet of an eye as a patch of the sphere of directions: what a map of the facets
draws, for any eye model (docs/facet_maps.md).

A *facet outline provider* answers, for one eye:

- ``outlines(idx)``: the patches' closed outlines, unit vectors (k, width, 3) with the
  number of points that count (k,) (an outline with fewer is padded by repeating its
  last point);
- ``centers(idx)``: each facet's direction (k, 3);
- ``at(lon, lat)``: the facet whose patch holds each direction (azimuth from +x
  counter-clockwise seen from above, elevation; radians), -1 where none does;
- ``describe(i)``: one line for a hover (index, direction, the facet's size).

Two providers:

- :class:`HealpixPatches` (the spherical eyes): the HEALPix cells
  (:func:`eyeviz.core.healpix.boundaries`, RING order), which tile the sphere;
  ``at`` is :func:`eyeviz.core.healpix.ang2pix_ring`.
- :class:`VoronoiPatches` (measured eyes): the spherical Voronoi cells of the facets' unit
  axes (``scipy.spatial.SphericalVoronoi``): each direction belongs to the facet whose
  axis is nearest to it. A real eye sees part of the sphere only, and the cells at the
  edge of its field reach far beyond it, so every cell is cut to the cap of radius
  ``reach_i = max(acceptance_i / 2, 3 x the median angle between neighbouring axes)`` about its
  axis: a direction is on facet i's patch iff axis i is the nearest to it and at most
  ``reach_i`` from it. A cell cut by its cap is outlined at :data:`CAP_POINTS` bearings
  about its axis (the nearer of the cell's edge and the cap); the others by their
  Voronoi vertices, ``step`` points per great-circle edge. Axes that coincide (to
  :data:`SAME_AXIS`) share one cell; where the Voronoi diagram does not exist (fewer than
  four distinct axes, or all on one great circle: a planar ring written as a measured
  eye) every cell is outlined from the bisectors with its :data:`NEIGHBOURS` nearest
  axes, cut by its cap the same way.

The patches of a measured pair are fixed: :func:`facet_patches` keeps them per pair (by
its fingerprint) and eye. Pure numpy and scipy; no matplotlib, Qt or VTK.
"""

from __future__ import annotations

import math
from collections import OrderedDict
from collections.abc import Callable
from functools import lru_cache
from typing import Any, Protocol

import numpy as np

from eyeviz.core import healpix

__all__ = [
    "CAP_POINTS",
    "FacetPatches",
    "HealpixPatches",
    "VoronoiPatches",
    "direction_text",
    "facet_patches",
    "patches_caption",
    "patches_caption_forms",
]

#: Bearings about its axis at which a cell cut by its cap is outlined.
CAP_POINTS = 24
#: A patch reaches at most this many times the eye's median angle between neighbouring
#: axes from its axis (or half its acceptance, if more): the cells at the edge of a real
#: eye's field would otherwise reach over the sky it does not see (their Voronoi cells
#: span 20-100 deg against 1-3 deg for 95 % of the honeybee's).
REACH_SPACINGS = 3.0
#: Axes closer than this (radians) are one generator of the Voronoi diagram.
SAME_AXIS = 1e-6
#: Neighbours whose bisectors outline a cell where the Voronoi diagram does not exist.
NEIGHBOURS = 12
#: Measured pairs whose patches are kept (a pair's are fixed; a few pairs at most open).
CACHE_PAIRS = 4
DEG = "\N{DEGREE SIGN}"


class FacetPatches(Protocol):
    """What a map of one eye's facets asks of its eye model (see the module docstring)."""

    #: facets on this eye
    n: int
    #: points per outline (the padded width of :meth:`outlines`)
    width: int
    #: whether a patch may hold a pole strictly inside (its outline then winds round it)
    may_wind: bool

    def outlines(self, idx: np.ndarray) -> tuple[np.ndarray, np.ndarray]: ...

    def centers(self, idx: np.ndarray) -> np.ndarray: ...

    def at(self, lon, lat) -> np.ndarray: ...

    def describe(self, i: int) -> str: ...


def direction_text(v: np.ndarray) -> str:
    """'azimuth a°, elevation e°' of a direction (azimuth from +x counter-clockwise seen
    from above, forward = 90; elevation from the plane z = 0; docs/conventions.md)."""
    az = math.degrees(math.atan2(float(v[1]), float(v[0]))) % 360.0
    el = math.degrees(math.asin(max(-1.0, min(1.0, float(v[2]) / float(np.linalg.norm(v))))))
    return f"azimuth {az:.2f}{DEG}, elevation {el:.2f}{DEG}"


class HealpixPatches:
    """The HEALPix cells of nside ``nside`` (RING order), ``step`` points per edge."""

    def __init__(self, nside: int, step: int = 2) -> None:
        self.nside = int(nside)
        self.step = int(step)
        self.n = healpix.npix(self.nside)
        self.width = 4 * self.step
        self.may_wind = False  # the cells at a pole have a vertex there

    def outlines(self, idx) -> tuple[np.ndarray, np.ndarray]:
        idx = np.asarray(idx, np.int64)
        v = healpix.boundaries(self.nside, idx, self.step)
        return v, np.full(idx.shape, self.width, np.int64)

    def centers(self, idx) -> np.ndarray:
        return healpix.centers(self.nside, np.asarray(idx, np.int64))

    def at(self, lon, lat) -> np.ndarray:
        return healpix.ang2pix_ring(self.nside, np.sin(lat), lon)

    def describe(self, i: int) -> str:
        """A facet's RING index, direction and solid angle (4 pi / npix: every HEALPix
        facet has the same)."""
        sr = 4.0 * math.pi / self.n
        return (
            f"facet {i:,}: {direction_text(self.centers(np.array([i]))[0])}, "
            f"{sr:.3g} sr = {sr * (180.0 / math.pi) ** 2:.3g} deg\N{SUPERSCRIPT TWO}"
        )


def _slerp(a: np.ndarray, b: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Points of the great-circle arcs a -> b (..., 3) at fractions t (s,): (..., s, 3)."""
    ang = np.arccos(np.clip((a * b).sum(-1), -1.0, 1.0))[..., None, None]
    s = np.sin(ang)
    tt = t[:, None]
    with np.errstate(invalid="ignore", divide="ignore"):
        wa = np.where(s > 1e-12, np.sin((1 - tt) * ang) / np.where(s > 1e-12, s, 1), 1 - tt)
        wb = np.where(s > 1e-12, np.sin(tt * ang) / np.where(s > 1e-12, s, 1), tt)
    p = wa * a[..., None, :] + wb * b[..., None, :]
    return p / np.linalg.norm(p, axis=-1, keepdims=True)


class VoronoiPatches:
    """The Voronoi patches of one measured eye (see the module docstring): ``axes``
    (n, 3) non-zero, ``acceptance`` (n,) full angles in radians."""

    def __init__(self, axes, acceptance, step: int = 2) -> None:
        u = np.asarray(axes, np.float64)
        u = u / np.linalg.norm(u, axis=1, keepdims=True)
        acc = np.asarray(acceptance, np.float64)
        self.n = u.shape[0]
        self.step = int(step)
        self.axes = u
        self.acceptance = acc
        # one generator per group of coinciding axes; rep[i] is facet i's generator
        from scipy.spatial import cKDTree  # measured eyes only: HEALPix never loads it

        gen, rep = _merge_same(u)
        self.gen_axes = u[gen]
        self.rep = rep
        self.tree = cKDTree(self.gen_axes)
        if len(gen) > 1:
            d, _ = self.tree.query(self.gen_axes, 2)
            spacing = float(np.median(2.0 * np.arcsin(np.minimum(d[:, 1] / 2.0, 1.0))))
        else:
            spacing = math.pi / 2
        # a generator's reach: the largest of its facets' half acceptances, or the spacing
        half = np.zeros(len(gen))
        np.maximum.at(half, rep, acc / 2.0)
        self.reach = np.maximum(half, REACH_SPACINGS * spacing)
        self.spacing = spacing
        self._verts, self._counts = self._build()
        self.width = int(self._verts.shape[1])
        self.may_wind = True

    def _build(self) -> tuple[np.ndarray, np.ndarray]:
        """Outlines (generators, width, 3) and counts of every generator's patch."""
        from scipy.spatial import QhullError, SphericalVoronoi

        g = self.gen_axes
        k = len(g)
        try:
            sv = SphericalVoronoi(g, 1.0, np.zeros(3))
            sv.sort_vertices_of_regions()
        except (ValueError, QhullError):  # < 4 generators, or all on one great circle
            return self._cut(np.arange(k), *self._bisectors())
        lens = np.array([len(r) for r in sv.regions], np.int64)
        big = int(lens.max())
        vi = np.empty((k, big, 3))  # each cell's vertices, the last repeated
        for m in np.unique(lens):
            rows = np.flatnonzero(lens == m)
            idx = np.array([sv.regions[i] for i in rows], np.int64)
            vi[rows, :m] = sv.vertices[idx]
            vi[rows, m:] = sv.vertices[idx[:, -1:]]
        ang = np.arccos(np.clip(np.einsum("kvj,kj->kv", vi, g), -1.0, 1.0))
        far = (ang > self.reach[:, None]).any(axis=1)
        t = np.arange(self.step) / self.step
        loops: dict[int, tuple[np.ndarray, np.ndarray]] = {}
        for m in np.unique(lens[~far]):  # the Voronoi cells, their edges sampled
            rows = np.flatnonzero((lens == m) & ~far)
            v = vi[rows, :m]
            pts = _slerp(v, np.roll(v, -1, axis=1), t).reshape(len(rows), -1, 3)
            loops[int(m)] = (rows, pts)
        # the cells cut by their caps: the planes of their edges, and their vertices in
        # the cap as extra bearings
        cut = np.flatnonzero(far)
        normals = np.cross(vi[cut], np.roll(vi[cut], -1, axis=1))
        normals *= np.sign(np.einsum("kvj,kj->kv", normals, g[cut]))[..., None]
        inside = np.where((ang[cut] <= self.reach[cut, None])[..., None], vi[cut], np.nan)
        cv, cn = self._cut(cut, normals, inside)
        width = max([cv.shape[1]] + [p.shape[1] for _, p in loops.values()])
        out = np.empty((k, width, 3))
        counts = np.empty(k, np.int64)
        for rows, pts in [*loops.values(), (cut, cv)]:
            out[rows, : pts.shape[1]] = pts
            out[rows, pts.shape[1] :] = pts[:, -1:]
        for rows, pts in loops.values():
            counts[rows] = pts.shape[1]
        counts[cut] = cn
        return out, counts

    def _bisectors(self) -> tuple[np.ndarray, np.ndarray]:
        """Per generator the planes bisecting it and its NEIGHBOURS nearest (g - n_j; a
        zero row where there are fewer), and no extra bearings."""
        g = self.gen_axes
        k = min(NEIGHBOURS + 1, len(g))
        _, nb = self.tree.query(g, k)
        nb = nb.reshape(len(g), k)
        normals = g[:, None, :] - g[nb]  # the generator itself gives a zero row
        return normals, np.full((len(g), 1, 3), np.nan)

    def _cut(self, rows, normals, extra) -> tuple[np.ndarray, np.ndarray]:
        """Outlines of generators ``rows`` from their planes ``normals`` (r, m, 3) cut to
        their caps, at CAP_POINTS bearings and those of the points ``extra`` (r, e, 3;
        NaN rows unused): (r, width, 3) padded, and the counts."""
        g = self.gen_axes[rows]
        r = len(rows)
        helper = np.where(np.abs(g[:, 2:3]) < 0.9, [[0.0, 0.0, 1.0]], [[1.0, 0.0, 0.0]])
        e1 = np.cross(helper, g)
        e1 /= np.linalg.norm(e1, axis=1, keepdims=True)
        e2 = np.cross(g, e1)
        uni = np.broadcast_to(
            np.linspace(0.0, 2 * math.pi, CAP_POINTS, endpoint=False), (r, CAP_POINTS)
        )
        more = np.arctan2(np.einsum("rej,rj->re", extra, e2), np.einsum("rej,rj->re", extra, e1))
        psi = np.sort(np.concatenate([uni, np.mod(more, 2 * math.pi)], axis=1), axis=1)
        counts = np.isfinite(psi).sum(axis=1)
        psi = np.where(np.isfinite(psi), psi, np.nanmax(psi, axis=1, keepdims=True))
        t = np.cos(psi)[..., None] * e1[:, None] + np.sin(psi)[..., None] * e2[:, None]
        gn = np.einsum("rmj,rj->rm", normals, g)
        tn = np.einsum("rbj,rmj->rbm", t, normals)
        with np.errstate(invalid="ignore"):
            rho = np.where(tn < 0, np.arctan2(gn[:, None, :], -tn), np.inf)
        rad = np.minimum(rho.min(axis=2), self.reach[rows, None])
        pts = np.cos(rad)[..., None] * g[:, None] + np.sin(rad)[..., None] * t
        return pts, counts

    def outlines(self, idx) -> tuple[np.ndarray, np.ndarray]:
        r = self.rep[np.asarray(idx, np.int64)]
        return self._verts[r], self._counts[r]

    def centers(self, idx) -> np.ndarray:
        return self.axes[np.asarray(idx, np.int64)]

    def at(self, lon, lat) -> np.ndarray:
        """The facet whose patch holds each direction (the last facet of a group of
        coinciding axes, the one drawn on top), -1 outside every patch."""
        lon, lat = np.broadcast_arrays(np.asarray(lon, np.float64), np.asarray(lat, np.float64))
        shape = lon.shape
        c = np.cos(lat.ravel())
        d = np.stack([c * np.cos(lon.ravel()), c * np.sin(lon.ravel()), np.sin(lat.ravel())], 1)
        dist, gi = self.tree.query(d)
        ang = 2.0 * np.arcsin(np.minimum(dist / 2.0, 1.0))
        last = np.zeros(len(self.gen_axes), np.int64)
        last[self.rep] = np.arange(self.n)  # numpy assigns in order: the last facet wins
        out = np.where(ang <= self.reach[gi], last[gi], -1)
        return out.reshape(shape)

    def describe(self, i: int) -> str:
        """A facet's index, axis direction and full acceptance angle."""
        return (
            f"facet {i:,}: axis {direction_text(self.axes[i])}, "
            f"acceptance {math.degrees(float(self.acceptance[i])):.2f}{DEG}"
        )


def _merge_same(u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(generators: the first facet of each group of axes within SAME_AXIS of another,
    rep: each facet's generator number)."""
    from scipy.spatial import cKDTree

    n = u.shape[0]
    pairs = cKDTree(u).query_pairs(2.0 * math.sin(SAME_AXIS / 2.0), output_type="ndarray")
    parent = np.arange(n)
    if len(pairs):
        from scipy.sparse import coo_matrix
        from scipy.sparse.csgraph import connected_components

        adj = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(n, n))
        _, labels = connected_components(adj, directed=False)
        first = np.full(labels.max() + 1, n)
        np.minimum.at(first, labels, np.arange(n))
        parent = first[labels]
    gen, rep = np.unique(parent, return_inverse=True)
    return gen, rep.astype(np.int64)


@lru_cache(maxsize=8)
def _healpix(nside: int, step: int) -> HealpixPatches:
    return HealpixPatches(nside, step)


_MEASURED: OrderedDict[tuple[str, str, int], VoronoiPatches] = OrderedDict()


def _healpix_patches(pair: Any, eye: str, step: int) -> FacetPatches:
    return _healpix(int(pair.nside), int(step))


def _measured_patches(pair: Any, eye: str, step: int) -> FacetPatches:
    key = (pair.fingerprint, eye, int(step))
    hit = _MEASURED.get(key)
    if hit is None:
        _pos, axes, acc = pair.facets(eye)
        hit = _MEASURED[key] = VoronoiPatches(axes, acc, step)
        while len(_MEASURED) > 2 * CACHE_PAIRS:
            _MEASURED.popitem(last=False)
    _MEASURED.move_to_end(key)
    return hit


def _healpix_caption(p: Any) -> tuple[str, ...]:
    return (f"nside {p.nside}, {p.npix:,} facets per eye", f"nside {p.nside}, {p.npix:,} facets",
            f"{p.npix:,} facets")  # fmt: skip


def _measured_caption(p: Any) -> tuple[str, ...]:
    a, b = p.facet_counts
    return (f"{a:,} (A) and {b:,} (B) measured facets", f"{a:,} + {b:,} measured facets",
            f"{a:,} + {b:,} facets")  # fmt: skip


#: Each eye model's facet outlines and their caption's forms, longest first, by
#: ``pair.kind`` (the row a new model in space adds): HEALPix cells of the spherical
#: pair's nside; Voronoi patches about a measured pair's facet axes.
PATCHES: dict[
    str, tuple[Callable[[Any, str, int], FacetPatches], Callable[[Any], tuple[str, ...]]]
] = {
    "spherical": (_healpix_patches, _healpix_caption),
    "measured": (_measured_patches, _measured_caption),
}


def _row(pair: Any):
    row = PATCHES.get(pair.kind)
    if row is None:
        raise ValueError(f"no facet map for {pair.kind!r} eyes (known: {', '.join(PATCHES)})")
    return row


def facet_patches(pair: Any, eye: str, step: int = 2) -> FacetPatches:
    """The outline provider of eye ``eye`` ("A" or "B") of an eye model: HEALPix cells of a
    spherical pair, Voronoi patches of a measured one (kept for the CACHE_PAIRS pairs
    used last, by fingerprint)."""
    if eye not in ("A", "B"):
        raise ValueError(f"eye must be 'A' or 'B', got {eye!r}")
    return _row(pair)[0](pair, eye, step)


def patches_caption(pair: Any) -> str:
    """The eyes' facets in a few words: 'nside 8, 768 facets per eye' or '3,187 (A) and
    3,187 (B) measured facets'."""
    return _row(pair)[1](pair)[0]


def patches_caption_forms(pair: Any) -> tuple[str, ...]:
    """:func:`patches_caption` and its shorter forms, longest first, for a panel that
    shows the first one its width holds: '3,187 (A) and 3,187 (B) measured facets',
    '3,187 + 3,187 measured facets', '3,187 + 3,187 facets'."""
    return _row(pair)[1](pair)
