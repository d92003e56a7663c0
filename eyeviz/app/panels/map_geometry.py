"""Geometry of the Facets dock's Mollweide maps (:mod:`eyeviz.app.panels.bitmaps3d`): the
lit facets' outlines in the map's plane (kept from frame to frame), one compound path per
ball, the map's outline, and the side the equator's label goes."""

from __future__ import annotations

import math
import weakref
from typing import Any

import numpy as np

from eyeviz.model.facet_patches import FacetPatches, HealpixPatches
from eyeviz.render.mpl.facet_map import compound_path, map_width, mollweide, view_lonlat, view_polys
from eyeviz.render.mpl.style import EDGE

__all__ = [
    "Outlines", "all_polys", "by_ball", "edge_colour", "ellipse", "equator_fit", "fit_words",
    "label_side", "lit_owners", "place_side_words",
    "map_polys", "R2", "SIDE_WORDS", "side_words", "title_fit",
]  # fmt: skip

R2 = math.sqrt(2.0)


def map_polys(patches: FacetPatches, pix: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Facet outlines in the Mollweide plane, those across the map's edge twice, and the
    points that count per outline."""
    verts, over, counts = view_polys(patches, pix)
    x, y = mollweide(verts[..., 0], verts[..., 1])
    return np.stack([x, y], axis=-1), over, counts


#: every facet's map outlines (all_polys), by the patches' cells: a window's Facets dock
#: drew them at each new pair of eyes (0.1-0.2 s of numpy for 12,288 facets), and each
#: window of the same eyes again
_ALL: weakref.WeakKeyDictionary[Any, tuple[np.ndarray, np.ndarray, np.ndarray]] = (
    weakref.WeakKeyDictionary()
)
_HEALPIX_ALL: dict[tuple[int, ...], tuple[np.ndarray, np.ndarray, np.ndarray]] = {}


def all_polys(patches: FacetPatches) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`map_polys` of every facet of ``patches``, computed once for each patches (a
    HEALPix eye's once for each nside and step); the arrays are read-only."""
    return _once(
        _ALL, _HEALPIX_ALL, ("nside", "step"), patches,
        lambda: _frozen(map_polys(patches, np.arange(patches.n))),
    )  # fmt: skip


def _once(weak, healpix: dict, fields: tuple[str, ...], patches: FacetPatches, compute):
    """``compute()`` once for each ``patches``: a HEALPix eye's kept in ``healpix`` by
    its ``fields`` (every window's eye of one nside shares it), another's in ``weak`` by
    the patches themselves (or computed each time if they are not weakly referable)."""
    if isinstance(patches, HealpixPatches):
        key = tuple(getattr(patches, f) for f in fields)
        got = healpix.get(key)
        if got is None:
            got = healpix[key] = compute()
        return got
    try:
        got = weak.get(patches)
    except TypeError:  # not weakly referable: computed each time
        return compute()
    if got is None:
        got = weak[patches] = compute()
    return got


def _frozen(arrays: tuple[np.ndarray, np.ndarray, np.ndarray]):
    for a in arrays:
        a.setflags(write=False)
    return arrays


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


#: label_side's answers, by the patches' cells: every facet's centre is computed (388,800
#: of them at nside 180), and the maps asked it at each layout (each text scale, resize
#: and lecture step) of every window
_SIDES: weakref.WeakKeyDictionary[Any, int] = weakref.WeakKeyDictionary()
_HEALPIX_SIDES: dict[tuple[int, ...], int] = {}


def label_side(patches: FacetPatches) -> int:
    """-1 (left) or 1 (right): where the equator's label goes. The right only where the
    outer 65 % of the left half map holds more than twice as many facets near the
    equator as the right's (a measured left eye's); a HEALPix eye keeps it on the left.
    Computed once for each patches (a HEALPix eye's once for each nside)."""
    return _once(_SIDES, _HEALPIX_SIDES, ("nside",), patches, lambda: _label_side(patches))


def _label_side(patches: FacetPatches) -> int:
    c = patches.centers(np.arange(patches.n))
    lon, lat = view_lonlat(np.arctan2(c[:, 1], c[:, 0]), np.arcsin(np.clip(c[:, 2], -1, 1)))
    near = np.abs(lat) < 0.25
    left = int(np.count_nonzero(near & (lon < -0.35 * math.pi)))
    right = int(np.count_nonzero(near & (lon > 0.35 * math.pi)))
    return 1 if left > 2 * right else -1


def ellipse(n: int = 181) -> np.ndarray:
    t = np.linspace(0.0, 2.0 * math.pi, n)
    return np.stack([2 * R2 * np.cos(t), R2 * np.sin(t)], axis=-1)


def equator_fit(
    t: Any, full: str, renderer: Any, dpi: float, box_w: float, box_h: float
) -> tuple[str, float]:
    """Set the equator's label ``t`` (a matplotlib text) to the first form that fits
    beside the map (the whole one ``full``, else "equator", else none) and return it with
    its width in inches, as the renderer draws it: at most a quarter of the box's width
    (``box_w`` inches), and no taller than 60 % of the map's box (``box_h``)."""
    t.set_visible(True)  # matplotlib measures a hidden text as a 1 px box
    for text in (full, "equator"):
        t.set_text(text)
        box = t.get_window_extent(renderer)
        w, h = box.width / dpi, box.height / dpi
        if w <= 0.25 * box_w and h <= 0.6 * box_h:
            return text, w
    t.set_text("")
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


def fit_words(texts: list[Any], renderer: Any, dpi: float, box_w: float, box_h: float,
              zoomed: bool) -> float:  # fmt: skip
    """The maps' words ``texts`` (matplotlib texts) at the maps' size now, measured as
    the renderer draws them: "forward" shown on the whole map, each title in the first
    form that fits the maps' width ``box_w`` inches (:func:`title_fit`), the equator's
    label in the first that fits beside the map (:func:`equator_fit`). Returns the room
    in inches the equator's label takes beside the whole map."""
    label_in = 0.0
    for t in texts:
        if t.get_text() == "forward":
            t.set_visible(not zoomed)
        elif t.get_gid() == "maptitle":
            t.set_visible(True)  # (hidden while the panel could not hold it)
            title_fit(t, box_w * dpi, renderer)
        elif t.get_gid() == "equator":
            full = str(t.get_url() or t.get_text())
            t.set_url(full)  # the whole label kept (the short form may be shown)
            text, label_in = equator_fit(t, full, renderer, dpi, box_w, box_h)
            t.set_visible(bool(text) and not zoomed)
    return label_in


def place_side_words(axes: list[Any], renderer: Any, fig: Any, zoomed: bool) -> None:
    """On each map (matplotlib axes, their limits set): a word the figure (its box
    ``fig``) cannot hold whole gives way (at 300 % "forward" fell off the bottom), then
    "left" and "right" are placed (:func:`side_words`)."""
    for ax in axes:
        ax.apply_aspect()  # the map's box as it will be drawn (equal aspect)
        for t in ax.texts:
            if t.get_visible() and not _inside(t.get_window_extent(renderer), fig):
                t.set_visible(False)
        words = {t.get_text(): t for t in ax.texts if t.get_text() in SIDE_WORDS}
        equator = [t for t in ax.texts if t.get_gid() == "equator" and t.get_visible()]
        side_words(words, equator, renderer, fig, zoomed)


def _inside(box: Any, fig: Any) -> bool:
    """Whether ``box`` lies inside the figure's box ``fig`` (half a pixel's slack)."""
    return (
        fig.x0 - 0.5 <= box.x0
        and box.x1 <= fig.x1 + 0.5
        and (fig.y0 - 0.5 <= box.y0 and box.y1 <= fig.y1 + 0.5)
    )


#: the words under each map, placed by :func:`side_words`
SIDE_WORDS = ("left", "forward", "right")
GAP_PX = 6.0  # the least room between two words


def side_words(words: dict[str, Any], others: list[Any], renderer: Any, fig: Any,
               zoomed: bool) -> None:  # fmt: skip
    """Place a map's words "left" and "right" (matplotlib texts under the map, "forward"
    at its middle), each measured as drawn: flush with the map's ends inside it where
    none overlaps another (GAP_PX apart), else beside the ends, outside the map, where
    they overlap neither "forward" nor ``others`` (the equator's label) and stay in the
    figure (its box ``fig``, pixels), else hidden (F11 + F5 + 175 % at 1280 x 720: the
    words had been placed by a width estimate of 0.62 em a character); hidden on a
    zoomed map (the words name the whole map's places)."""
    left, fwd, right = (words.get(w) for w in SIDE_WORDS)
    if left is None or right is None:
        return
    pair = (left, right)
    if zoomed:
        for t in pair:
            t.set_visible(False)
        return
    fixed = [t.get_window_extent(renderer) for t in others]
    if fwd is not None and fwd.get_visible():
        fixed.append(fwd.get_window_extent(renderer))

    def clear(inside: bool) -> bool:
        left.set_x(-2.0 * R2 * (1.0 if inside else 1.03))
        right.set_x(2.0 * R2 * (1.0 if inside else 1.03))
        left.set_horizontalalignment("left" if inside else "right")
        right.set_horizontalalignment("right" if inside else "left")
        for t in pair:
            t.set_visible(True)  # measured as drawn (a hidden text is a 1 px box)
        boxes = [t.get_window_extent(renderer) for t in pair]
        if any(b.x0 < fig.x0 or b.x1 > fig.x1 or b.y0 < fig.y0 or b.y1 > fig.y1 for b in boxes):
            return False
        every = boxes + fixed
        return not any(
            _apart(every[i], every[j]) < GAP_PX
            for i in range(len(boxes)) for j in range(i + 1, len(every))
        )  # fmt: skip

    shown = clear(True) or clear(False)
    for t in pair:
        t.set_visible(shown)


def _apart(a: Any, b: Any) -> float:
    """How far apart two boxes are in pixels (negative: they overlap) along the axis
    that separates them best."""
    dx = max(b.x0 - a.x1, a.x0 - b.x1)
    dy = max(b.y0 - a.y1, a.y0 - b.y1)
    return max(dx, dy)
