"""Where the 3D view's names go: beside their ball or eye, over nothing else (issue 32.4).

One placement for the app's VTK view and for the exported figures
(:mod:`eyeviz.render.vtk.scene3d`, :mod:`eyeviz.render.mpl.perspective3d`): the things
named (balls, eyes) and the things a name must not cover (every ball, every eye, the
predictions' ghosts) are spheres; through the camera each is a disc on the screen, and
each name is a box of known size in pixels. :func:`place_boxes` tries, per name in turn,
positions around its disc (beside it, above, below, on the diagonals, then one and two
text heights further out) and keeps the first whose box covers no disc, no box already
placed and stays inside the view; where none does, the one covering least. A name whose
least-covering place still covers a name placed before it gives way: it is not drawn
(a box of NaN), so two names never print over each other (sphere_lecture's step 7 at
F11 + F5 + 175 % in 1280 x 720: a 234 px high view where "above" and "below" found no
places apart); the names placed first (the selected ball's) keep theirs. Pure: arrays
in, arrays out, no drawing.

Pixels here have y up (VTK's display coordinates; a figure's axes are converted).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from eyeviz.model.camera3d import Camera3D, basis, dolly, project

__all__ = [
    "GAP_PX",
    "LABEL_MARGIN_PX",
    "Named3D",
    "discs",
    "fit_labels",
    "frame_names",
    "gap_for",
    "leaders",
    "pan",
    "place_boxes",
    "place_named",
    "shifted",
]

#: pixels between a disc's rim and its name's box at text scale 1 (a name of
#: :data:`REF_TEXT_PX` high): the gap grows with the name's height, so with the zoom
#: (Ctrl+=); at F11 + F5 + 175 % names touched their ball or its selection ring with
#: 0-2 px to spare
GAP_PX = 4.0
#: a ball name's height in pixels at text scale 1 (the 3D view's 20 px font)
REF_TEXT_PX = 24.0
#: a name placed farther than this many of its heights beyond its gap from its ball's
#: rim gets a leader line to the ball (:func:`leaders`)
LEADER_AFTER = 0.75

# directions tried around a disc, in order: beside (right, left), above, the upper
# diagonals, below, the lower diagonals; ``below`` first for the eyes' names
_DIRS = ((1, 0), (-1, 0), (0, 1), (1, 1), (-1, 1), (0, -1), (1, -1), (-1, -1))
_DIRS_BELOW = ((0, -1), (1, -1), (-1, -1), (1, 0), (-1, 0), (0, 1), (1, 1), (-1, 1))
# then the same sides slid along the disc: beside it raised / lowered by half a name's
# height, above / below it moved by half its width (more places near the ball before a
# name goes farther out or gives way: sphere_lecture's step 6 at 175 % drew "below" far
# from its ball)
_SLIDES = ((1, 0, 0.5), (1, 0, -0.5), (-1, 0, 0.5), (-1, 0, -0.5),
           (0, 1, 0.5), (0, 1, -0.5), (0, -1, 0.5), (0, -1, -0.5))  # fmt: skip
# how far beyond the gap a name is tried, in its heights: beside the ball, then out
_FARS = (0.0, 0.5, 1.0, 2.0, 3.0)


def gap_for(h: float) -> float:
    """The gap (pixels) between a ball's rim and its name ``h`` pixels high: GAP_PX at
    text scale 1, scaled with the text, plus two pixels: the rounding of the name's offset
    to whole pixels, and the selection ring's line (2 px wide, half of it outside)."""
    return max(GAP_PX, GAP_PX * h / REF_TEXT_PX) + 2.0


def _box_at(cx: float, cy: float, r: float, w: float, h: float, d, far: float):
    """The box (x0, y0, x1, y1) of a ``w`` x ``h`` name touching the disc (cx, cy, r)
    from direction ``d`` (dx, dy[, slide]) at ``far`` pixels beyond its rim; ``slide``
    moves it along that side by that many of its heights (beside) or widths (above,
    below)."""
    dx, dy = d[0], d[1]
    slide = d[2] if len(d) > 2 else 0.0
    k = (r + far) / (math.sqrt(2.0) if dx and dy else 1.0)
    px, py = cx + dx * k, cy + dy * k
    x0 = px if dx > 0 else (px - w if dx < 0 else px - w / 2.0 + slide * w)
    y0 = py if dy > 0 else (py - h if dy < 0 else py - h / 2.0 + slide * h)
    return x0, y0, x0 + w, y0 + h


def _disc_hits(box, dsc: np.ndarray) -> np.ndarray:
    """Per disc (rows cx, cy, r): the depth (pixels) by which ``box`` enters it (<= 0: apart)."""
    if dsc.size == 0:
        return np.zeros(0)
    qx = np.clip(dsc[:, 0], box[0], box[2])
    qy = np.clip(dsc[:, 1], box[1], box[3])
    return dsc[:, 2] - np.hypot(dsc[:, 0] - qx, dsc[:, 1] - qy)


def _box_hits(box, placed: list) -> float:
    cost = 0.0
    for b in placed:
        ox = min(box[2], b[2]) - max(box[0], b[0])
        oy = min(box[3], b[3]) - max(box[1], b[1])
        if ox > 0 and oy > 0:
            cost += ox * oy
    return cost


def place_boxes(
    centres: np.ndarray,
    radii: np.ndarray,
    sizes: np.ndarray,
    obstacles: np.ndarray,
    bounds: tuple[float, float, float, float],
    *,
    below: bool = False,
    gap: float | None = None,
    keep_out: np.ndarray | None = None,
    give_way: bool = True,
) -> np.ndarray:
    """Boxes (n, 4: x0, y0, x1, y1, pixels, y up) for n names: name i (``sizes[i]`` =
    width, height) beside the disc (``centres[i]``, ``radii[i]``) it names, ``gap``
    pixels (default :func:`gap_for` its height) clear of every disc (named, or a row of
    ``obstacles``: cx, cy, r), of every earlier box and inside ``bounds`` (x0, y0, x1,
    y1) where a place allows; else the place covering least (a box of NaN for a name whose
    centre is NaN: behind the camera). Places are tried beside the disc first, then slid
    along it, then farther out (:data:`_FARS`; a name beyond :data:`LEADER_AFTER` gets a
    leader line, :func:`leaders`); a place nearer another disc than its own is taken only
    where nothing else is free (it would read as that ball's name). Names are placed in
    order: put the one that matters most (the selected ball's) first. ``below``: try
    under the disc first (the eyes' names). ``keep_out`` (k, 4 boxes as the result's):
    the view's own texts (its title, its side note), which a name covers no more than
    another name. ``give_way``: a name that covers an earlier name wherever it goes gets
    a box of NaN (not drawn); without it, the place covering least (to measure what a
    framing leaves room for, as :func:`eyeviz.render.vtk.scene3d.fit_labels` does)."""
    c = np.asarray(centres, float).reshape(-1, 2)
    r = np.asarray(radii, float).reshape(-1)
    s = np.asarray(sizes, float).reshape(-1, 2)
    ob = np.asarray(obstacles, float).reshape(-1, 3)
    ok = np.isfinite(c).all(axis=1) & np.isfinite(r)
    own_rows = np.flatnonzero(ok)  # row k of dsc is named disc own_rows[k]
    dsc = np.concatenate([np.column_stack([c, r])[ok], ob[np.isfinite(ob).all(axis=1)]])
    out = np.full((len(c), 4), np.nan)
    placed: list[tuple[float, float, float, float]] = []
    fixed = [tuple(b) for b in np.asarray(keep_out if keep_out is not None else [], float)
             .reshape(-1, 4) if np.isfinite(b).all()]  # fmt: skip
    dirs = (_DIRS_BELOW if below else _DIRS) + _SLIDES
    for k, i in enumerate(own_rows):
        w, h = float(s[i, 0]), float(s[i, 1])
        g = gap_for(h) if gap is None else float(gap)
        grown = dsc.copy()
        grown[:, 2] += g - 0.5  # the gap kept from every disc (half a pixel of rounding)
        best, best_cost = None, math.inf
        for f in _FARS:
            for d in dirs:
                box = _box_at(float(c[i, 0]), float(c[i, 1]), float(r[i]), w, h, d, g + f * h)
                out_x = max(bounds[0] - box[0], 0.0) + max(box[2] - bounds[2], 0.0)
                out_y = max(bounds[1] - box[1], 0.0) + max(box[3] - bounds[3], 0.0)
                depth = _disc_hits(box, grown)
                cost = (
                    _box_hits(box, placed)
                    + _box_hits(box, fixed)
                    + float(np.sum(np.clip(depth, 0.0, None))) * h
                    + (out_x * h + out_y * w) * 4.0
                )
                if cost <= 0.0 and len(depth) > 1:
                    # nearer another disc's rim than its own: read as that one's name
                    rim = -depth + g
                    own = rim[k]
                    rim[k] = math.inf
                    if float(rim.min()) < own:
                        cost = 1e-6 * (own - float(rim.min()) + 1.0)
                if cost < best_cost - 1e-12:
                    best, best_cost = box, cost
                if cost <= 0.0:
                    break
            if best_cost <= 0.0:
                break
        assert best is not None
        if give_way and _box_hits(best, placed) > 0.0:
            continue  # no place apart from the names before it: this one is not drawn
        out[i] = best
        placed.append(best)
    return out


def leaders(
    centres: np.ndarray,
    radii: np.ndarray,
    boxes: np.ndarray,
    others: np.ndarray | None = None,
    gap: float | None = None,
) -> np.ndarray:
    """Leader lines (n, 4: x0, y0, x1, y1, pixels; NaN where none) from each disc's rim
    to its name's box where :func:`place_boxes` had to put the name farther out than
    :data:`LEADER_AFTER` of its heights beyond its gap, or nearer another disc (another
    named one, or a row of ``others``: cx, cy, r) than its own: the line tells whose name
    it is. Each ends half a ``gap`` (default :func:`gap_for` the name's height) short of
    both."""
    c = np.asarray(centres, float).reshape(-1, 2)
    r = np.asarray(radii, float).reshape(-1)
    b = np.asarray(boxes, float).reshape(-1, 4)
    ob = np.asarray(others if others is not None else np.zeros((0, 3)), float).reshape(-1, 3)
    every = np.concatenate([np.column_stack([c, r]), ob])
    every = every[np.isfinite(every).all(axis=1)]
    out = np.full((len(c), 4), np.nan)
    for i in range(len(c)):
        if not (np.isfinite(b[i]).all() and np.isfinite(c[i]).all() and np.isfinite(r[i])):
            continue
        h = b[i, 3] - b[i, 1]
        g = gap_for(h) if gap is None else float(gap)
        q = np.array([np.clip(c[i, 0], b[i, 0], b[i, 2]), np.clip(c[i, 1], b[i, 1], b[i, 3])])
        v = q - c[i]
        dist = float(np.hypot(*v))
        if dist <= 0.0:
            continue
        rims = -_disc_hits(b[i], every)  # the box's distance to each disc's rim
        own = dist - r[i]
        nearer = bool(np.any(rims < own - 1.0))  # another disc nearer than its own
        if own <= g + LEADER_AFTER * h + 1e-9 and not nearer:
            continue
        u = v / dist
        a, e = c[i] + u * (r[i] + g / 2.0), q - u * (g / 2.0)
        out[i] = (a[0], a[1], e[0], e[1])
    return out


def discs(
    cam: Camera3D, centres, radii, width: float, height: float
) -> tuple[np.ndarray, np.ndarray]:
    """Spheres (``centres`` (n, 3), ``radii`` (n,)) seen through ``cam`` in a ``width`` x
    ``height`` pixel viewport: their discs' centres (n, 2, pixels from the bottom-left, y
    up; NaN behind the camera) and radii (pixels: a sphere of radius g at distance d
    subtends asin(g / d), :func:`eyeviz.model.camera3d.project`'s perspective)."""
    p = np.asarray(centres, float).reshape(-1, 3)
    g = np.asarray(radii, float).reshape(-1)
    if len(p) == 0:
        return np.zeros((0, 2)), np.zeros(0)
    xy, depth = project(cam, p, width / max(height, 1.0))
    px = np.column_stack([(xy[:, 0] + 1.0) * width / 2.0, (xy[:, 1] + 1.0) * height / 2.0])
    dist = np.linalg.norm(p - np.asarray(cam.position, float), axis=1)
    t = math.tan(math.radians(cam.view_angle) / 2.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        ang = np.arcsin(np.clip(g / np.maximum(dist, 1e-300), 0.0, 1.0))
        rad = np.tan(ang) / t * height / 2.0
    front = (depth > 0.0) & (dist > g)
    px[~front] = np.nan
    rad = np.where(front, np.minimum(rad, 4.0 * max(width, height)), np.nan)
    return px, rad


@dataclass(frozen=True)
class Named3D:
    """Spheres to name in a 3D view and spheres their names must not cover.

    ``centres`` (n, 3) and ``radii`` (n,) of the named spheres, ``sizes`` (n, 2) their
    names' width and height in pixels, ``others`` (m, 4: x, y, z, radius) the rest
    (every ball, eye and ghost not named here), ``below``: the names go under their
    spheres first (the eyes'), ``keep_out`` boxes no name may cover (the view's title and
    side note, in the viewport's pixels, y up)."""

    centres: np.ndarray
    radii: np.ndarray
    sizes: np.ndarray
    others: np.ndarray
    below: bool = False
    keep_out: np.ndarray | None = None  # (k, 4) boxes of the view's own texts, pixels y up


def place_named(
    named: Named3D,
    cam: Camera3D,
    width: float,
    height: float,
    margin: float = 2.0,
    *,
    give_way: bool = True,
) -> np.ndarray:
    """:func:`place_boxes` for ``named`` seen through ``cam`` in a ``width`` x ``height``
    pixel viewport (boxes (n, 4) in its pixels, y up; NaN rows for spheres behind the
    camera or wholly outside the viewport, and for names that give way to an earlier
    one, ``give_way`` as in :func:`place_boxes`: their names are not drawn)."""
    c, r = discs(cam, named.centres, named.radii, width, height)
    off = (c[:, 0] + r < 0) | (c[:, 0] - r > width) | (c[:, 1] + r < 0) | (c[:, 1] - r > height)
    c[off] = np.nan
    oth = np.asarray(named.others, float).reshape(-1, 4)
    oc, orad = discs(cam, oth[:, :3], oth[:, 3], width, height)
    obs = np.column_stack([oc, orad]) if len(oth) else np.zeros((0, 3))
    bounds = (margin, margin, width - margin, height - margin)
    return place_boxes(
        c,
        r,
        named.sizes,
        obs,
        bounds,
        below=named.below,
        keep_out=named.keep_out,
        give_way=give_way,
    )


def _covers(boxes: np.ndarray, keep_out: np.ndarray | None) -> bool:
    """Whether any finite box of ``boxes`` overlaps one of ``keep_out`` (both (n, 4))."""
    if keep_out is None or len(keep_out) == 0 or len(boxes) == 0:
        return False
    b = boxes[np.isfinite(boxes).all(axis=1)][:, None, :]
    k = np.asarray(keep_out, float)[None, :, :]
    ox = np.minimum(b[..., 2], k[..., 2]) - np.maximum(b[..., 0], k[..., 0])
    oy = np.minimum(b[..., 3], k[..., 3]) - np.maximum(b[..., 1], k[..., 1])
    return bool(np.any((ox > 0) & (oy > 0)))


#: The ball labels' margin to the scene viewport's edges when a preset frames the scene.
LABEL_MARGIN_PX = 6
#: The pixels a ball's name keeps clear of the view's own texts (title, side note).
KEEP_CLEAR_PX = 3


def _band_shift(keep_out: np.ndarray | None, h: float) -> float:
    """Pixels (y up) to move the view's middle so that it is the middle of the band
    between the view's own texts at its bottom (the side note) and at its top (the
    title); 0 where they leave no band a quarter of the view's height."""
    if keep_out is None or len(keep_out) == 0:
        return 0.0
    lo, hi = 0.0, float(h)
    for x0, y0, x1, y1 in np.asarray(keep_out, float).reshape(-1, 4):
        if not np.isfinite((x0, y0, x1, y1)).all():
            continue
        if (y0 + y1) / 2.0 < h / 2.0:
            lo = max(lo, y1)
        else:
            hi = min(hi, y0)
    if hi - lo < 0.25 * h:
        return 0.0
    return (lo + hi) / 2.0 - h / 2.0


def shifted(cam: Camera3D, by) -> Camera3D:
    """``cam`` and its focal point moved by ``by`` (x, y, z, model units)."""
    p = np.asarray(cam.position, float) + np.asarray(by, float)
    f = np.asarray(cam.focal_point, float) + np.asarray(by, float)
    return Camera3D(
        (float(p[0]), float(p[1]), float(p[2])),
        (float(f[0]), float(f[1]), float(f[2])),
        cam.view_up,
        cam.view_angle,
    )


def pan(cam: Camera3D, dy_px: float, height: float) -> Camera3D:
    """``cam`` moved (with its focal point) across its line of sight so that what it
    drew at the view's middle is drawn ``dy_px`` pixels higher (y up) in a view
    ``height`` pixels high."""
    if dy_px == 0.0:
        return cam
    _right, up, _back = basis(cam)
    pos, foc = np.asarray(cam.position, float), np.asarray(cam.focal_point, float)
    t = math.tan(math.radians(cam.view_angle) / 2.0)
    return shifted(cam, -up * dy_px * 2.0 * float(np.linalg.norm(pos - foc)) * t / max(height, 1.0))


def _all_discs(named: Named3D, cam: Camera3D, w: float, h: float):
    """The on-screen discs (centres (k, 2), radii (k,)) of every ball, eye and ghost
    (``named``'s spheres and its ``others``) that ``cam`` draws in front of it."""
    oth = np.asarray(named.others, float).reshape(-1, 4)
    c = np.concatenate([np.asarray(named.centres, float).reshape(-1, 3), oth[:, :3]])
    r = np.concatenate([np.asarray(named.radii, float).reshape(-1), oth[:, 3]])
    at, rad = discs(cam, c, r, w, h)
    ok = np.isfinite(at).all(axis=1) & np.isfinite(rad)
    return at[ok], rad[ok]


def _discs_cover(named: Named3D, cam: Camera3D, w: float, h: float) -> bool:
    """Whether a ball, an eye or a ghost (``named``'s spheres and its ``others``), as
    ``cam`` draws it, covers one of the view's own texts (``named.keep_out``)."""
    if named.keep_out is None or len(named.keep_out) == 0:
        return False
    at, rad = _all_discs(named, cam, w, h)
    if len(rad) == 0:
        return False
    for x0, y0, x1, y1 in np.asarray(named.keep_out, float).reshape(-1, 4):
        qx, qy = np.clip(at[:, 0], x0, x1), np.clip(at[:, 1], y0, y1)
        if bool(np.any(np.hypot(at[:, 0] - qx, at[:, 1] - qy) < rad)):
            return True
    return False


def _names_clear(boxes: np.ndarray, named: Named3D, cam: Camera3D, w: float, h: float) -> bool:
    """Whether the names at ``boxes`` (every name placed, none given way) are apart from
    each other and from every ball, eye and ghost (``named``'s spheres, its ``others``)
    by their gap (:func:`gap_for`)."""
    b = boxes[np.isfinite(boxes).all(axis=1)]
    for k in range(len(b)):
        if _covers(b[k : k + 1], b[k + 1 :]):
            return False
    at, rad = _all_discs(named, cam, w, h)
    for x0, y0, x1, y1 in b:
        qx, qy = np.clip(at[:, 0], x0, x1), np.clip(at[:, 1], y0, y1)
        gap = gap_for(y1 - y0) - 0.5  # as place_boxes keeps it
        if bool(np.any(np.hypot(at[:, 0] - qx, at[:, 1] - qy) < rad + gap - 1e-6)):
            return False
    return True


def _content_middle(
    boxes: np.ndarray, named: Named3D, cam: Camera3D, w: float, h: float
) -> float | None:
    """The middle (pixels, y up) of what ``cam`` shows of ``named``: its spheres' discs
    and the names at ``boxes``; None where nothing is in front of the camera."""
    at, rad = _all_discs(named, cam, w, h)
    b = boxes[np.isfinite(boxes).all(axis=1)]
    lo = np.concatenate([at[:, 1] - rad, b[:, 1]])
    hi = np.concatenate([at[:, 1] + rad, b[:, 3]])
    if len(lo) == 0:
        return None
    return float(lo.min() + hi.max()) / 2.0


def frame_names(
    cam: Camera3D,
    named: Named3D,
    size: tuple[float, float],
    margin: float = LABEL_MARGIN_PX,
    steps: int = 16,
    *,
    pan_ok: bool = True,
) -> tuple[Camera3D, bool]:
    """:func:`fit_labels`, and whether the framing found is clear: every name inside,
    none over another name, a ball, an eye, a ghost or the view's own texts, and no
    sphere over those texts. ``pan_ok`` False: moved along its line of sight only."""
    if len(named.centres) == 0:
        return cam, True
    w, h = size
    shift = _band_shift(named.keep_out, h) if pan_ok else 0.0
    inside: Camera3D | None = None
    for k in range(steps + 1):
        moved = dolly(cam, 1.1**k)
        boxes = place_named(named, moved, w, h, give_way=False)  # every name, to frame them
        tries = [moved, pan(moved, shift, h)]
        mid = _content_middle(boxes, named, moved, w, h)
        if mid is not None and shift != 0.0:  # what it shows, centred in the band
            tries.append(pan(moved, shift + h / 2.0 - mid, h))
        for c in dict.fromkeys(tries):
            if c is not moved:
                boxes = place_named(named, c, w, h, give_way=False)
            ok = ~np.isfinite(boxes).all(axis=1) | (
                (boxes[:, 0] >= margin - 0.5)
                & (boxes[:, 2] <= w - margin + 0.5)
                & (boxes[:, 1] >= margin - 0.5)
                & (boxes[:, 3] <= h - margin + 0.5)
            )
            if bool(np.all(ok)):
                if (
                    not _covers(boxes, named.keep_out)
                    and not _discs_cover(named, c, w, h)
                    and _names_clear(boxes, named, c, w, h)
                ):
                    return c, True
                inside = inside or c  # the nearest with every name inside, if none is clear
    return inside or dolly(cam, 1.1**steps), False


def fit_labels(
    cam: Camera3D,
    named: Named3D,
    size: tuple[float, float],
    margin: float = LABEL_MARGIN_PX,
    steps: int = 16,
) -> Camera3D:
    """``cam`` moved back along its line of sight (10 % of the distance a step, at most
    ``steps``) until every name, placed by :func:`eyeviz.model.labels3d.place_named`, is
    inside the viewport of ``size`` (width, height px) with ``margin`` pixels to spare,
    apart from every other name and sphere. The presets frame the balls; a name beside a
    ball at the view's edge was cut (sphere_predictions at its default framing). Nor may
    a name, nor a ball, an eye or a ghost, cover the view's own texts (``named.keep_out``:
    the title, the side note; at F11 + F5 + 175 % in 1280 x 720 the side note crossed a
    ball in sphere_lecture's steps 2-6): at each distance the camera is tried as it is,
    then moved across its line of sight to centre what it shows in the band between
    those texts (:func:`pan`). Where no distance is clear, the nearest with every name
    inside."""
    return frame_names(cam, named, size, margin, steps)[0]
