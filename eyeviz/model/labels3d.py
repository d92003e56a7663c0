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

from eyeviz.model.camera3d import Camera3D, project

__all__ = ["GAP_PX", "Named3D", "discs", "place_boxes", "place_named"]

#: pixels between a disc's rim and its name's box
GAP_PX = 3.0

# directions tried around a disc, in order: beside (right, left), above, the upper
# diagonals, below, the lower diagonals; ``below`` first for the eyes' names
_DIRS = ((1, 0), (-1, 0), (0, 1), (1, 1), (-1, 1), (0, -1), (1, -1), (-1, -1))
_DIRS_BELOW = ((0, -1), (1, -1), (-1, -1), (1, 0), (-1, 0), (0, 1), (1, 1), (-1, 1))


def _box_at(cx: float, cy: float, r: float, w: float, h: float, d: tuple[int, int], far: float):
    """The box (x0, y0, x1, y1) of a ``w`` x ``h`` name touching the disc (cx, cy, r)
    from direction ``d`` at ``far`` pixels beyond its rim."""
    dx, dy = d
    k = (r + far) / (math.sqrt(2.0) if dx and dy else 1.0)
    px, py = cx + dx * k, cy + dy * k
    x0 = px if dx > 0 else (px - w if dx < 0 else px - w / 2.0)
    y0 = py if dy > 0 else (py - h if dy < 0 else py - h / 2.0)
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
    gap: float = GAP_PX,
    keep_out: np.ndarray | None = None,
    give_way: bool = True,
) -> np.ndarray:
    """Boxes (n, 4: x0, y0, x1, y1, pixels, y up) for n names: name i (``sizes[i]`` =
    width, height) beside the disc (``centres[i]``, ``radii[i]``) it names, covering no
    named disc, no row of ``obstacles`` (cx, cy, r), no earlier box and inside ``bounds``
    (x0, y0, x1, y1) where a place allows; else the place covering least (a box of NaN
    for a name whose centre is NaN: behind the camera). Names are placed in order: put
    the one that matters most (the selected ball's) first. ``below``: try under the disc
    first (the eyes' names). ``keep_out`` (k, 4 boxes as the result's): the view's own
    texts (its title, its side note), which a name covers no more than another name.
    ``give_way``: a name that covers an earlier name wherever it goes gets a box of NaN
    (not drawn); without it, the place covering least (to measure what a framing leaves
    room for, as :func:`eyeviz.render.vtk.scene3d.fit_labels` does)."""
    c = np.asarray(centres, float).reshape(-1, 2)
    r = np.asarray(radii, float).reshape(-1)
    s = np.asarray(sizes, float).reshape(-1, 2)
    ob = np.asarray(obstacles, float).reshape(-1, 3)
    ok = np.isfinite(c).all(axis=1) & np.isfinite(r)
    dsc = np.concatenate([np.column_stack([c, r])[ok], ob[np.isfinite(ob).all(axis=1)]])
    out = np.full((len(c), 4), np.nan)
    placed: list[tuple[float, float, float, float]] = []
    fixed = [tuple(b) for b in np.asarray(keep_out if keep_out is not None else [], float)
             .reshape(-1, 4) if np.isfinite(b).all()]  # fmt: skip
    dirs = _DIRS_BELOW if below else _DIRS
    for i in np.flatnonzero(ok):
        w, h = float(s[i, 0]), float(s[i, 1])
        best, best_cost = None, math.inf
        for far in (gap, gap + h, gap + 2.5 * h):
            for d in dirs:
                box = _box_at(float(c[i, 0]), float(c[i, 1]), float(r[i]), w, h, d, far)
                out_x = max(bounds[0] - box[0], 0.0) + max(box[2] - bounds[2], 0.0)
                out_y = max(bounds[1] - box[1], 0.0) + max(box[3] - bounds[3], 0.0)
                depth = _disc_hits(box, dsc)
                cost = (
                    _box_hits(box, placed)
                    + _box_hits(box, fixed)
                    + float(np.sum(np.clip(depth, 0.0, None))) * h
                    + (out_x * h + out_y * w) * 4.0
                )
                if cost < best_cost - 1e-9:
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
