"""The PNG of a spherical scene (issue 22 item 6, docs/spherical.md): the whole figure of
:func:`eyeviz.render.mpl.figure3d.figure3d` (the 3D view, the Mollweide maps, the readout),
its 3D view the VTK off-screen render of the app's view through the same camera.

:func:`view_rgba` renders the 3D view (the eyes close up and the scene, as
:class:`eyeviz.render.vtk.scene3d.Scene3DActors` draws them in the app) off-screen (EGL,
no display) to an array of exactly the view box's pixels; the text (names, captions,
title) is left to matplotlib, so that it is the vector figure's, at the figure's sizes.
:func:`export_png3d` writes the figure with that picture in the view's box, pixel for
pixel; the SVG/PDF draw the same view from the model as polygons
(:mod:`eyeviz.render.mpl.perspective3d`). ``tests/render/test_figure3d_vtk.py`` compares
the two.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from eyeviz import EyevizError
from eyeviz.core.validation import check_int
from eyeviz.model.camera3d import Camera3D
from eyeviz.model.predictions3d import Predictions3D, Predictor3D, scene_predictions3d
from eyeviz.model.scene import Scene
from eyeviz.model.state3d import SceneState3D, compute_state3d
from eyeviz.render.mpl.figure3d import export3d
from eyeviz.render.vtk.scene3d import offscreen_view, shoot

__all__ = ["MAX_VIEW_PX", "export_png3d", "view_rgba"]

#: VTK renders the 3D view at most this many pixels wide or high (an off-screen buffer).
MAX_VIEW_PX = 8192


def view_rgba(
    scene: Scene,
    camera: Camera3D,
    width: int,
    height: int,
    *,
    state: SceneState3D | None = None,
    selected: int | None = None,
    transparent: bool = False,
    supersample: int = 2,
    predictions: Predictions3D | None = None,
) -> np.ndarray:
    """The 3D view of ``scene`` through ``camera`` (the scene part's; the close-up's
    follows it) rendered off-screen, ``height`` x ``width`` x 4 uint8 (alpha 0 where
    ``transparent`` leaves the background out), without text: no title, no caption, no
    names (layer "labels" is drawn by the figure).

    Rendered ``supersample`` times larger each way (while that stays within
    :data:`MAX_VIEW_PX`) and averaged down: smooth edges beside the antialiased maps, and
    no one-pixel cracks between the unlit sphere's facets."""
    width = check_int("width", width, ge=16, le=MAX_VIEW_PX)
    height = check_int("height", height, ge=16, le=MAX_VIEW_PX)
    k = check_int("supersample", supersample, ge=1, le=4)
    while k > 1 and max(width, height) * k > MAX_VIEW_PX:
        k -= 1
    img = _render(scene, camera, width * k, height * k, state, selected, transparent, predictions)
    if k > 1:
        img = _downsample(img, k)
    return img


def _downsample(img: np.ndarray, k: int) -> np.ndarray:
    """``img`` (H k, W k, 4 uint8) averaged over k x k blocks, colours weighted by alpha.

    Summed in integers block slice by block slice (k^2 adds of one output's size; the
    float64 copy of the whole k^2-size image took 0.4 s of a 3D snapshot, issue 32.14)."""
    h, w = img.shape[0] // k, img.shape[1] // k
    a_sum = np.zeros((h, w), np.uint32)
    rgb_sum = np.zeros((h, w, 3), np.uint32)
    for i in range(k):
        for j in range(k):
            block = img[i : h * k : k, j : w * k : k]
            a = block[..., 3].astype(np.uint32)
            a_sum += a
            rgb_sum += block[..., :3] * a[..., None]
    rgb = rgb_sum / np.maximum(a_sum, 1)[..., None]  # 0 where every pixel is clear
    out = np.concatenate([rgb, (a_sum / float(k * k))[..., None]], axis=-1)
    return np.clip(np.round(out), 0, 255).astype(np.uint8)


def _render(
    scene: Scene,
    camera: Camera3D,
    width: int,
    height: int,
    state: SceneState3D | None,
    selected: int | None,
    transparent: bool,
    predictions: Predictions3D | None = None,
) -> np.ndarray:
    sc = scene.copy()
    sc.layers = [k for k in sc.layers if k != "labels"]
    st = compute_state3d(sc) if state is None else state
    win, actors = offscreen_view(width, height)
    try:
        actors.update(sc, st, selected)
        actors.draw_predictions(predictions if sc.shows("predictions") else None)
        actors.title.SetVisibility(False)
        actors.eyes_caption.SetVisibility(False)
        img = shoot(win, actors, camera, transparent)
    finally:
        win.close()
    if img.shape[:2] != (height, width):
        raise EyevizError(
            f"VTK rendered {img.shape[1]} x {img.shape[0]} px, not {width} x {height}"
        )
    if img.shape[2] == 3:
        img = np.concatenate([img, np.full((height, width, 1), 255, np.uint8)], axis=2)
    return np.ascontiguousarray(img, dtype=np.uint8)


def export_png3d(
    scene: Scene,
    path: str | os.PathLike,
    scale: float = 1.0,
    transparent: bool = False,
    *,
    width: float = 3.5,
    title: bool = True,
    table: bool = True,
    bitmaps: bool = True,
    aspect: float | None = None,
    camera: Camera3D | None = None,
    view: str = "default",
    selected: int | None = None,
    predictions: Predictions3D | None = None,
    ball: int | None = None,
    min_font: float | None = None,
) -> Path:
    """Write the spherical scene's figure as a PNG (``width`` inches at 300 dpi times
    ``scale``), atomically: :func:`eyeviz.render.mpl.figure3d.export3d` with the 3D view
    rendered by VTK (:func:`view_rgba`) at the view box's pixel size. EyevizError (one
    line) for a view beyond :data:`MAX_VIEW_PX` pixels. The predictions layer answers
    for ball ``ball`` (default ``selected``, else the first); ``predictions`` is its content when
    computed already (the app's), else it is computed once here for both the view and
    the readout."""
    if Path(path).suffix.lower() != ".png":
        raise EyevizError(f"export_png3d writes .png files, got {str(path)!r}")
    st = compute_state3d(scene)
    preds = predictions
    if scene.shows("predictions") and preds is None and scene.features:
        one = ball if ball is not None else (0 if selected is None else selected)
        preds = scene_predictions3d(scene, st, min(max(one, 0), st.n - 1), Predictor3D())

    def vtk_view(cam: Camera3D, w: int, h: int) -> np.ndarray:
        if max(w, h) > MAX_VIEW_PX:
            most = float(scale) * MAX_VIEW_PX / max(w, h)
            raise EyevizError(
                f"scale {float(scale):g} makes the 3D view {w} x {h} px; VTK renders at most "
                f"{MAX_VIEW_PX} px: scale <= {most:.3g} at this width"
            )
        return view_rgba(
            scene, cam, w, h, state=st, selected=selected, transparent=transparent,
            predictions=preds,
        )  # fmt: skip

    return export3d(
        scene, path, scale, transparent, width=width, title=title, table=table,
        bitmaps=bitmaps, aspect=aspect, camera=camera, view=view, view_image=vtk_view,
        predictions=preds, ball=ball if ball is not None else (selected or 0),
        min_font=min_font,
    )  # fmt: skip
