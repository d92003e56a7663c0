"""Cameras of the 2D top view as plain maths: pixel <-> model, zoom, pan, fit (no Qt, no VTK).

The view is a parallel projection without rotation: a :class:`~eyeviz.model.scene.View`
(centre and width in model units) shown in a :class:`Viewport` (a rectangle of widget
pixels, y down). The window only measures its widgets and hands these functions pixels;
tests drive them with plain numbers and no display.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from eyeviz.model.scene import Eyes, Scene, View

__all__ = [
    "INSET_TEXT_PX",
    "MAX_WIDTH",
    "MIN_WIDTH",
    "ZOOM_STEP",
    "Viewport",
    "discs_meet",
    "fit_inset",
    "fit_view",
    "pan",
    "to_model",
    "to_pixel",
    "units_per_px",
    "zoom_about",
]

ZOOM_STEP = 1.15  # one wheel notch
MIN_WIDTH = 1e-6
MAX_WIDTH = 1e9
FIT_MARGIN = 1.15
INSET_TEXT_PX = 24.0  # a line of text in the inset


@dataclass(frozen=True)
class Viewport:
    """A renderer's rectangle in widget pixels: left, top, width, height (y down)."""

    left: float
    top: float
    width: float
    height: float

    def contains(self, px: float, py: float) -> bool:
        return (
            self.left <= px <= self.left + self.width and self.top <= py <= self.top + self.height
        )


def units_per_px(view: View, vp: Viewport) -> float:
    """Model units per pixel (the same along x and y: no anisotropic scaling)."""
    return view.width / max(vp.width, 1e-9)


def to_model(view: View, vp: Viewport, px: float, py: float) -> tuple[float, float]:
    """Widget pixel -> model (x, y); the viewport's centre shows the view's centre."""
    u = units_per_px(view, vp)
    cx, cy = view.center
    return (
        cx + (px - vp.left - vp.width / 2.0) * u,
        cy - (py - vp.top - vp.height / 2.0) * u,
    )


def to_pixel(view: View, vp: Viewport, x: float, y: float) -> tuple[float, float]:
    """Model (x, y) -> widget pixel (inverse of :func:`to_model`)."""
    u = units_per_px(view, vp)
    cx, cy = view.center
    return vp.left + vp.width / 2.0 + (x - cx) / u, vp.top + vp.height / 2.0 - (y - cy) / u


def discs_meet(view: View, vp: Viewport, x, y, g, rect: Viewport, min_px: float = 0.0) -> bool:
    """Whether any disc (centres x, y and radii g, model units; drawn at least ``min_px``
    pixels in radius) shown in ``vp`` overlaps the pixel rectangle ``rect``: the app hides
    its magnified inset rather than a feature under it (issue 12, item 4)."""
    x, y, g = np.broadcast_arrays(*(np.asarray(a, dtype=np.float64) for a in (x, y, g)))
    if x.size == 0:
        return False
    if x.size <= 4:  # a drag frame asks about one disc: plain floats, ~5x faster
        u = units_per_px(view, vp)
        right, bottom = rect.left + rect.width, rect.top + rect.height
        xs, ys, gs = x.ravel().tolist(), y.ravel().tolist(), g.ravel().tolist()
        for xi, yi, gi in zip(xs, ys, gs, strict=True):
            px, py = to_pixel(view, vp, xi, yi)
            dx = min(max(px, rect.left), right) - px
            dy = min(max(py, rect.top), bottom) - py
            if math.hypot(dx, dy) <= max(gi / u, min_px):
                return True
        return False
    with np.errstate(over="ignore", invalid="ignore"):
        px, py = to_pixel(view, vp, x, y)  # elementwise on arrays
        r = np.maximum(g / units_per_px(view, vp), min_px)
        dx = np.clip(px, rect.left, rect.left + rect.width) - px
        dy = np.clip(py, rect.top, rect.top + rect.height) - py
        return bool((np.hypot(dx, dy) <= r).any())


def zoom_about(view: View, vp: Viewport, px: float, py: float, factor: float) -> View:
    """The view ``factor`` times wider, the model point under pixel (px, py) staying there.

    The width is kept in [MIN_WIDTH, MAX_WIDTH] (a zoom past a bound stops at it).
    """
    if not (math.isfinite(factor) and factor > 0):
        raise ValueError(f"zoom factor must be a positive finite number, got {factor!r}")
    x, y = to_model(view, vp, px, py)
    width = min(max(view.width * factor, MIN_WIDTH), MAX_WIDTH)
    k = width / view.width
    cx, cy = view.center
    return View((x + (cx - x) * k, y + (cy - y) * k), width)


def pan(view: View, vp: Viewport, dpx: float, dpy: float) -> View:
    """The view moved so that the content follows a drag of (dpx, dpy) pixels."""
    u = units_per_px(view, vp)
    cx, cy = view.center
    return View((cx - dpx * u, cy + dpy * u), view.width)


def scene_bounds(scene: Scene) -> tuple[float, float, float, float]:
    """(xmin, xmax, ymin, ymax) of the eyes and every feature disc."""
    e = scene.eyes
    xs = [-(e.h + e.l), e.h + e.l]
    ys = [-e.l, e.l]
    for f in scene.features:
        xs += [f.x - f.g, f.x + f.g]
        ys += [f.y - f.g, f.y + f.g]
    return min(xs), max(xs), min(ys), max(ys)


def _fit_box(box, vp: Viewport, free: Viewport) -> View:
    """The view of ``vp`` that shows ``box`` inside the sub-rectangle ``free`` of it."""
    x0, x1, y0, y1 = box
    bw, bh = max(x1 - x0, 1e-9), max(y1 - y0, 1e-9)
    u = max(bw / free.width, bh / free.height) * FIT_MARGIN  # units per pixel
    # the free rectangle's centre shows the box's centre
    fx = free.left + free.width / 2.0 - (vp.left + vp.width / 2.0)
    fy = free.top + free.height / 2.0 - (vp.top + vp.height / 2.0)
    cx = (x0 + x1) / 2.0 - fx * u
    cy = (y0 + y1) / 2.0 + fy * u
    return View((cx, cy), min(max(u * vp.width, MIN_WIDTH), MAX_WIDTH))


def fit_view(
    scene: Scene,
    vp: Viewport,
    avoid: Viewport | None = None,
    top: float = 0.0,
    right: float = 0.0,
    extra: tuple[float, float, float, float] | None = None,
) -> View:
    """The main view showing the eyes, every feature and the box ``extra`` (xmin, xmax,
    ymin, ymax: a trajectory's path), clear of ``avoid`` (the inset),
    of a band of ``top`` pixels at the top of ``vp`` (the title) and of ``right`` pixels
    at its right (the features' labels, written right of each disc).

    With an inset in a corner the content goes into the larger of the two rectangles the
    inset leaves free (beside it, full height, or below/above it, full width), so that F
    never places a feature under the inset or the title.
    """
    box = scene_bounds(scene)
    if extra is not None:
        box = (
            min(box[0], extra[0]),
            max(box[1], extra[1]),
            min(box[2], extra[2]),
            max(box[3], extra[3]),
        )
    top = min(max(top, 0.0), 0.5 * vp.height)
    right = min(max(right, 0.0), 0.3 * vp.width)
    full = vp
    if top > 0 or right > 0:  # the rectangles below are all taken inside the free part
        vp = Viewport(vp.left, vp.top + top, vp.width - right, vp.height - top)
    if avoid is None or avoid.width <= 0 or avoid.height <= 0:
        return _fit_box(box, full, vp)
    cands = []
    # beside the inset (full height)
    if avoid.left - vp.left > vp.left + vp.width - (avoid.left + avoid.width):
        cands.append(Viewport(vp.left, vp.top, avoid.left - vp.left, vp.height))
    else:
        right = avoid.left + avoid.width
        cands.append(Viewport(right, vp.top, vp.left + vp.width - right, vp.height))
    # above or below the inset (full width)
    if avoid.top - vp.top > vp.top + vp.height - (avoid.top + avoid.height):
        cands.append(Viewport(vp.left, vp.top, vp.width, avoid.top - vp.top))
    else:
        bottom = avoid.top + avoid.height
        cands.append(Viewport(vp.left, bottom, vp.width, vp.top + vp.height - bottom))
    cands = [c for c in cands if c.width >= 1 and c.height >= 1]
    if not cands:
        return _fit_box(box, full, vp)
    views = [_fit_box(box, full, c) for c in cands]
    return min(views, key=lambda v: v.width)  # the larger picture


def eye_overlaps(eyes: Eyes, features) -> list[tuple[int, str]]:
    """(index, "A" or "B") of each feature disc that overlaps an eye's circle (centres at
    (-h, 0) and (h, 0), radius l: the situation BFV Property 1 excludes)."""
    out = []
    for i, f in enumerate(features):
        for eye, cx in (("A", -eyes.h), ("B", eyes.h)):
            if math.hypot(f.x - cx, f.y) < f.g + eyes.l:
                out.append((i, eye))
    return out


def fit_inset(eyes: Eyes, vp: Viewport, features=()) -> View:
    """The inset's view: both eyes with their A/B labels above the m/theta/psi text line,
    and whole any of ``features`` that overlaps an eye (:func:`eye_overlaps`)."""
    w, h = max(vp.width, 1.0), max(vp.height, 1.0)
    u = max(
        2 * (eyes.h + eyes.l) * 1.08 / w,
        3.1 * eyes.l / max(h - 1.6 * INSET_TEXT_PX, 1.0),
    )
    cx, cy = 0.0, -0.25 * eyes.l
    hit = sorted({i for i, _ in eye_overlaps(eyes, features)})
    if hit:
        fs = [features[i] for i in hit]
        x0 = min([-(eyes.h + eyes.l)] + [f.x - f.g for f in fs])
        x1 = max([eyes.h + eyes.l] + [f.x + f.g for f in fs])
        y0 = min([-1.3 * eyes.l] + [f.y - f.g for f in fs])  # room for A and B below
        y1 = max([eyes.l] + [f.y + f.g for f in fs])
        u = max(u, (x1 - x0) * 1.08 / w, (y1 - y0) * 1.08 / max(h - 1.6 * INSET_TEXT_PX, 1.0))
        cx, cy = (x0 + x1) / 2.0, (y0 + y1) / 2.0
    shift = 0.8 * INSET_TEXT_PX * u  # centre the content above the text line
    return View((cx, cy - shift), u * w)
