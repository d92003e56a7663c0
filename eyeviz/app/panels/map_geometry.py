"""Geometry of the Facets dock's Mollweide maps (:mod:`eyeviz.app.panels.bitmaps3d`): the
lit facets' outlines in the map's plane (kept from frame to frame), one compound path per
ball, the map's outline, and the side the equator's label goes."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from eyeviz.model.facet_patches import FacetPatches
from eyeviz.render.mpl.facet_map import compound_path, map_width, mollweide, view_lonlat, view_polys
from eyeviz.render.mpl.style import EDGE

__all__ = [
    "Outlines", "by_ball", "edge_colour", "ellipse", "equator_fit", "label_side", "lit_owners",
    "map_polys", "R2", "side_word", "title_fit",
]  # fmt: skip

R2 = math.sqrt(2.0)


def map_polys(patches: FacetPatches, pix: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Facet outlines in the Mollweide plane, those across the map's edge twice, and the
    points that count per outline."""
    verts, over, counts = view_polys(patches, pix)
    x, y = mollweide(verts[..., 0], verts[..., 1])
    return np.stack([x, y], axis=-1), over, counts


class Outlines:
    """Facet outlines in the Mollweide plane of one eye, the last call's kept: a drag
    lights mostly the facets lit a frame before, and only the others are computed."""

    def __init__(self, patches: FacetPatches) -> None:
        self.patches = patches
        w = map_width(patches)
        self.pix = np.zeros(0, np.int64)
        self.base = np.zeros((0, w, 2))
        self.dup = np.zeros((0, w, 2))  # the second copy (where ``over``)
        self.over = np.zeros(0, bool)
        self.counts = np.zeros(0, np.int64)

    def get(self, pix: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """(outlines, across the edge, second copies, points per outline) of the sorted
        facets ``pix``."""
        k = pix.size
        w = self.base.shape[1]
        at = np.minimum(np.searchsorted(self.pix, pix), max(self.pix.size - 1, 0))
        hit = self.pix[at] == pix if self.pix.size else np.zeros(k, bool)
        base = np.empty((k, w, 2))
        dup = np.empty((k, w, 2))
        over = np.zeros(k, bool)
        counts = np.zeros(k, np.int64)
        h = at[hit]
        base[hit], dup[hit], over[hit], counts[hit] = (
            self.base[h], self.dup[h], self.over[h], self.counts[h]
        )  # fmt: skip
        new = np.flatnonzero(~hit)
        if new.size:
            verts, o, c = map_polys(self.patches, pix[new])
            base[new], over[new], counts[new] = verts[: new.size], o, c[: new.size]
            dup[new[o]] = verts[new.size :]
        self.pix, self.base, self.dup, self.over, self.counts = pix, base, dup, over, counts
        return base, over, dup, counts


def by_ball(verts: np.ndarray, owner: np.ndarray, rgba: np.ndarray, counts: np.ndarray):
    """One compound path per ball (its facets' outlines) and the balls' colours."""
    if owner.size == 0:
        return [], np.zeros((0, 4))
    order = np.argsort(owner, kind="stable")
    groups = np.split(order, np.flatnonzero(np.diff(owner[order])) + 1)
    paths = [compound_path(verts[g], counts[g]) for g in groups]
    return paths, rgba[[int(owner[g[0]]) for g in groups]]


def label_side(patches: FacetPatches) -> int:
    """-1 (left) or 1 (right): where the equator's label goes. The right only where the
    outer 65 % of the left half map holds more than twice as many facets near the
    equator as the right's (a measured left eye's); a HEALPix eye keeps it on the left."""
    c = patches.centers(np.arange(patches.n))
    lon, lat = view_lonlat(np.arctan2(c[:, 1], c[:, 0]), np.arcsin(np.clip(c[:, 2], -1, 1)))
    near = np.abs(lat) < 0.25
    left = int(np.count_nonzero(near & (lon < -0.35 * math.pi)))
    right = int(np.count_nonzero(near & (lon > 0.35 * math.pi)))
    return 1 if left > 2 * right else -1


def ellipse(n: int = 181) -> np.ndarray:
    t = np.linspace(0.0, 2.0 * math.pi, n)
    return np.stack([2 * R2 * np.cos(t), R2 * np.sin(t)], axis=-1)


def equator_fit(full: str, char_in: float, box_w: float, box_h: float) -> tuple[str, float]:
    """The equator's label that fits beside the map (the whole one, else "equator", else
    none) and its width in inches: at most a quarter of the box's width, and no taller
    than the map's middle third."""
    for text in (full, "equator"):
        lines = text.split("\n")
        w = max(len(x) for x in lines) * char_in
        h = len(lines) * 1.25 * char_in / 0.62
        if w <= 0.25 * box_w and h <= 0.6 * box_h:
            return text, w
    return "", 0.0


def title_fit(t: Any, width_px: float, renderer: Any) -> None:
    """A map's title ``t`` (a matplotlib text) in the first form that fits ``width_px``
    figure pixels: the whole one ("eye A (left), seen from inside"), else "eye A (left)",
    else "eye A" (at F11 + F5 + 175 % in 1280 x 720 the whole one was cut at both sides
    of the 390 px dock); the whole one is kept as the text's url."""
    full = str(t.get_url() or t.get_text())
    t.set_url(full)
    for text in (full, full.split(",")[0], full.split(" (")[0]):
        t.set_text(text)
        if t.get_window_extent(renderer).width <= width_px:
            return


def lit_owners(csr: tuple[np.ndarray, np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """(lit facets sorted, the ball that colours each) from an eye's CSR lit sets; a later
    ball wins where several light a facet (as the planar app and the 3D figure)."""
    indptr, idx = csr
    ball = np.repeat(np.arange(indptr.size - 1), np.diff(indptr))
    pix, first = np.unique(idx[::-1], return_index=True)  # the last ball's occurrence
    return pix, ball[::-1][first]


#: Above this many facets an eye (HEALPix nside 16) the outlines are drawn lighter: a
#: measured eye's 3,000 facets are a few pixels each in the dock, and EDGE turned the map grey
DENSE = 3072
EDGE_DENSE = "#cdcdcd"


def edge_colour(n: int) -> str:
    return EDGE if n <= DENSE else EDGE_DENSE


def side_word(t: Any, map_in: float, box_w: float, char_in: float, zoomed: bool) -> None:
    """Place the map's word "left" or "right" (text ``t``, under the map): flush with the
    map's end inside it where the map is wide enough for left / forward / right (~22
    characters of ``char_in`` inches), else beside that end, outside the map, where the
    box (``box_w`` inches wide) leaves it room and "forward" still fits the map (F11 + F5
    at 1280 x 720, sphere_lecture's step 8: the maps dropped them), else hidden; hidden
    on a zoomed map (the words name the whole map's places)."""
    word = t.get_text()
    wide = map_in >= 22 * char_in
    beside = (box_w - map_in) / 2.0 >= 6.5 * char_in and map_in >= 9 * char_in
    t.set_x((-2.0 if word == "left" else 2.0) * R2 * (1.0 if wide else 1.03))
    inner, outer = (word, "right" if word == "left" else "left")
    t.set_horizontalalignment(inner if wide else outer)
    t.set_visible((wide or beside) and not zoomed)
