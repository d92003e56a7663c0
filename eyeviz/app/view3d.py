"""The 3D view of the main window: a spherical scene in pyvistaqt, in the same window.

Opening a spherical-side scene (HEALPix eyes, ``[eyes] nside``, or measured eyes,
``[eyes] file``: docs/measured.md) swaps the planar view and its strip for this
view (:class:`Scene3DHost`), hides the planar docks and shows the 3D ones (the facets on
Mollweide maps, the readout); opening a planar scene swaps back. The flow is the planar
one (docs/architecture.md): Qt events -> :mod:`eyeviz.model.app_model3d` (a drag is one
generator, one undo step on the window's stack) -> ``compute_state3d`` ->
:class:`eyeviz.render.vtk.scene3d.Scene3DActors` and the docks.

Mouse and keys (3D view > Mouse and keys and Help > Keyboard shortcuts are both written
from one list, eyeviz.app.help.VIEW3D_KEYS):

- standard VTK camera interaction (trackball): left-drag on the background turns the
  view, middle-drag (or Shift+left on the background) pans, the wheel or right-drag
  zooms; the eyes' close-up (left) always looks from the scene camera's direction;
- left-drag on a ball moves it in the plane through its centre facing the camera;
  Shift+ or Ctrl+left-drag on a ball moves it along the line of sight (up: farther);
- with the view focused, the arrow keys nudge the selected ball across the screen,
  Shift+Up / Shift+Down move it farther / nearer along the line of sight (Tab selects the
  next ball);
- View > 3D view: the camera presets (0 default, 1 front, 2 top, 3 side, 4 along eye A's
  axis, 5 along eye B's axis) and the layers.
"""

from __future__ import annotations

import math
import time
from collections.abc import Generator
from typing import TYPE_CHECKING, Any

from PyQt5 import QtCore, QtWidgets

from eyeviz.app.actions import PLANAR_ONLY, command3d
from eyeviz.app.help import LAYER3D_TEXT, view3d_help_text
from eyeviz.app.predictions_layer3d import Predictions3DLayer
from eyeviz.app.status3d import StatusLine, ball_status
from eyeviz.app.view import make_view
from eyeviz.model import app_model3d as m3
from eyeviz.model.camera3d import PRESETS, Camera3D
from eyeviz.model.draw_bounds import check_drawable_eyes
from eyeviz.model.predictions3d import LatestOnly, Predictions3D, Predictor3D, check_estimators
from eyeviz.model.scene import SPHERICAL_LAYERS, Scene, layer_applies
from eyeviz.render.vtk.scene3d import (
    Scene3DActors,
    camera_of,
    default_camera,
    layout,
    make_renderers,
    split_viewports,
)
from eyeviz.render.vtk.side3d import SideNote

if TYPE_CHECKING:
    from eyeviz.app.panels.bitmaps3d import Bitmaps3DPanel
    from eyeviz.app.panels.estimators3d import Estimators3DPanel
    from eyeviz.app.panels.readout3d import Readout3DPanel
    from eyeviz.app.view import _Frames

__all__ = ["PRESET_KEYS", "Scene3DHost"]

#: View > 3D view presets: (name, menu text, shortcut)
PRESET_KEYS = (
    ("default", "&Default (3/4 view)", "0"),
    ("front", "&Front", "1"),
    ("top", "&Top", "2"),
    ("side", "&Side", "3"),
    ("eye_a", "Along eye &A's axis", "4"),
    ("eye_b", "Along eye &B's axis", "5"),
)
PANEL_SHARE = 0.25  # the docks take at most about this share of a drag's time
PANEL_FRAMES = 4  # and follow it at most every fourth frame
DOCK_FRACTION = 0.41  # the 3D docks' column takes at most this share of the window's width
# (0.4 left the Balls table's names 5 px short at F11 + F5 in 1280 x 720: "tar…")
PANEL_MS = 250  # the docks follow a drag at <= 4 Hz (the Mollweide maps take 15-75 ms at
# nside 180); the drag's end refreshes them at once
_MOD_DEPTH = QtCore.Qt.KeyboardModifier.ShiftModifier | QtCore.Qt.KeyboardModifier.ControlModifier


class Scene3DHost(Predictions3DLayer, QtCore.QObject):
    """The window's 3D page: the view widget, its actors and model, the 3D docks, the
    View > 3D view menu. Built on the first spherical scene; ``active`` while shown."""

    def __init__(self, win: QtWidgets.QMainWindow, split: QtWidgets.QSplitter) -> None:
        super().__init__(win)
        # the MainWindow (its plotter, bitmaps, undo_stack, jobs, show_error); typed
        # loosely: this module is imported by the window (no import cycle)
        self.win: Any = win
        self.split = split
        self.active = False
        self.model: m3.AppModel3D | None = None
        self.view: _Frames | None = None
        self.actors: Scene3DActors | None = None
        self.bitmaps: Bitmaps3DPanel | None = None
        self.readout: Readout3DPanel | None = None
        self.estimators: Estimators3DPanel | None = None
        # the selected ball's status line, in the first form that fits the bar
        self.status_line = StatusLine(win, lambda: ball_status(self.model), lambda: self.active)
        # the predictions layer (eyeviz.model.predictions3d): the fast estimators answer
        # on every frame; the limit on the window's job runner after a drag, latest only
        self.predictor3d: Predictor3D | None = None
        self.preds: Predictions3D | None = None
        self.latest = LatestOnly()
        self.limit_jobs = 0  # limit jobs started (tests)
        self.docks: dict[str, QtWidgets.QDockWidget] = {}
        self._hidden: list[QtWidgets.QWidget] = []
        self._drag: Generator[None, m3.Pointer, None] | None = None
        self._press_cam: Camera3D | None = None  # the camera at a drag's press
        self._dirty = False
        self._panel_frames = 0  # drag frames drawn since the docks' last refresh
        self._frame_timer = QtCore.QTimer(self)
        self._frame_timer.setSingleShot(True)
        self._frame_timer.setInterval(0)
        self._frame_timer.timeout.connect(self.draw)
        # a window's first show resizes the view several times: one re-frame for all
        self._resize_timer = QtCore.QTimer(self)
        self._resize_timer.setSingleShot(True)
        self._resize_timer.setInterval(0)
        self._resize_timer.timeout.connect(self._resized)
        self._panel_timer = QtCore.QTimer(self)
        self._panel_timer.setSingleShot(True)
        self._panel_timer.setInterval(PANEL_MS)
        self._panel_timer.timeout.connect(self.refresh_panels)
        self.help_box: QtWidgets.QMessageBox | None = None  # 3D view > Mouse and keys
        self.preset: str | None = None  # the preset shown, until the user moves the camera
        self._framed: m3.SceneState3D | None = None  # the state the preset framed
        self._fit_width = 0  # the window's width the docks' column was last fitted to
        self.preset_actions: dict[str, QtWidgets.QAction] = {}
        self.layer_actions: dict[str, QtWidgets.QAction] = {}
        self.menu = self._build_menu()
        self._menu_action(False)

    # --- the page ------------------------------------------------------------------------
    def _build(self) -> None:
        view = make_view(None)
        view.setFocusPolicy(QtCore.Qt.FocusPolicy.StrongFocus)
        view.setObjectName("view3d")
        from vtkmodules.vtkCommonCore import vtkCommand
        from vtkmodules.vtkInteractionStyle import vtkInteractorStyleTrackballCamera

        style = vtkInteractorStyleTrackballCamera()
        iren = view.ren_win.GetInteractor()
        iren.SetInteractorStyle(style)
        self.style = style
        # a preset is kept across resizes until the user turns or zooms the view
        style.AddObserver(vtkCommand.StartInteractionEvent, lambda *_: self._forget_preset())
        scene_ren = view.renderer
        scene_ren.AutomaticLightCreationOn()
        eyes_ren = make_renderers(view.ren_win, scene_ren)
        self.view = view
        self.actors = Scene3DActors(scene_ren, eyes_ren)
        self.side = SideNote(scene_ren)  # "seen from front, ...; eye A on the right"
        self.actors.keep_clear.append(self.side.actor)  # no ball's name over it
        # the eyes' camera follows the scene's before every render (VTK's own too)
        view.ren_win.AddObserver(vtkCommand.StartEvent, lambda *_: self._sync_eyes())
        view.installEventFilter(self)
        self.split.addWidget(view)
        self.split.setStretchFactor(self.split.indexOf(view), 1)
        # imported with the page: matplotlib's Qt canvas costs a planar window ~1 s
        from eyeviz.app.panels.bitmaps3d import Bitmaps3DPanel
        from eyeviz.app.panels.estimators3d import Estimators3DPanel
        from eyeviz.app.panels.readout3d import Readout3DPanel

        self.bitmaps = Bitmaps3DPanel()
        self.readout = Readout3DPanel(lambda: self.model)  # typed values, row clicks
        self.estimators = Estimators3DPanel(self._set_estimators)
        self.docks["bitmaps3d"] = self._dock("Facets (Mollweide)", self.bitmaps, "bitmaps3d")
        self.docks["readout3d"] = self._dock("Balls", self.readout, "readout3d")
        # as the planar window's: a tab beside the readout, greyed until the layer is on
        self.docks["estimators3d"] = self._dock("Estimators", self.estimators, "estimators3d")
        self.win.tabifyDockWidget(self.docks["readout3d"], self.docks["estimators3d"])

    def _dock(self, title: str, widget: QtWidgets.QWidget, name: str) -> QtWidgets.QDockWidget:
        d = QtWidgets.QDockWidget(title, self.win)
        d.setObjectName(f"dock_{name}")
        d.setWidget(widget)
        self.win.addDockWidget(QtCore.Qt.DockWidgetArea.RightDockWidgetArea, d)
        d.hide()
        return d

    def _build_menu(self) -> QtWidgets.QMenu:
        mb = self.win.menuBar()
        assert mb is not None
        menu = QtWidgets.QMenu("&3D view", self.win)
        mb.addMenu(menu)
        for name, text, key in PRESET_KEYS:
            a = QtWidgets.QAction(text, self.win)
            a.setShortcut(key)
            a.setShortcutContext(QtCore.Qt.ShortcutContext.WindowShortcut)
            a.triggered.connect(lambda _c=False, n=name: self.set_preset(n))
            a.setEnabled(False)
            menu.addAction(a)
            self.win.addAction(a)
            self.preset_actions[name] = a
        menu.addSeparator()
        help_action = QtWidgets.QAction("Mouse and &keys…", self.win)
        help_action.triggered.connect(self._show_help)
        menu.addAction(help_action)
        menu.addSeparator()
        for layer in SPHERICAL_LAYERS:
            a = QtWidgets.QAction(f"Show {LAYER3D_TEXT.get(layer, layer)}", self.win)
            a.setCheckable(True)
            a.triggered.connect(lambda on, n=layer: self._set_layer(n, on))
            menu.addAction(a)
            self.layer_actions[layer] = a
        return menu

    def _show_help(self) -> None:
        self.show_help()

    def show_help(self) -> QtWidgets.QMessageBox:
        """3D view > Mouse and keys: how to turn the view and move the balls."""
        box = QtWidgets.QMessageBox(
            QtWidgets.QMessageBox.Information,
            "The 3D view",
            view3d_help_text(PRESET_KEYS),
            parent=self.win,
        )
        box.setObjectName("help3d")
        box.open()
        self.help_box = box
        return box

    def _menu_action(self, shown: bool) -> None:
        a = self.menu.menuAction()
        if a is not None:
            a.setVisible(shown)

    def _set_layer(self, layer: str, on: bool) -> None:
        if self.model is not None:
            self.model.set_layer(layer, bool(on))

    def _set_estimators(self, names: list[str]) -> None:
        """The Estimators dock: the scene's ``[predictions] estimators`` (one undo step)."""
        if self.model is not None and names != self.model.scene.estimators:
            after = self.model.scene.copy()
            after.estimators = list(names)
            self.model.commit(after, "Choose estimators")

    # --- swapping ------------------------------------------------------------------------
    def check(self, scene: Scene) -> bool:
        """Whether the view can hold ``scene`` (else a one-line dialog; nothing changes)."""
        from eyeviz import EyevizError

        try:
            check_estimators(scene)  # a name no estimator has: one line, not the defaults
            check_drawable_eyes(scene, "app")  # nside, balls, lit facets: before allocating
            m3.checked_state(scene)
        except EyevizError as exc:
            self.win.show_error("Cannot open scene", str(exc))
            return False
        return True

    def open(self, scene: Scene) -> None:
        """Show ``scene`` (spherical) in the 3D page, swapping the planar page out."""
        if self.view is None:
            self._build()
        assert self.view is not None
        self.model = m3.AppModel3D(scene)
        self.model.push = self._push
        self.model.listeners.append(self._on_model)
        if not self.active:
            self._swap(True)
        self._on_model("scene", None)
        self.set_preset("default")
        QtCore.QTimer.singleShot(0, self.fit_docks)

    def leave(self) -> None:
        """Back to the planar page (a planar scene was opened)."""
        if self.active:
            self._end_drag()
            self._swap(False)
        self.model = None

    def _planar_widgets(self) -> list[QtWidgets.QWidget]:
        out: list[QtWidgets.QWidget] = [self.win.plotter, self.win.bitmaps]
        for d in self.win.findChildren(QtWidgets.QDockWidget):
            if d not in self.docks.values():
                out.append(d)
        return out

    def _swap(self, to3d: bool) -> None:
        assert self.view is not None
        self.active = to3d
        if to3d:
            # not explicitly hidden (a window not shown yet counts its docks as shown)
            self._hidden = [w for w in self._planar_widgets() if not w.isHidden()]
            for w in self._planar_widgets():
                w.hide()
            self.view.show()
            for d in self.docks.values():
                d.show()
            self.docks["readout3d"].raise_()
            self.view.setFocus()
        else:
            self.view.hide()
            for d in self.docks.values():
                d.hide()
            for w in self._hidden:
                w.show()
            self._hidden = []
        self._menu_action(to3d)
        self.win.cursor_label.setVisible(not to3d)  # the planar view's x, y: room for the status
        for a in self.preset_actions.values():
            a.setEnabled(to3d)
        for a in self.win.findChildren(QtWidgets.QAction):
            if a.text().replace("&", "") in PLANAR_ONLY:
                a.setEnabled(not to3d)

    # --- model -> view -------------------------------------------------------------------
    def _push(self, before: Scene, after: Scene, text: str, merge_key=None) -> None:
        assert self.model is not None
        at = self._press_cam if self._drag is not None else None  # a drag: the view too
        cams = (self.camera, self.set_camera)
        self.win.undo_stack.push(command3d(self.model, before, after, text, merge_key, cams, at))

    def _on_model(self, what: str, index: int | None) -> None:
        if what == "feature":  # a live move: one frame pending at most
            self._dirty = True
            if not self._frame_timer.isActive():
                self._frame_timer.start()
            return
        self._dirty = True
        presenter = getattr(self.win, "presenter", None)
        if presenter is not None and self.active:  # new labels at the text scale (issue 24)
            self.flush()
            presenter.rescale_view()
        self.draw()
        self.refresh_panels()
        if what == "scene" and self.model is not None:
            kind = self.model.scene.eyes.kind
            for name, a in self.layer_actions.items():
                a.setChecked(self.model.scene.shows(name))
                a.setVisible(layer_applies(name, kind))  # cones: measured eyes only
            QtCore.QTimer.singleShot(0, self.fit_docks)

    def flush(self) -> None:
        """Bring the actors up to the model (no render)."""
        if self._dirty and self.model is not None and self.actors is not None:
            self._dirty = False
            self.actors.update(self.model.scene, self.model.state, self.model.selected)
            self._predictions()
            if not self._panel_timer.isActive():
                self._panel_frames += 1
                if self._panel_frames >= PANEL_FRAMES:
                    self._panel_frames = 0
                    self._panel_timer.start()

    def draw(self) -> None:
        """Update and render now (a view not shown yet is only updated: its first paint
        renders; the window's start rendered three frames nobody saw, issue 32.14)."""
        if self.view is None or not self.active:
            return
        self.flush()
        if self.view.isVisible():
            self.view.draw()

    def fit_docks(self) -> None:
        """Widen the readout's dock column to its tables' natural width (both whole: no
        horizontal scroll bar, nothing elided but long names), at most DOCK_FRACTION of the
        window; never narrowed (the user's width is kept when it is wider)."""
        if self.readout is None or not self.active:
            return
        d = self.docks["readout3d"]
        want = min(self.readout.natural_width() + 8, int(DOCK_FRACTION * self.win.width()))
        if d.isVisible() and d.width() < want:
            self.win.resizeDocks([d], [want], QtCore.Qt.Orientation.Horizontal)

    def refresh_panels(self) -> None:
        self._panel_timer.stop()
        m = self.model
        if m is None or not self.active:
            return
        t0 = time.perf_counter()
        st = m.state
        if self.bitmaps is not None:
            self.bitmaps.set_state(st, m.scene, m.selected)  # the selected ball outlined
        if self.readout is not None:
            self.readout.set_state(st, m.scene, m.selected)
            self.readout.set_predictions(self.preds, m.scene)
        if self.estimators is not None:
            self.estimators.refresh(m.scene, self.preds)
        self.show_status()
        # the next refresh during a drag waits PANEL_MS, or longer after a slow one
        took = 1e3 * (time.perf_counter() - t0)
        self._panel_timer.setInterval(max(PANEL_MS, int(took * (1.0 - PANEL_SHARE) / PANEL_SHARE)))

    def show_status(self) -> None:
        """The selected ball in the status bar (:class:`eyeviz.app.status3d.StatusLine`)."""
        self.status_line.show()

    def _sync_eyes(self) -> None:
        if self.actors is not None and self.model is not None:
            self.actors.sync_eyes_camera()
            self.side.update(self.camera())

    # --- camera --------------------------------------------------------------------------
    def _layout(self) -> None:
        if self.view is None or self.actors is None:
            return
        w, h = max(self.view.width(), 1), max(self.view.height(), 1)
        assert self.actors.eyes_ren is not None
        layout(self.actors.scene_ren, self.actors.eyes_ren, w, h)

    def camera(self) -> Camera3D:
        """The scene camera as shown now."""
        assert self.actors is not None
        return camera_of(self.actors.scene_ren)

    def set_camera(self, cam: Camera3D) -> None:
        assert self.actors is not None
        self._layout()
        self.actors.set_cameras(cam)
        self.draw()

    def set_preset(self, name: str, keep: bool = False) -> None:
        """View > 3D view: a camera preset (eyeviz.model.camera3d.preset) framing the balls
        shown now, or (``keep``: a resize) those it framed last (an edit never re-frames)."""
        if self.model is None or name not in PRESETS:
            return
        self.flush()
        self.preset = name
        if not keep or self._framed is None:
            self._framed = self.model.state
        vp = self.pointer("move", 0, 0)
        cam = default_camera(self._framed, name, vp.w / max(vp.h, 1.0))
        if self.actors is not None and vp.w > 1 and vp.h > 1:  # the balls' names not cut
            self._layout()  # the viewports as the view's size is now, to measure texts in
            self.side.show_for(cam)  # its words and lines for this camera, to keep clear
            cam = self.actors.frame_preset(cam, (vp.w, vp.h), keep)
        self.set_camera(cam)

    # --- pixels ----------------------------------------------------------------------------
    def pointer(self, kind: str, x: float, y: float) -> m3.Pointer:
        """A widget pixel -> a :class:`Pointer` in the scene viewport's pixels."""
        assert self.view is not None
        w, h = max(self.view.width(), 1), max(self.view.height(), 1)
        _, (x0, _y0, x1, _y1) = split_viewports(w, h)
        return m3.Pointer(kind, x - x0 * w, y, (x1 - x0) * w, float(h))

    def scene_pixel(self, point) -> tuple[float, float]:
        """Widget pixel where a model point is drawn in the scene viewport (tests)."""
        from eyeviz.model.camera3d import project, to_pixels

        assert self.view is not None
        w, h = max(self.view.width(), 1), max(self.view.height(), 1)
        _, (x0, _y0, x1, _y1) = split_viewports(w, h)
        vw = (x1 - x0) * w
        xy, _ = project(self.camera(), point, vw / h)
        c, r = to_pixels(xy, int(round(vw)), h)
        return float(c + x0 * w), float(r)

    # --- events ----------------------------------------------------------------------------
    def eventFilter(self, obj, ev) -> bool:  # noqa: N802 (Qt name)
        if obj is not self.view or self.model is None:
            return False
        t = ev.type()
        E = QtCore.QEvent.Type
        if t == E.MouseButtonPress and ev.button() == QtCore.Qt.MouseButton.LeftButton:
            self.view.setFocus(QtCore.Qt.FocusReason.MouseFocusReason)
            return self._press(ev)
        if t == E.MouseMove and self._drag is not None:
            self._send(self.pointer("move", ev.x(), ev.y()))
            return True
        if t == E.MouseButtonRelease and self._drag is not None:
            self._send(self.pointer("release", ev.x(), ev.y()))
            self._drag = None
            return True
        if t == E.KeyPress:
            return self._key(ev)
        if t == E.Wheel and self.pointer("move", ev.x(), ev.y()).px < 0:
            return True  # over the eyes' close-up: it follows the scene camera, not zoomed
        if t == E.Resize:
            self._resize_timer.start()
        return False

    def _forget_preset(self) -> None:
        self.preset = None

    def _resized(self) -> None:
        if self.active and self.win.width() != self._fit_width:  # a wider window (F11):
            self._fit_width = self.win.width()  # the docks' column may take its share
            QtCore.QTimer.singleShot(0, self.fit_docks)
        if self.active and self.preset is not None:
            self.set_preset(self.preset, keep=True)
        elif self.active and self.actors is not None:
            self._layout()
            self._sync_eyes()
            self.draw()

    def _press(self, ev) -> bool:
        assert self.model is not None
        self._end_drag()
        p = self.pointer("press", ev.x(), ev.y())
        if p.px < 0 or not self.model.scene.shows("features"):
            return False  # the eyes' close-up: VTK turns the camera
        st = self.model.state
        cam = self.camera()
        i = m3.pick_ball(cam, p, st.x, st.y, st.z, st.g)
        if i is None:
            return False  # the background: VTK's camera interaction
        depth = bool(ev.modifiers() & _MOD_DEPTH)
        self._press_cam = cam
        self._drag = m3.drag_ball(self.model, cam, p, i, depth)
        next(self._drag)
        return True

    def _send(self, p: m3.Pointer) -> None:
        assert self._drag is not None
        try:
            self._drag.send(p)
        except StopIteration:
            self._drag = None
        except ValueError as exc:  # a move the view cannot draw: the ball stays
            self.win.statusBar().showMessage(str(exc), 8000)

    def _end_drag(self) -> None:
        if self._drag is not None:
            self._drag.close()
            self._drag = None

    def _key(self, ev) -> bool:
        assert self.model is not None and self.view is not None
        K = QtCore.Qt.Key
        k = ev.key()
        shift = bool(ev.modifiers() & QtCore.Qt.KeyboardModifier.ShiftModifier)
        if k == K.Key_Tab:
            n = len(self.model.scene.features)
            if n:
                cur = self.model.selected
                self.model.select(0 if cur is None else (cur + 1) % n)
                self._dirty = True
                self.draw()
                self.refresh_panels()
            return True
        steps = {
            K.Key_Left: (-1, 0, 0),
            K.Key_Right: (1, 0, 0),
            K.Key_Up: (0, 0, 1) if shift else (0, 1, 0),
            K.Key_Down: (0, 0, -1) if shift else (0, -1, 0),
        }.get(k)
        if steps is None:
            return False
        vp = self.pointer("move", 0, 0)
        from eyeviz import EyevizError

        try:
            m3.nudge(self.model, self.camera(), vp.h, *steps)
        except (EyevizError, ValueError) as exc:  # the ball stays
            self.win.statusBar().showMessage(str(exc), 8000)
        return True

    # --- edits from the window's Edit menu -------------------------------------------------
    def add_ball(self) -> None:
        """Edit > Add: a ball at the camera's focal point, 1/40 of its distance wide."""
        assert self.model is not None
        cam = self.camera()
        d = math.dist(cam.position, cam.focal_point)
        self.model.add_ball(*cam.focal_point, g=max(d / 40.0, 1e-6))

    def duplicate_selected(self) -> None:
        if self.model is not None and self.model.selected is not None:
            self.model.duplicate_ball(self.model.selected)

    def delete_selected(self) -> None:
        if self.model is not None and self.model.selected is not None:
            self.model.delete_ball(self.model.selected)

    # File > Export: the window's export_to (eyeviz.app.export3d.export_work3d's work)

    def scene_or(self, planar: Scene) -> Scene:
        """The scene the window shows: the 3D page's when active, else ``planar``."""
        return self.model.scene if self.active and self.model is not None else planar

    def close(self) -> None:
        self._end_drag()
        self._frame_timer.stop()
        self._panel_timer.stop()
        if self.view is not None:
            self.view.close()
