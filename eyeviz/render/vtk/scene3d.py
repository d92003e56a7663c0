"""A spherical-side scene -> VTK actors, updated in place (the app's 3D view and its PNG).

:class:`Scene3DActors` draws a :class:`eyeviz.model.state3d.SceneState3D` in two
renderers side by side: ``scene`` (the balls, the eyes, the binocular field's cones, the
tangent cones, the acceptance cones and the plane z = 0, through the view's camera) and
``eyes`` (the two eyes close up, seen from the same direction: at the paper's distances
an eye is a few pixels in the scene, so its facets are shown again where they can be
seen; :func:`eyeviz.model.camera3d.eyes_camera`). The eyes are HEALPix spheres or
measured eyes (docs/measured.md): what differs is the model's
:class:`eyeviz.model.facets3d.EyeSurface`. Every position drawn comes from
:mod:`eyeviz.model.shapes3d`, the surface or the state; nothing here computes geometry.

One painter per layer (as the planar view's :mod:`eyeviz.render.vtk.layers`), named by
the layer table's ``vtk3d`` hooks (:data:`eyeviz.model.layers.LAYERS`, made in
``vtk3d_order``), each rebuilding its actors only when its structure changes and writing
positions and colours in place every frame; a painter draws the few layers that share its
actors: :mod:`~eyeviz.render.vtk.field3d` (``bfv``, ``plane``),
:mod:`~eyeviz.render.vtk.eyes3d` (``eyes``: the facets, lit in the colour of the ball
they see, with the level of detail of a large nside), :mod:`~eyeviz.render.vtk.balls3d`
(``features``, ``labels``, ``tangents``) and :mod:`~eyeviz.render.vtk.cones3d`
(``cones``: the selected ball's lit acceptance cones, measured eyes).
"""

from __future__ import annotations

import os
from dataclasses import replace
from pathlib import Path
from typing import TypeVar

import numpy as np
from vtkmodules.vtkCommonCore import vtkCommand
from vtkmodules.vtkRenderingCore import vtkRenderer

from eyeviz.files.atomic import atomic_output
from eyeviz.model import shapes3d
from eyeviz.model.camera3d import Camera3D, dolly, eyes_camera
from eyeviz.model.facets3d import EyeSurface, surface_of
from eyeviz.model.labels3d import (
    KEEP_CLEAR_PX,
    LABEL_MARGIN_PX,
    Named3D,
    discs,
    fit_labels,
    frame_names,
    pan,
    shifted,
)
from eyeviz.model.labels3d import (
    _covers as covers,
)
from eyeviz.model.layers import ordered, resolve
from eyeviz.model.predictions3d import Predictions3D
from eyeviz.model.scene import Scene
from eyeviz.model.state3d import SceneState3D, compute_state3d
from eyeviz.render.style3d import EYES_FRACTION  # the looks the vector view shares
from eyeviz.render.vtk.balls3d import BallsPainter
from eyeviz.render.vtk.cones3d import ConesPainter
from eyeviz.render.vtk.eye_names3d import (
    EYE_NAMES,
    SHORT_NAMES,
    misplaced,
    names_under,
    over_discs,
    unclear,
)
from eyeviz.render.vtk.eyes3d import LABEL_PX as EYES_LABEL_PX
from eyeviz.render.vtk.eyes3d import EyesPainter
from eyeviz.render.vtk.field3d import FieldPainter
from eyeviz.render.vtk.ghosts3d import Ghosts3D, make_overlay
from eyeviz.render.vtk.names3d import Leaders, named_of, place_texts, show_at
from eyeviz.render.vtk.offscreen import OffscreenWindow
from eyeviz.render.vtk.painter3d import Painter3D
from eyeviz.render.vtk.primitives import fit_lines, screen_text
from eyeviz.render.vtk.style import BACKGROUND, INK, INSET_BACKGROUND

__all__ = [
    "EYES_FRACTION",
    "LABEL_MARGIN_PX",
    "PNG_ASPECT",
    "Scene3DActors",
    "apply_camera",
    "camera_of",
    "fit_labels",
    "frame_names",
    "default_camera",
    "pan",
    "png_size",
    "render_png3d",
    "split_viewports",
]

LABEL_PX = EYES_LABEL_PX


def split_viewports(w: float, h: float) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """(eyes, scene) viewports (xmin, ymin, xmax, ymax) of a ``w`` x ``h`` pixel view."""
    f = EYES_FRACTION if w >= 2.0 * h * EYES_FRACTION else 0.5
    return (0.0, 0.0, f, 1.0), (f, 0.0, 1.0, 1.0)


def apply_camera(ren: vtkRenderer, cam: Camera3D) -> None:
    """Put a :class:`Camera3D` into a VTK renderer (clipping range fitted to its props)."""
    c = ren.GetActiveCamera()
    c.SetPosition(*cam.position)
    c.SetFocalPoint(*cam.focal_point)
    c.SetViewUp(*cam.view_up)
    c.SetViewAngle(cam.view_angle)
    c.OrthogonalizeViewUp()
    ren.ResetCameraClippingRange()


def camera_of(ren: vtkRenderer) -> Camera3D:
    """A VTK renderer's camera as a :class:`Camera3D`."""
    c = ren.GetActiveCamera()
    return Camera3D(
        tuple(float(v) for v in c.GetPosition()),  # type: ignore[arg-type]
        tuple(float(v) for v in c.GetFocalPoint()),  # type: ignore[arg-type]
        tuple(float(v) for v in c.GetViewUp()),  # type: ignore[arg-type]
        float(c.GetViewAngle()),
    )


def default_camera(state: SceneState3D, name: str = "default", aspect: float = 1.0) -> Camera3D:
    """The preset ``name`` framing the scene's balls (:func:`shapes3d.scene_extent`) in a
    viewport ``aspect`` (width / height) wide."""
    return shapes3d.view_camera(state, name, aspect)


P = TypeVar("P", bound=Painter3D)


def _painter(painters: list[Painter3D], cls: type[P]) -> P:
    """The painter of class ``cls`` among ``painters`` (the table's ``vtk3d`` hooks)."""
    for p in painters:
        if isinstance(p, cls):
            return p
    raise LookupError(f"no {cls.__name__} among the layer table's 3D painters")


def _aspect(ren: vtkRenderer) -> float:
    """A renderer's width / height in pixels (1 before it has a window)."""
    w, h = ren.GetSize()
    return w / h if w > 0 and h > 0 else 1.0


class Scene3DActors:
    """The painters of one 3D view (see the module docstring); ``update`` after each change.

    ``field`` (bfv, plane), ``eyes`` (the facets), ``balls`` (features, labels, tangents)
    and ``cones`` (the lit acceptance cones), painted in that order; the title, the
    close-up's caption and the predictions' overlay are the view's own."""

    def __init__(self, scene_ren: vtkRenderer, eyes_ren: vtkRenderer | None) -> None:
        self.scene_ren = scene_ren
        self.eyes_ren = eyes_ren
        self.renderers = [r for r in (scene_ren, eyes_ren) if r is not None]
        self.title = screen_text(22, INK, (0.01, 0.985), top=True)
        scene_ren.AddViewProp(self.title)
        # the view's own texts no ball's name may cover (the app adds its side note)
        self.keep_clear: list = [self.title]
        # the title is broken into lines that fit the view, checked before each render
        # (the view's width and the title's font size change with the window and F5/Ctrl+=)
        self._title_text = ""
        self._title_lines = ""  # the title as fitted to the view (shown unless it gave way)
        self._title_fit: tuple | None = None
        scene_ren.AddObserver(vtkCommand.StartEvent, self._fit_title)
        scene_ren.AddObserver(vtkCommand.StartEvent, self._place_names)
        self.leaders = Leaders(scene_ren)  # from a ball to its name placed farther out
        if eyes_ren is not None:
            eyes_ren.AddObserver(vtkCommand.StartEvent, self._place_eye_names)
        self.state: SceneState3D | None = None
        self.selected: int | None = None
        # the last preset framing (frame_preset): how far back, how far aside, what size
        self._back: float | None = None
        self._aside = np.zeros(3)
        self._framed_size: tuple[float, float] = (0.0, 0.0)
        self.scene_shows_predictions = False
        self.name_boxes = np.zeros((0, 4))
        self.eye_name_boxes = np.zeros((0, 4))  # the close-up's names' (its pixels, y up)
        self.eye_name_anchors = np.zeros((0, 2))  # and its eyes' centres
        self.eyes_caption = screen_text(16, (0.35, 0.35, 0.35), (0.03, 0.985), top=True)
        self._caption_fit: tuple | None = None  # fitted to: see _fit_caption
        self._caption_shown = ""
        if eyes_ren is not None:
            eyes_ren.AddViewProp(self.eyes_caption)
        # one painter per layer of the table that has one (LayerSpec.vtk3d), in draw order
        self.painters: list[Painter3D] = [
            resolve(spec.vtk3d)(scene_ren, eyes_ren) for spec in ordered("vtk3d")
        ]
        # the view's own uses of the shipped painters (names, the close-up's caption)
        self.field = _painter(self.painters, FieldPainter)
        self.eyes = _painter(self.painters, EyesPainter)
        self.eyes.caption = self.eyes_caption
        self.balls = _painter(self.painters, BallsPainter)
        self.cones = _painter(self.painters, ConesPainter)
        self.surface: EyeSurface | None = None
        # the predictions layer: a renderer over the scene's, made on first use
        self.overlay: vtkRenderer | None = None
        self.ghosts: Ghosts3D | None = None

    def frame(
        self, cam: Camera3D, size: tuple[float, float], pan_ok: bool = True
    ) -> tuple[Camera3D, bool]:
        """:func:`frame_names` for the names shown, clear of the view's title and side
        note; where no framing keeps the names and balls clear of the title (a view a
        few names high: sphere_lecture's step 7 at F11 + F5 + 175 % in 1280 x 720 is 234
        px high, its title 57 px), the title gives way (until the view's size or text
        size changes, as in :meth:`_place_names`) and the framing is made without it.
        ``pan_ok`` as in :func:`frame_names`. Returns the camera and whether it is clear."""
        self._fit_title()
        saved = self._title_lines  # shown again if it gave way before: tried first
        self.title.SetInput(saved)
        framed, clear = frame_names(cam, self.named(), size, pan_ok=pan_ok)
        if clear or not saved:
            return framed, clear
        self.title.SetInput("")
        bare, clear = frame_names(cam, self.named(), size, pan_ok=pan_ok)
        if clear:
            return bare, True
        self.title.SetInput(saved)
        return framed, False

    def frame_preset(self, base: Camera3D, size: tuple[float, float], keep: bool) -> Camera3D:
        """A preset's camera ``base`` framed for the names (:meth:`frame`) in a view of
        ``size`` pixels; ``keep`` (a resize) keeps it as far back as the last framing
        and, while the view's height is the same, as far aside (the focal point kept: an
        edit that grew a panel must not re-frame) unless that is not clear in a new
        width; a new height moves the band between the view's texts, so the move aside
        is made anew (the first framing, at the window's first layout, is of a 240 x 400
        view)."""
        same_h = size[1] == self._framed_size[1]
        cam = base
        if keep and self._back is not None:
            cam = dolly(base, self._back)
            if same_h:
                cam = shifted(cam, self._aside)
        framed, clear = self.frame(cam, size, pan_ok=not (keep and same_h))
        if keep and same_h and not clear and size[0] != self._framed_size[0]:
            framed, clear = self.frame(dolly(base, self._back or 1.0), size)
        d0 = float(np.linalg.norm(np.subtract(base.position, base.focal_point)))
        self._back = float(np.linalg.norm(np.subtract(framed.position, framed.focal_point))) / d0
        self._aside = np.subtract(framed.focal_point, base.focal_point)
        self._framed_size = size
        return framed

    def named(self) -> Named3D:
        """The ball names shown and what they must not cover, for :func:`fit_labels`."""
        return self._ball_names()[1]

    def _eye_spheres(self) -> np.ndarray:
        s = self.surface
        if s is None:
            return np.zeros((0, 4))
        return np.array([(*c, s.radius) for c in s.centres], float)

    def _ball_names(self) -> tuple[list[int], Named3D]:
        others = [self._eye_spheres()]
        if self.ghosts is not None and self.scene_shows_predictions:
            others.append(self.ghosts.discs())
        st = self.state
        if st is None:
            return [], Named3D(np.zeros((0, 3)), np.zeros(0), np.zeros((0, 2)), np.zeros((0, 4)))
        order, named = self.balls.named(st, np.concatenate(others), self._dpi(), self.selected)
        return order, replace(named, keep_out=self._text_boxes())

    def _text_boxes(self, actors=None, ren=None) -> np.ndarray:
        """Boxes (k, 4, the scene viewport's pixels, y up) of the shown texts among
        ``actors`` (default :attr:`keep_clear`): at 175 % in a small window a name printed
        over the title (issue 32.3).

        A text actor's bounding box is relative to its anchor (the title's reached from
        -57 to 0 px, under the view, so names were still placed over it at F11 + F5 +
        175 % in 1280 x 720): moved by the anchor's viewport pixels, and grown by
        :data:`KEEP_CLEAR_PX` so that no name touches it."""
        ren, out, pad = ren or self.scene_ren, [], KEEP_CLEAR_PX
        for actor in self.keep_clear if actors is None else actors:
            if actor.GetVisibility() and actor.GetInput():
                b = [0.0] * 4  # x0, x1, y0, y1, relative to the anchor
                actor.GetBoundingBox(ren, b)
                ax, ay = actor.GetActualPositionCoordinate().GetComputedViewportValue(ren)
                out.append((ax + b[0] - pad, ay + b[2] - pad, ax + b[1] + pad, ay + b[3] + pad))
        return np.array(out, float).reshape(-1, 4)

    def _place_names(self, *_args) -> None:
        """Before the scene renders: each ball's name beside it, over nothing (issue 32.4).
        Where no place clear of the title is left (step 7 of sphere_lecture at F11 + F5 +
        175 % in 1280 x 720: a 234 px high view, 51 px names, a 57 px title), the title
        gives way until the view's size or text size changes (the step's caption says
        more than the scene's title)."""
        cam = camera_of(self.scene_ren)
        order, named = self._ball_names()
        boxes = place_texts(self.scene_ren, cam, self.balls.ball_labels, named, order)
        if self.title.GetInput() and covers(boxes, self._text_boxes([self.title])):
            self.title.SetInput("")
            order, named = self._ball_names()
            boxes = place_texts(self.scene_ren, cam, self.balls.ball_labels, named, order)
        self.name_boxes = boxes
        labs = self.balls.ball_labels
        cols = [labs[i].GetTextProperty().GetColor() for i in order]
        self.leaders.draw_for(cam, named, boxes, cols, self.scene_ren.GetSize())

    def _place_eye_names(self, *_args) -> None:
        """Before the close-up renders: each eye's name under it, over nothing: not the
        other's name nor the close-up's caption (F11 + F5 + 175 % in 1280 x 720: "eye A"
        printed over it, or over "eye B", in sphere_lecture's steps 6-8). Where the names find
        no places clear of the caption and of each other, the caption gives way (this frame:
        each frame tries again). Where a whole name reads as neither eye's, the names are
        "A" and "B" (:func:`eyeviz.render.vtk.eye_names3d.unclear`)."""
        if self.eyes_ren is None or self.state is None:
            return
        eyes = self._eye_spheres()  # the close-up draws no ball: the eyes are all there is
        labs = self.eyes.labels
        if len(labs) != len(eyes):
            return
        for names in (EYE_NAMES, SHORT_NAMES, EYE_NAMES):  # short ones no clearer: whole
            for lab, name in zip(labs, names, strict=False):
                if lab.GetInput() != name:
                    lab.SetInput(name)
            boxes, at = self._eye_names_once(eyes, labs)
            # a name as near the other eye as its own (a 300 px pane at 175 %: both names
            # between the eyes in sphere_lecture's step 6) reads as neither's: "A", "B"
            if not unclear(boxes, at):
                break
        self.eye_name_boxes = boxes
        self.eye_name_anchors = at

    def _eye_names_once(self, eyes: np.ndarray, labs: list) -> tuple[np.ndarray, np.ndarray]:
        """The close-up's names placed as they read now (see :meth:`_place_eye_names`):
        their boxes and the eyes' disc centres (pixels)."""
        ren, cap = self.eyes_ren, self.eyes_caption
        assert ren is not None
        cap.GetTextProperty().SetOpacity(1.0)
        self._fit_caption()
        keep = self._text_boxes([cap], ren)
        order, named = named_of(
            labs, eyes[:, :3], eyes[:, 3], np.zeros((0, 4)), self._dpi(), below=True
        )
        w, h = ren.GetSize()
        at, rad = discs(camera_of(ren), named.centres, named.radii, float(w), float(h))
        if over_discs(keep, at, rad):  # never over an eye (its third line, a short pane)
            cap.GetTextProperty().SetOpacity(0.0)
            keep = np.zeros((0, 4))
        named = replace(named, keep_out=keep)
        # both eyes named always: where they cross, the caption gives way instead
        boxes = place_texts(ren, camera_of(ren), labs, named, order, give_way=False)
        crossed = any(covers(boxes[i : i + 1], boxes[i + 1 :]) for i in range(len(boxes)))
        # a name placed nearer the other eye than its own reads as that eye's (a tiny
        # pane at 175 %: "eye A" under eye B): the caption gives way too
        if crossed or covers(boxes, keep) or misplaced(boxes, at):
            cap.GetTextProperty().SetOpacity(0.0)
            bare = replace(named, keep_out=None)
            boxes = place_texts(ren, camera_of(ren), labs, bare, order, give_way=False)
            if misplaced(boxes, at):  # no free place near its own eye: right under it
                boxes = names_under(at, rad, named.sizes, float(w), float(h))
                show_at(labs, order, boxes, at)
        return boxes, at

    def _fit_caption(self) -> None:
        """The close-up's caption in lines that fit its pane: as it is where it fits, else
        without its lead-in ("the eyes close up: ") broken at spaces into one line more than
        it has, else none: never cut with "…" (at F11 + F5 + 175 % in 1280 x 720 its 614 px
        line was cut at the right of a 305-355 px pane, then "768 facet…"). Refitted when the
        pane's width, the font size or the caption change."""
        cap, ren = self.eyes_caption, self.eyes_ren
        if ren is None or self.surface is None or not cap.GetInput():
            return
        tp, dpi, text = cap.GetTextProperty(), self._dpi(), self.surface.caption
        key = (ren.GetSize()[0], tp.GetFontSize(), dpi, text)
        if key == self._caption_fit and cap.GetInput() == self._caption_shown:
            return
        avail = ren.GetSize()[0] * (1.0 - 2.0 * cap.GetPosition()[0]) - 4.0
        n = text.count("\n") + 1
        shown = fit_lines(tp, text, avail, dpi, n)
        if shown != text and ": " in text.split("\n")[0]:
            shown = fit_lines(tp, text.split(": ", 1)[1], avail, dpi, n + 1)
        if shown.endswith("…"):  # never cut: whole, or it gives way
            shown = ""
        self._caption_fit, self._caption_shown = key, shown
        cap.SetInput(shown)

    def _dpi(self) -> int:
        win = self.scene_ren.GetRenderWindow()
        return win.GetDPI() if win is not None else 72

    def _fit_title(self, *_args) -> None:
        """Break the title into lines that fit the scene's viewport (at most two, else
        none: never cut with "…"; one where two would take over a fifth of a short view's
        height: at 175 % in a 1280 x 720 screen they left the balls' names no room; none
        while the names find no place clear of it, see :meth:`_place_names`); refitted
        only when the view's size, the font size or the title change."""
        ren = self.scene_ren
        width, height = ren.GetSize()
        tp = self.title.GetTextProperty()
        dpi = self._dpi()
        key = (width, height, tp.GetFontSize(), dpi)
        if key == self._title_fit or width <= 0:
            return
        self._title_fit = key
        avail = width * (1.0 - 2.0 * self.title.GetPosition()[0]) - 4.0
        two = 2 * 1.2 * tp.GetFontSize() * dpi / 72.0 <= 0.2 * height
        lines = fit_lines(tp, self._title_text, avail, dpi, max_lines=2 if two else 1)
        # never cut ("Spherical c…" at F11 + F5 + 175 % in 1280 x 720): whole, or it gives
        # way (the step's caption says more)
        self._title_lines = (
            "" if lines.endswith("…") and not self._title_text.endswith("…") else lines
        )
        self.title.SetInput(self._title_lines)

    def update(self, scene: Scene, state: SceneState3D, selected: int | None) -> None:
        """Draw ``state`` (of ``scene``): each painter rebuilds only what changed."""
        surface = surface_of(state.pair)
        if self.surface is None or surface.key != self.surface.key:
            self.surface = surface
        if scene.title != self._title_text:
            self._title_text = self._title_lines = scene.title
            self._title_fit = None
            self.title.SetInput(scene.title)
        for p in self.painters:
            p.update(scene, state, selected, self.surface)
        self.state, self.selected = state, selected
        self.scene_shows_predictions = scene.shows("predictions")

    def draw_predictions(self, preds: Predictions3D | None) -> None:
        """The predictions layer (:mod:`eyeviz.render.vtk.ghosts3d`): ``preds``' ghosts
        and cloud over the scene; None hides them."""
        if preds is None and self.ghosts is None:
            return
        if self.ghosts is None:
            self.overlay = make_overlay(self.scene_ren)
            if self.overlay is None:
                return
            self.ghosts = Ghosts3D(self.overlay)
        self.sync_overlay()
        self.ghosts.draw(preds)

    def sync_overlay(self) -> None:
        """The predictions' renderer keeps the scene's viewport."""
        if self.overlay is not None:
            self.overlay.SetViewport(*self.scene_ren.GetViewport())

    def set_cameras(self, cam: Camera3D) -> None:
        """The scene through ``cam``; the eyes from the same direction, framed."""
        apply_camera(self.scene_ren, cam)
        self.sync_overlay()
        if hasattr(self.scene_ren, "camera_set"):  # pyvista's: no reset at its first render
            self.scene_ren.camera_set = True
        if self.eyes_ren is not None and self.surface is not None:
            self._eyes_camera(cam)

    def _eyes_camera(self, cam: Camera3D) -> None:
        assert self.eyes_ren is not None and self.surface is not None
        h = abs(self.surface.centres[1][0] - self.surface.centres[0][0]) / 2.0
        r = self.surface.radius
        apply_camera(self.eyes_ren, eyes_camera(cam, h, r, _aspect(self.eyes_ren)))

    def sync_eyes_camera(self) -> None:
        """The eyes' camera follows the scene camera's direction (after a rotation)."""
        self.sync_overlay()
        if self.eyes_ren is not None and self.surface is not None:
            self._eyes_camera(camera_of(self.scene_ren))


def make_renderers(ren_win, scene_ren: vtkRenderer) -> vtkRenderer:
    """Add the eyes' renderer beside ``scene_ren`` in ``ren_win``; returns it."""
    eyes = vtkRenderer()
    eyes.SetUseOIT(False)
    eyes.SetUseDepthPeeling(False)
    eyes.SetBackground(*INSET_BACKGROUND)
    eyes.InteractiveOff()  # the mouse over it turns the scene's camera (it follows)
    eyes.AutomaticLightCreationOn()
    ren_win.AddRenderer(eyes)
    scene_ren.SetBackground(*BACKGROUND)
    return eyes


def layout(scene_ren: vtkRenderer, eyes_ren: vtkRenderer, w: float, h: float) -> None:
    left, right = split_viewports(w, h)
    eyes_ren.SetViewport(*left)
    scene_ren.SetViewport(*right)


#: A PNG's height / width when none is given (the app's window is about as wide).
PNG_ASPECT = 9.0 / 16.0


def png_size(width_px: float, aspect: float | None = None) -> tuple[int, int]:
    """(width, height) pixels of a PNG ``width_px`` wide, ``aspect`` (height / width,
    default :data:`PNG_ASPECT`) high; EyevizError (one line) beyond 64 ... 8192 pixels."""
    from eyeviz import EyevizError

    a = PNG_ASPECT if aspect is None else float(aspect)
    w, h = int(round(width_px)), int(round(width_px * a))
    if not (64 <= w <= 8192 and 64 <= h <= 8192):
        raise EyevizError(
            f"a 3D PNG must be 64 to 8192 pixels wide and high, got {w} x {h} "
            "(change --scale, --width or --aspect)"
        )
    return w, h


def offscreen_view(width: int, height: int) -> tuple[OffscreenWindow, Scene3DActors]:
    """An off-screen window laid out as the app's 3D view (the scene, the eyes' close-up),
    with no multisampling and no depth peeling, and its empty actors: what
    :func:`render_png3d` and :mod:`eyeviz.render.vtk.png3d` render with. The caller
    closes the window. Plain VTK (:class:`eyeviz.render.vtk.offscreen.OffscreenWindow`,
    lit as pyvista's light kit: the same pixels within one level in a thousandth of them):
    a pyvista plotter cost a spherical snapshot a quarter of a second (issue 32.14)."""
    win = OffscreenWindow(width, height)
    try:
        main = win.renderer
        main.SetUseOIT(False)
        main.SetUseDepthPeeling(False)
        eyes = make_renderers(win.ren_win, main)
        layout(main, eyes, width, height)
        return win, Scene3DActors(main, eyes)
    except BaseException:
        win.close()
        raise


def shoot(
    win: OffscreenWindow, actors: Scene3DActors, camera: Camera3D, transparent: bool
) -> np.ndarray:
    """Render ``win`` (from :func:`offscreen_view`) through ``camera``; its pixels."""
    actors.set_cameras(camera)
    return win.pixels(transparent)


def render_png3d(
    scene: Scene,
    path: str | os.PathLike,
    camera: Camera3D | None = None,
    width: int = 1600,
    height: int = 900,
    *,
    state: SceneState3D | None = None,
    selected: int | None = None,
    transparent: bool = False,
    predictions: Predictions3D | None = None,
) -> Path:
    """Render a spherical scene off-screen (no display: EGL) to a PNG at ``camera`` (the
    default preset framing the balls when None), ``width`` x ``height`` pixels, written
    atomically; the same picture as the app's 3D view (``transparent``: no background;
    ``predictions``: the predictions layer's content, drawn when the scene shows it)."""
    from eyeviz import EyevizError
    from eyeviz.core.validation import check_int

    if Path(path).suffix.lower() != ".png":
        raise EyevizError(f"render_png3d writes .png files, got {str(path)!r}")
    width = check_int("width", width, ge=64, le=8192)
    height = check_int("height", height, ge=64, le=8192)
    target = Path(path)
    if not (target.parent if str(target.parent) else Path(".")).is_dir():
        raise EyevizError(f"{target}: directory {target.parent} does not exist")
    st = compute_state3d(scene) if state is None else state
    win, actors = offscreen_view(width, height)
    try:
        actors.update(scene, st, selected)
        actors.draw_predictions(predictions if scene.shows("predictions") else None)
        if camera is None:
            left, _ = split_viewports(width, height)
            camera = default_camera(st, aspect=(1.0 - left[2]) * width / height)
        img = shoot(win, actors, camera, transparent)
    finally:
        win.close()
    from PIL import Image

    with atomic_output(target) as tmp:
        Image.fromarray(np.asarray(img)).save(str(tmp), format="PNG")
    return target
