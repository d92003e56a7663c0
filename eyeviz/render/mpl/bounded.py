"""Keep what Agg and FreeType are handed within what they can raster (issue 13).

A valid scene may put a disc of radius 1e12 next to a view 8000 wide, or zoom to a view
1e-6 wide beside eyes of radius 20: drawn as they are, the circles span 1e11-1e20 pixels
and Agg (24.8 fixed point, curve subdivision by pixel size) hangs or draws garbage, and a
label placed beside such a disc sits 1e11 pixels away, where FreeType fails with "raster
overflow". :func:`bound_figure` runs after the painters and before saving, on every axes:

- a patch entirely outside the view (expanded by :data:`MARGIN`) is removed (nothing of
  it could show);
- a patch far larger than the view is replaced by its intersection with the expanded
  view, as a polygon: circles and wedges exactly (their arcs sampled finely only over the
  angles from which the view is seen), other paths by clipping their vertices;
- a text anchored more than :data:`TEXT_REACH_PX` pixels outside the figure is removed
  (no text of at most 200 characters reaches that far).

What is visible is unchanged. When the numbers themselves cannot place an edge inside the
view (a disc of radius 1e12 seen through a view 1e-6 wide: float64 resolves 1e-4 there)
the figure is refused in one line naming the shape, instead of drawing noise.
"""

from __future__ import annotations

import math

import numpy as np
from matplotlib.patches import Circle, Polygon, Wedge
from matplotlib.transforms import Bbox

from eyeviz import EyevizError

__all__ = ["bound_figure", "disc_in_box", "clip_polygon", "MARGIN", "TEXT_REACH_PX"]

#: The view is expanded by this fraction of its size on each side before clipping.
MARGIN = 0.05
#: A patch whose extent exceeds this many view sizes is replaced by its clipped polygon.
HUGE = 20.0
#: Texts anchored further than this outside the figure (pixels) are dropped.
TEXT_REACH_PX = 1e5
#: Arc samples over the part of a circle that faces the view.
ARC_SAMPLES = 1024
#: Relative float64 resolution allowed for an edge inside the view (of the view size).
_EPS = 4.0 * np.finfo(float).eps


Box = tuple[float, float, float, float]  # x0, x1, y0, y1


def clip_polygon(pts: np.ndarray, box: Box) -> np.ndarray:
    """Sutherland-Hodgman: the polygon ``pts`` (k, 2) clipped to ``box``; (0, 2) if none."""
    x0, x1, y0, y1 = box
    poly = np.asarray(pts, float)
    for axis, bound, keep_less in ((0, x0, False), (0, x1, True), (1, y0, False), (1, y1, True)):
        if len(poly) == 0:
            break
        v = poly[:, axis] - bound
        inside = v <= 0 if keep_less else v >= 0
        nxt = np.roll(poly, -1, axis=0)
        vn = np.roll(v, -1)
        inside_n = np.roll(inside, -1)
        out = []
        for p, q, a, b, ins, ins_n in zip(poly, nxt, v, vn, inside, inside_n, strict=True):
            if ins:
                out.append(p)
            if ins != ins_n:
                t = a / (a - b)
                out.append(p + t * (q - p))
        poly = np.array(out, float).reshape(-1, 2)
    return poly


def _span(c: tuple[float, float], box: Box) -> tuple[float, float] | None:
    """Angles (lo, hi), hi - lo < pi, under which ``box`` is seen from ``c`` (None: c is
    inside the box, every angle)."""
    x0, x1, y0, y1 = box
    if x0 <= c[0] <= x1 and y0 <= c[1] <= y1:
        return None
    mid = math.atan2((y0 + y1) / 2 - c[1], (x0 + x1) / 2 - c[0])
    rel = [
        (math.atan2(y - c[1], x - c[0]) - mid + math.pi) % (2 * math.pi) - math.pi
        for x in (x0, x1)
        for y in (y0, y1)
    ]
    return mid + min(rel), mid + max(rel)


def _arc(c, r: float, lo: float, hi: float, n: int = ARC_SAMPLES) -> np.ndarray:
    t = np.linspace(lo, hi, n)
    return np.column_stack((c[0] + r * np.cos(t), c[1] + r * np.sin(t)))


def _sector_pieces(span, t1: float, t2: float) -> list[tuple[float, float]]:
    """The angle intervals of [t1, t2] (radians, t2 - t1 <= 2 pi) inside ``span``."""
    if span is None:
        return [(t1, t2)]
    lo, hi = span
    out = []
    for k in (-2, -1, 0, 1, 2):
        a, b = max(lo, t1 + 2 * math.pi * k), min(hi, t2 + 2 * math.pi * k)
        if a < b:
            out.append((a, b))
    return out


def disc_in_box(
    c: tuple[float, float],
    r: float,
    box: Box,
    theta: tuple[float, float] | None = None,
    r_in: float = 0.0,
) -> list[np.ndarray]:
    """The disc (or the wedge ``theta`` in radians, ring from ``r_in``) around ``c``
    intersected with ``box``, as polygons (an empty list when they do not meet)."""
    span = _span(c, box)
    t1, t2 = theta if theta is not None else (-math.pi, math.pi)
    if theta is None and span is None:
        pieces = [(-math.pi, math.pi)]
    else:
        pieces = _sector_pieces(span, t1, t2)
    polys = []
    for lo, hi in pieces:
        outer = _arc(c, r, lo, hi)
        if r_in > 0:
            inner = _arc(c, r_in, hi, lo)
        elif theta is None and span is None:
            inner = np.empty((0, 2))
        else:
            inner = np.array([c], float)
        clipped = clip_polygon(np.vstack((outer, inner)), box)
        if len(clipped) >= 3:
            polys.append(clipped)
    return polys


def _expanded(ax) -> Box:
    x0, x1 = sorted(ax.get_xlim())
    y0, y1 = sorted(ax.get_ylim())
    dx, dy = (x1 - x0) * MARGIN, (y1 - y0) * MARGIN
    return x0 - dx, x1 + dx, y0 - dy, y1 + dy


def _replace(ax, patch, polys: list[np.ndarray]) -> None:
    for i, pts in enumerate(polys):
        new = Polygon(
            pts,
            closed=True,
            facecolor=patch.get_facecolor(),
            edgecolor=patch.get_edgecolor(),
            linewidth=patch.get_linewidth(),
            linestyle=patch.get_linestyle(),
            fill=patch.get_fill(),
            zorder=patch.get_zorder(),
            clip_on=patch.get_clip_on(),
        )
        gid = patch.get_gid()
        if gid:
            new.set_gid(gid if i == 0 else f"{gid}-{i}")
        ax.add_patch(new)
    patch.remove()


def _distances(c, box: Box) -> tuple[float, float]:
    """Nearest and farthest distance from ``c`` to the points of ``box``."""
    x0, x1, y0, y1 = box
    nx, ny = min(max(c[0], x0), x1), min(max(c[1], y0), y1)
    fx, fy = max(abs(c[0] - x0), abs(c[0] - x1)), max(abs(c[1] - y0), abs(c[1] - y1))
    return math.hypot(nx - c[0], ny - c[1]), math.hypot(fx, fy)


def _check_resolution(patch, res: float, box: Box) -> None:
    """Refuse an arc through the view that float64 places only to ``res``."""
    size = min(box[1] - box[0], box[3] - box[2])
    if res > 1e-3 * size:
        what = patch.get_gid() or type(patch).__name__.lower()
        raise EyevizError(
            f"cannot draw {what} (its edge is known to {res:.2g}) in a view {size:.3g} "
            "wide: float64 cannot place it there; widen the view"
        )


def _circle_extents(patch) -> Bbox | None:
    """The data box of a finite Circle, None for any other patch."""
    if type(patch) is not Circle:
        return None
    (cx, cy), r = patch.center, patch.radius
    if not math.isfinite(cx + cy + r):
        return None
    return Bbox.from_extents(cx - r, cy - r, cx + r, cy + r)


def _bound_patch(ax, patch, box: Box) -> None:
    if patch.get_data_transform() is not ax.transData:
        return
    try:
        ext = _circle_extents(patch)  # a disc's at once: its path's Bezier walk took 0.7 ms
        if ext is None:
            ext = patch.get_path().get_extents(patch.get_patch_transform())
    except (ValueError, OverflowError):
        return
    bx0, bx1, by0, by1 = box
    if ext.x1 < bx0 or ext.x0 > bx1 or ext.y1 < by0 or ext.y0 > by1:
        patch.remove()
        return
    size = max(bx1 - bx0, by1 - by0)
    if max(ext.width, ext.height) <= HUGE * size:
        return
    if isinstance(patch, Circle) and patch.width == patch.height:
        c, r = patch.center, patch.width / 2
        res = max(abs(c[0]), abs(c[1]), r) * _EPS
        dmin, dmax = _distances(c, box)
        if dmax <= r - res:  # the view lies inside the disc
            x0, x1, y0, y1 = box
            _replace(ax, patch, [np.array([(x0, y0), (x1, y0), (x1, y1), (x0, y1)], float)])
            return
        if dmin > r + res:
            patch.remove()
            return
        _check_resolution(patch, res, box)
        _replace(ax, patch, disc_in_box(c, r, box))
    elif isinstance(patch, Wedge):
        c, r = patch.center, patch.r
        r_in = max(r - patch.width, 0.0) if patch.width is not None else 0.0
        res = max(abs(c[0]), abs(c[1]), r) * _EPS
        dmin, dmax = _distances(c, box)
        if any(dmin - res <= rr <= dmax + res for rr in (r, r_in) if rr > 0):
            _check_resolution(patch, res, box)  # an arc runs through the view
        t1, t2 = math.radians(patch.theta1), math.radians(patch.theta2)
        while t2 <= t1:
            t2 += 2 * math.pi
        t2 = min(t2, t1 + 2 * math.pi)
        _replace(ax, patch, disc_in_box(c, r, box, (t1, t2), r_in))
    else:
        path = patch.get_patch_transform().transform_path(patch.get_path())
        pts = np.asarray(path.vertices, float)
        pts = pts[np.isfinite(pts).all(axis=1)]
        clipped = clip_polygon(pts, box) if len(pts) >= 3 else np.empty((0, 2))
        _replace(ax, patch, [clipped] if len(clipped) >= 3 else [])


def _bound_texts(fig) -> None:
    w, h = fig.bbox.width, fig.bbox.height
    reach = TEXT_REACH_PX
    texts = list(fig.texts) + [t for ax in fig.axes for t in ax.texts]
    for t in texts:
        try:
            x, y = t.get_transform().transform(t.get_position())
        except (ValueError, OverflowError):
            x = y = math.inf
        if not (-reach <= x <= w + reach and -reach <= y <= h + reach):
            t.remove()


def bound_figure(fig) -> None:
    """Make every artist of ``fig`` rasterable in bounded time (see the module doc)."""
    for ax in fig.axes:
        box = _expanded(ax)
        if not all(math.isfinite(v) for v in box):
            continue
        for patch in list(ax.patches):
            _bound_patch(ax, patch, box)
    _bound_texts(fig)
