"""Gestures on the view and small edits, as model functions (no Qt): the window only
translates Qt events into calls of these (napari's split; issue 9 item 3).

Views: ``which`` is "main" (the scene's view, saved with it) or "inset" (the magnified eyes).
Camera moves are not undo steps; scene edits are (through ``AppModel.commit``).

The wheel (issue 12 item 3): a plain wheel notch ALWAYS zooms about the cursor, wherever
it is, so a feature drifting under the cursor while zooming is never resized and one can
zoom in centred on a feature by pointing at it. Resizing with the wheel needs a modifier
(Ctrl or Shift + wheel) over a feature; consecutive notches on one feature merge into one
undo step.
"""

from __future__ import annotations

import math
from collections.abc import Generator

from eyeviz.model import camera
from eyeviz.model.app_model import AppModel, MouseEvent, hit_test
from eyeviz.model.camera import Viewport
from eyeviz.model.scene import TRAJECTORY_KINDS, Trajectory, View

__all__ = [
    "WHEEL_RADIUS_STEP",
    "fit_inset",
    "fit_view",
    "pan_drag",
    "press",
    "set_trajectory",
    "set_view",
    "toggle_estimator",
    "view_of",
    "wheel",
    "zoom",
]

WHEEL_RADIUS_STEP = 1.08  # one modified wheel notch over a feature


def view_of(model: AppModel, which: str) -> View:
    return model.scene.view if which == "main" else model.inset_view


def set_view(model: AppModel, which: str, view: View) -> None:
    """Move a camera (not an undo step)."""
    if which == "main":
        model.scene.view = view
    else:
        model.inset_view = view
        model.inset_auto = False
    model.notify_view(which)


def zoom(model: AppModel, which: str, vp: Viewport, px: float, py: float, factor: float) -> None:
    """Zoom ``which`` by ``factor`` about pixel (px, py) (the point there stays put)."""
    set_view(model, which, camera.zoom_about(view_of(model, which), vp, px, py, factor))


def wheel(
    model: AppModel, which: str, vp: Viewport, px: float, py: float, steps: float, resize: bool
) -> str:
    """One wheel event of ``steps`` notches (positive: away from the user).

    ``resize`` (the modifier held) over a shown feature scales its radius by
    WHEEL_RADIUS_STEP per notch; otherwise the view zooms about the cursor (in by
    camera.ZOOM_STEP per notch). Returns "resize", "zoom" or "none".
    """
    if steps == 0 or not math.isfinite(steps):
        return "none"
    if resize and model.scene.shows("features"):
        v = view_of(model, which)
        x, y = camera.to_model(v, vp, px, py)
        i, _ = hit_test(model.scene, model.selected, x, y, camera.units_per_px(v, vp))
        if i is not None:
            sc = model.scene
            after = sc.copy()
            after.features[i].g = sc.features[i].g * WHEEL_RADIUS_STEP**steps
            model.select(i)
            model.commit(after, f"Resize {sc.features[i].name}", merge_key=("wheel", i))
            return "resize"
    zoom(model, which, vp, px, py, camera.ZOOM_STEP ** (-steps))
    return "zoom"


def pan_drag(
    model: AppModel, which: str, vp: Viewport, event: MouseEvent
) -> Generator[None, MouseEvent, None]:
    """A pan of ``which``: the content follows the cursor until the release."""
    v0 = view_of(model, which)
    px0, py0 = event.px, event.py
    event = yield
    while event.type == "move":
        set_view(model, which, camera.pan(v0, vp, event.px - px0, event.py - py0))
        event = yield


def press(
    model: AppModel,
    event: MouseEvent,
    which: str,
    vp: Viewport,
    button: str = "left",
    main_vp: Viewport | None = None,
) -> Generator[None, MouseEvent, None] | None:
    """What a press starts: a feature drag (left on a feature), else a pan of ``which``.

    A press inside the inset is first tried on the main view's features (``main_vp``):
    a feature lying under the inset stays pickable; only a press on no feature pans the
    inset. Returns the started generator (already primed) or None.
    """
    gen = None
    if button == "left" and model.scene.shows("features"):
        for w, p in ((which, vp), ("main", main_vp)):
            if p is None:
                continue
            v = view_of(model, w)
            x, y = camera.to_model(v, p, event.px, event.py)
            i, part = hit_test(model.scene, model.selected, x, y, camera.units_per_px(v, p))
            if i is not None:
                e = MouseEvent("press", x, y, event.px, event.py)
                gen = _feature_drag(model, e, i, part, w, p)
                break
    if gen is None and button in ("left", "middle"):
        gen = pan_drag(model, which, vp, event)
    if gen is not None:
        next(gen)
    return gen


def _feature_drag(
    model: AppModel, event: MouseEvent, index: int, part: str, which: str, vp: Viewport
) -> Generator[None, MouseEvent, None]:
    """drag_feature with the events' model coordinates taken in the view it started in."""
    from eyeviz.model.app_model import drag_feature

    inner = drag_feature(model, event, index, part)
    next(inner)
    while True:
        ev = yield
        v = view_of(model, which)
        x, y = camera.to_model(v, vp, ev.px, ev.py)
        try:
            inner.send(MouseEvent(ev.type, x, y, ev.px, ev.py))
        except StopIteration:
            return


def fit_view(
    model: AppModel,
    vp: Viewport,
    avoid: Viewport | None = None,
    top: float = 0.0,
    right: float = 0.0,
    extra: tuple[float, float, float, float] | None = None,
) -> None:
    """F: the eyes, every feature and ``extra`` (a trajectory's path) in view, clear of
    the inset (``avoid``), the title (a band of ``top`` pixels) and the labels (``right``
    pixels)."""
    set_view(model, "main", camera.fit_view(model.scene, vp, avoid, top, right, extra))


def fit_inset(model: AppModel, vp: Viewport) -> None:
    """Shift+F (and after h or l change): the inset shows both eyes again."""
    model.inset_view = camera.fit_inset(model.scene.eyes, vp, model.scene.features)
    model.inset_auto = True
    model.notify_view("inset")


def toggle_estimator(model: AppModel, name: str, on: bool) -> None:
    """Show or hide one estimator's predictions (one undo step)."""
    after = model.scene.copy()
    est = [n for n in after.estimators if n != name]
    if on:
        est.append(name)
    after.estimators = est
    model.commit(after, f"{'Show' if on else 'Hide'} {name} predictions")


def set_trajectory(model: AppModel, kind: str | None = None) -> None:
    """Give the scene a trajectory of ``kind`` (default: keep the present one, else
    horizontal) at the selected feature's distance and radius, and show its layer."""
    if kind is not None and kind not in TRAJECTORY_KINDS:
        raise ValueError(f"trajectory kind must be one of {', '.join(TRAJECTORY_KINDS)}")
    sc = model.scene
    if sc.trajectory is not None and (kind is None or kind == sc.trajectory.kind):
        if not sc.shows("trajectory"):
            model.set_layer("trajectory", True)
        return
    i = model.selected
    f = sc.features[i] if i is not None and i < len(sc.features) else None
    r = math.hypot(f.x, f.y) if f else 2000.0
    g = f.g if f else 50.0
    if not 100.0 < r < 1e6:
        r = 2000.0
    after = sc.copy()
    after.trajectory = Trajectory(kind or "horizontal", float(r), float(g))
    if "trajectory" not in after.layers:
        after.layers.append("trajectory")
    model.commit(after, f"Trajectory {after.trajectory.kind}")
