"""The 3D view's model: the open spherical-side scene (HEALPix or measured eyes), the
selection, picking, and a ball's drag as one generator (no Qt, no VTK).

As the planar :class:`eyeviz.model.app_model.AppModel` (docs/architecture.md): every edit
goes through :meth:`AppModel3D.commit` (one undo step; the window installs a
QUndoStack-backed ``push``); a drag changes the scene through :meth:`AppModel3D.live`
between ``begin_live`` and ``end_live``, and the whole gesture is ONE undo step.

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
from collections.abc import Callable, Generator
from dataclasses import dataclass

import numpy as np

from eyeviz import EyevizError
from eyeviz.model.camera3d import Camera3D, basis
from eyeviz.model.edits import feature_value
from eyeviz.model.scene import OKABE_ITO, Feature, Scene
from eyeviz.model.state3d import SceneState3D, compute_state3d, eyes_name
from eyeviz.model.typed3d import KEYS, typed_ball

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

DRAG_THRESHOLD_PX = 4.0  # released closer than this to the press: a click (select only)
PICK_PX = 8.0  # a ball is grabbed within this many pixels of its drawn outline
MIN_DEPTH = 0.05  # a depth drag stops at this fraction of the ball's distance from the camera
NUDGE_PX = 10.0  # one arrow key
NUDGE_DEPTH = 0.05  # one depth key: the distance times exp(+-0.05)
#: The 3D view holds at most this many lit facets (both eyes, all balls; 128 MB of
#: indices): a scene or an edit beyond it is refused in one line, the scene kept.
MAX_VIEW_LIT = 1 << 24


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


def checked_state(scene: Scene) -> SceneState3D:
    """:func:`compute_state3d`, refused (EyevizError, one line) beyond MAX_VIEW_LIT."""
    st = compute_state3d(scene)
    n = sum(int(c[1].size) for c in (st.lit_a, st.lit_b) if c is not None)
    if n > MAX_VIEW_LIT:
        raise EyevizError(
            f"the balls light {n:,} facets ({eyes_name(st.pair)}); the 3D view draws at "
            f"most {MAX_VIEW_LIT:,} (smaller balls, farther balls or a smaller nside)"
        )
    return st


@dataclass
class _Live:
    before: Scene
    text: str


class AppModel3D:
    """The open spherical scene plus the selection; notifies listeners ``fn(what, index)``
    ("scene", "feature" (a live move of ball ``index``), "selection")."""

    def __init__(self, scene: Scene):
        self.scene = scene.copy()
        self.selected: int | None = 0 if scene.features else None
        self.listeners: list[Callable[[str, int | None], None]] = []
        self.push: Callable[..., None] = self._push_plain
        self._state: SceneState3D | None = None
        self._live: _Live | None = None

    @property
    def state(self) -> SceneState3D:
        """The scene's state (:func:`compute_state3d`), recomputed after each change."""
        if self._state is None:
            self._state = checked_state(self.scene)
        return self._state

    def _notify(self, what: str, index: int | None = None) -> None:
        # a live move ("feature") has computed its state already (live())
        if what not in ("selection", "feature"):
            self._state = None
        for fn in list(self.listeners):
            fn(what, index)

    def _push_plain(self, before: Scene, after: Scene, text: str, merge_key=None) -> None:
        self.set_scene(after)

    def set_scene(self, scene: Scene) -> None:
        """Replace the scene (open, undo and redo land here)."""
        self.scene = scene.copy()
        n = len(self.scene.features)
        if self.selected is not None and self.selected >= n:
            self.selected = n - 1 if n else None
        if self.selected is None and n:
            self.selected = 0
        self._notify("scene")

    def commit(self, after: Scene, text: str, merge_key=None) -> None:
        """One undoable edit to ``after`` (edits with one ``merge_key`` merge); an edit
        whose state the view cannot hold raises EyevizError and changes nothing."""
        self.end_live()
        before = self.scene.copy()
        if after != before:
            checked_state(after)
            self.push(before, after.copy(), text, merge_key)

    @property
    def live_open(self) -> bool:
        return self._live is not None

    def begin_live(self, text: str) -> None:
        self.end_live()
        self._live = _Live(self.scene.copy(), text)

    def end_live(self) -> bool:
        """End the gesture: one undo step from its start to now; True if it changed."""
        live, self._live = self._live, None
        if live is None:
            return False
        after = self.scene.copy()
        if after == live.before:
            return False
        self.push(live.before, after, live.text, None)
        return True

    def finish_gestures(self) -> None:
        self.end_live()

    def live(self, index: int, **values: float) -> None:
        """Move or resize ball ``index`` during a gesture (x, y, z, g only)."""
        bad = set(values) - {"x", "y", "z", "g"}
        if bad:
            raise ValueError(f"live() changes x, y, z or g only, got {', '.join(sorted(bad))}")
        checked = {k: feature_value(k, v, "ball radius") for k, v in values.items()}
        f = self.scene.features[index]
        old = {k: getattr(f, k) for k in checked}
        for k, v in checked.items():
            setattr(f, k, v)
        self._state = None
        try:
            self.state  # noqa: B018 (computed now: a refused move leaves the ball where it was)
        except EyevizError as exc:
            for k, v in old.items():
                setattr(f, k, v)
            self._state = None
            raise ValueError(str(exc)) from None
        self._notify("feature", index)

    def select(self, index: int | None) -> None:
        if index != self.selected:
            self.selected = index
            self._notify("selection", index)

    def set_layer(self, layer: str, on: bool) -> None:
        after = self.scene.copy()
        if on and layer not in after.layers:
            after.layers.append(layer)
        elif not on and layer in after.layers:
            after.layers.remove(layer)
        self.commit(after, f"{'Show' if on else 'Hide'} {layer}")

    def move(self, index: int, centre, text: str, merge_key=None) -> None:
        """Put ball ``index`` at ``centre`` (x, y, z) as one undo step."""
        after = self.scene.copy()
        f = after.features[index]
        f.x, f.y, f.z = (
            feature_value(k, v, "ball radius") for k, v in zip("xyz", centre, strict=True)
        )
        self.commit(after, text, merge_key)

    def type_value(self, index: int, key: str, text: str) -> None:
        """Ball ``index``'s coordinate ``key`` (x, y, z, g, r, az, el) typed as ``text``:
        one undo step (:func:`eyeviz.model.typed3d.typed_ball`); a bad value raises
        ValueError (one line) and changes nothing."""
        f = self.scene.features[index]
        x, y, z, g = typed_ball(f, key, text)
        after = self.scene.copy()
        a = after.features[index]
        a.x, a.y, a.z, a.g = x, y, z, g
        try:
            self.commit(after, f"Type {KEYS[key]} of {f.name}")
        except EyevizError as exc:
            raise ValueError(str(exc)) from None

    def _name(self, base: str) -> str:
        names = {f.name for f in self.scene.features}
        i = 1
        while f"{base} {i}" in names:
            i += 1
        return f"{base} {i}"

    def add_ball(self, x: float, y: float, z: float, g: float) -> None:
        after = self.scene.copy()
        color = OKABE_ITO[len(after.features) % len(OKABE_ITO)]
        after.features.append(Feature(self._name("ball"), x, y, g, color, z))
        self.commit(after, "Add ball")
        self.select(len(self.scene.features) - 1)

    def duplicate_ball(self, index: int) -> None:
        after = self.scene.copy()
        f = after.features[index]
        color = OKABE_ITO[len(after.features) % len(OKABE_ITO)]
        after.features.append(
            Feature(self._name(f"{f.name} copy"), f.x + 2.5 * f.g, f.y, f.g, color, f.z)
        )
        self.commit(after, f"Duplicate {f.name}")
        self.select(len(self.scene.features) - 1)

    def delete_ball(self, index: int) -> None:
        after = self.scene.copy()
        name = after.features.pop(index).name
        self.commit(after, f"Delete {name}")


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
