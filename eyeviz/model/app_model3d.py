"""The 3D view's gestures on the app model: picking, a ball's drag as one generator and
the keyboard's nudges (no Qt, no VTK).

The model is the one :class:`eyeviz.model.app_model.AppModel` of every eye model
(issue 37.2), holding a spherical-side scene (HEALPix or measured eyes) with the state
function ``checked_state`` of :mod:`eyeviz.model.state3d`; :data:`AppModel3D` is that
class typed for the spherical state (the name the 3D page, its tests and plug-ins use).
Every edit goes through ``commit`` (one undo step; the window installs a QUndoStack-backed
``push``); a drag changes the scene through ``live`` between ``begin_live`` and
``end_live``, and the whole gesture is ONE undo step. What stays here is the gestures'
mathematics, which differs from the planar page's (:func:`eyeviz.model.app_model.drag_feature`
moves a disc in the plane's own coordinates): a 3D press is a line of sight through a
camera, picked against spheres, dragged in the plane facing the camera or along the ray.

Gestures (pixels of the scene's viewport, y down, through the :class:`Camera3D` the view
had at the press):

- a left drag on a ball moves it in the plane through its centre facing the camera (the
  grab point stays under the cursor);
- with Shift (or Ctrl) held at the press it moves along the line of sight instead: up is
  farther, down nearer, each pixel by what a pixel spans in the screen plane at the ball's
  distance at the press (issue 32.5: a factor of the camera distance moved balls
  thousands of units in a few pixels), never nearer the camera than MIN_DEPTH of that
  distance (the ball stays under the cursor and grows or shrinks);
- :func:`nudge` (the keyboard) moves the selected ball NUDGE_PX pixels across the screen
  or by a factor ``exp(NUDGE_DEPTH)`` along the line of sight; consecutive nudges of one
  ball are one undo step.
"""

from __future__ import annotations

import math
from collections.abc import Generator
from dataclasses import dataclass

import numpy as np

from eyeviz.model.app_model import DRAG_THRESHOLD_PX, AppModel
from eyeviz.model.camera3d import Camera3D, basis
from eyeviz.model.state3d import MAX_VIEW_LIT, SceneState3D, checked_state

__all__ = [
    "MIN_DEPTH",
    "NUDGE_DEPTH",
    "NUDGE_PX",
    "PICK_PX",
    "MAX_VIEW_LIT",
    "AppModel3D",
    "checked_state",
    "Pointer",
    "drag_ball",
    "nudge",
    "pick_ball",
    "ray",
]

PICK_PX = 8.0  # a ball is grabbed within this many pixels of its drawn outline
MIN_DEPTH = 0.05  # a depth drag stops at this fraction of the ball's distance from the camera
NUDGE_PX = 10.0  # one arrow key
NUDGE_DEPTH = 0.05  # one depth key: the distance times exp(+-0.05)
# DRAG_THRESHOLD_PX (released closer than this to the press: a click) is the planar page's
# (eyeviz.model.app_model); MAX_VIEW_LIT and checked_state are the spherical state
# function's (eyeviz.model.state3d), re-exported here where the 3D page imports them.

#: The app model of a spherical-side scene: :class:`eyeviz.model.app_model.AppModel`
#: typed for its state (:class:`eyeviz.model.state3d.SceneState3D`).
AppModel3D = AppModel[SceneState3D]


@dataclass(frozen=True)
class Pointer:
    """A mouse event in the scene viewport's pixels (``w`` x ``h``, y down)."""

    type: str  # "press" | "move" | "release"
    px: float
    py: float
    w: float
    h: float


def ray(cam: Camera3D, p: Pointer) -> tuple[np.ndarray, np.ndarray]:
    """(origin, unit direction) of the line of sight through pixel (px, py)."""
    right, up, back = basis(cam)
    t = math.tan(math.radians(cam.view_angle) / 2.0)
    aspect = p.w / max(p.h, 1e-9)
    x = (2.0 * p.px / max(p.w, 1e-9) - 1.0) * t * aspect
    y = (1.0 - 2.0 * p.py / max(p.h, 1e-9)) * t
    d = x * right + y * up - back
    return np.asarray(cam.position, dtype=float), d / np.linalg.norm(d)


def _units_per_px(cam: Camera3D, depth: float, h: float) -> float:
    return 2.0 * depth * math.tan(math.radians(cam.view_angle) / 2.0) / max(h, 1e-9)


def pick_ball(cam: Camera3D, p: Pointer, x, y, z, g) -> int | None:
    """The ball under pixel (px, py): the nearest one whose sphere the line of sight meets
    within PICK_PX pixels of its outline; None when there is none."""
    o, d = ray(cam, p)
    c = np.column_stack([np.asarray(x, float), np.asarray(y, float), np.asarray(z, float)])
    if c.shape[0] == 0:
        return None
    rel = c - o
    along = rel @ d  # distance along the ray to the closest approach
    miss = np.sqrt(np.maximum((rel * rel).sum(axis=1) - along**2, 0.0))
    tol = np.array([_units_per_px(cam, max(a, 0.0), p.h) * PICK_PX for a in along])
    hit = (along > 0) & (miss <= np.asarray(g, float) + tol)
    if not hit.any():
        return None
    # nearest: the front of the sphere along the ray
    front = np.where(
        hit, along - np.sqrt(np.maximum(np.asarray(g, float) ** 2 - miss**2, 0)), np.inf
    )
    return int(np.argmin(front))


def drag_ball(
    model: AppModel3D, cam: Camera3D, press: Pointer, index: int, depth: bool = False
) -> Generator[None, Pointer, None]:
    """A whole drag of ball ``index`` through ``cam`` (see the module docstring): send the
    moves and the release with ``gen.send(pointer)``. Under DRAG_THRESHOLD_PX of travel it
    is a click (select only); a drag is ONE undo step."""
    model.select(index)
    f = model.scene.features[index]
    c0 = np.array([f.x, f.y, f.z])
    o, d0 = ray(cam, press)
    _, _, back = basis(cam)
    # the grab point: where the press's line of sight meets the plane through c0
    s0 = float((c0 - o) @ back) / float(d0 @ back)
    grab = o + s0 * d0
    offset = c0 - grab
    dist0 = float(np.linalg.norm(c0 - o))
    # a pixel of depth drag: a pixel's span in the screen plane at the ball's depth
    per_px = _units_per_px(cam, max(float((o - c0) @ back), 0.0), press.h)
    dragging = False
    p = yield
    try:
        while p.type == "move":
            if not dragging and math.hypot(p.px - press.px, p.py - press.py) >= DRAG_THRESHOLD_PX:
                dragging = True
                model.begin_live(("Move " if not depth else "Push ") + f.name)
            if dragging:
                if depth:
                    dist = max(dist0 - (p.py - press.py) * per_px, MIN_DEPTH * dist0)
                    c = o + (c0 - o) * (dist / dist0) if dist0 > 0 else c0
                else:
                    _, d = ray(cam, p)
                    s = float((c0 - o) @ back) / float(d @ back)
                    c = o + s * d + offset
                model.live(index, x=c[0], y=c[1], z=c[2])
            p = yield
    finally:
        if dragging:
            model.end_live()


def nudge(
    model: AppModel3D, cam: Camera3D, h_px: float, dx: int = 0, dy: int = 0, dz: int = 0
) -> bool:
    """Move the selected ball ``dx``, ``dy`` steps of NUDGE_PX pixels across the screen
    (right, up) at its depth in a viewport ``h_px`` high, and ``dz`` steps along the line
    of sight (positive: farther). Consecutive nudges of one ball are one undo step.
    False when no ball is selected."""
    i = model.selected
    if i is None or not 0 <= i < len(model.scene.features):
        return False
    f = model.scene.features[i]
    c = np.array([f.x, f.y, f.z])
    right, up, back = basis(cam)
    o = np.asarray(cam.position, dtype=float)
    depth = float((o - c) @ back)
    step = _units_per_px(cam, max(depth, 0.0), h_px) * NUDGE_PX
    c = c + step * (dx * right + dy * up)
    if dz:
        c = o + (c - o) * math.exp(NUDGE_DEPTH * dz)
    model.move(i, c, f"Nudge {f.name}", merge_key=("nudge", i))
    return True
