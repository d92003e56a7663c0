"""The eyeviz main window: a 2D top view (VTK's Qt widget, see view.py) plus side panels.

Flow (DESIGN.md §2): a Qt event mutates the Scene through :class:`AppModel` ->
``compute_state`` -> :class:`SceneActors` and the panels redraw from that state. Mouse
events on the view never reach VTK's interactor styles: the window maps pixels to model
coordinates itself (parallel projection, no rotation), feeds drags to the model's
generators and pans/zooms the camera.
"""

from __future__ import annotations

import math
import os
import tempfile
from pathlib import Path

import numpy as np
from PyQt5 import QtCore, QtGui, QtWidgets
from vtkmodules.util.numpy_support import vtk_to_numpy
from vtkmodules.vtkRenderingCore import vtkTextActor, vtkWindowToImageFilter

from eyeviz.app.panels import (
    BitmapPanel,
    EyesPanel,
    FeaturePanel,
    LayersPanel,
    ReadoutPanel,
    design_skips,
)
from eyeviz.app.view import VtkView, fast_renderer
from eyeviz.model.app_model import AppModel, MouseEvent, drag_feature, hit_test
from eyeviz.model.scene import Scene, SceneError, View, load, save
from eyeviz.render.vtk.actors import (
    BACKGROUND,
    INSET_BACKGROUND,
    SceneActors,
    inset_viewport,
    style_text,
)
from eyeviz.render.vtk.overlays import OverlayActors
from eyeviz.resources import scene_path as scene_path_of

__all__ = ["MainWindow", "make_settings", "run_app"]

APP_FONT_PT = 13
RECENT_MAX = 8
CAMERA_DISTANCE = 1000.0
ZOOM_STEP = 1.15
WHEEL_RADIUS_STEP = 1.08
INSET_TEXT_PX = 24.0  # a line of text in the inset
INSET_HIDE_EYE_PX = 40.0  # eyes at least this wide on screen: no magnified inset


def make_settings(path: str | os.PathLike | None = None) -> QtCore.QSettings:
    """Window layout and recent files; ``path`` (or $EYEVIZ_SETTINGS) selects an INI file."""
    path = path or os.environ.get("EYEVIZ_SETTINGS")
    if path:
        return QtCore.QSettings(str(path), QtCore.QSettings.IniFormat)
    return QtCore.QSettings(
        QtCore.QSettings.IniFormat, QtCore.QSettings.UserScope, "eyeviz", "eyeviz"
    )


class SceneCommand(QtWidgets.QUndoCommand):
    """One undo step: the scene before and after (the view is left where the user put it)."""

    def __init__(self, model: AppModel, before: Scene, after: Scene, text: str, merge_key=None):
        super().__init__(text)
        self.model, self.before, self.after, self.merge_key = model, before, after, merge_key

    def _set(self, scene: Scene) -> None:
        s = scene.copy()
        s.view = View(self.model.scene.view.center, self.model.scene.view.width)
        self.model.set_scene(s)

    def redo(self) -> None:
        self._set(self.after)

    def undo(self) -> None:
        self._set(self.before)

    def id(self) -> int:  # noqa: A003 (Qt name)
        return 1 if self.merge_key is not None else -1

    def mergeWith(self, other) -> bool:  # noqa: N802 (Qt name)
        if other.merge_key != self.merge_key:
            return False
        self.after = other.after
        return True


class MainWindow(QtWidgets.QMainWindow):
    def __init__(self, scene: Scene, path: str | os.PathLike | None = None, settings=None):
        super().__init__()
        self.settings = settings if settings is not None else make_settings()
        self.path: Path | None = Path(path) if path else None
        self.model = AppModel(scene)
        self.undo_stack = QtWidgets.QUndoStack(self)
        self.model.push = self._push
        self.last_error: str = ""
        self.error_box: QtWidgets.QMessageBox | None = None
        self._drag = None
        self._drag_which = "main"
        self._wheel_serial = 0
        self.inset_view = View((0.0, 0.0), 1.0)
        self.inset_auto = True

        self._dirty: set[int] = set()  # features changed live, not yet drawn
        self._table_index: int | None = None
        self._table_timer = QtCore.QTimer(self)
        self._table_timer.setSingleShot(True)
        self._table_timer.setInterval(100)
        self._table_timer.timeout.connect(lambda: self.features_panel.refresh(self._table_index))
        self._frame_pending = False
        self.inset_shown = True

        self.plotter = VtkView(self)
        self.plotter.set_background(BACKGROUND)
        self.plotter.before_render = self._flush
        self.ren_win = self.plotter.ren_win
        self.main_ren = self.plotter.renderer
        self.inset_ren = fast_renderer(INSET_BACKGROUND)
        self.inset_ren.InteractiveOff()
        self.ren_win.AddRenderer(self.inset_ren)
        self.actors = SceneActors(self.main_ren, self.inset_ren)
        self.overlays = OverlayActors(self.main_ren)
        self.picker = None  # docks built on first use (issue 6 layers)
        self.trajectory_panel = None
        self._docks: dict[str, QtWidgets.QDockWidget] = {}
        self.title_actor = vtkTextActor()
        style_text(self.title_actor.GetTextProperty(), 24, (0.1, 0.1, 0.1))
        self.title_actor.GetPositionCoordinate().SetCoordinateSystemToNormalizedViewport()
        self.title_actor.SetPosition(0.015, 0.93)
        self.main_ren.AddViewProp(self.title_actor)
        self.plotter.setMouseTracking(True)
        self.plotter.installEventFilter(self)

        self.bitmaps = BitmapPanel(self.model)
        split = QtWidgets.QSplitter(QtCore.Qt.Vertical)
        split.addWidget(self.plotter)
        split.addWidget(self.bitmaps)
        split.setStretchFactor(0, 1)
        split.setStretchFactor(1, 0)
        split.setChildrenCollapsible(False)
        self.setCentralWidget(split)

        self.readout = ReadoutPanel(self.model)
        self.eyes_panel = EyesPanel(self.model)
        self.features_panel = FeaturePanel(self.model)
        self.layers_panel = LayersPanel(self.model)
        d_read = self._dock("Selected feature", self.readout, "readout")
        d_feat = self._dock("Features", self.features_panel, "features")
        d_eyes = self._dock("Eyes", self.eyes_panel, "eyes")
        d_lay = self._dock("Layers", self.layers_panel, "layers")
        self.tabifyDockWidget(d_feat, d_eyes)
        self.tabifyDockWidget(d_eyes, d_lay)
        d_feat.raise_()
        self._docks.update(features=d_feat, readout=d_read)

        self.cursor_label = QtWidgets.QLabel("")
        # a fixed width: a new cursor text must not re-lay out the status bar every move
        fm = self.cursor_label.fontMetrics()
        self.cursor_label.setFixedSize(  # width AND height: a setText never re-lays out
            fm.horizontalAdvance("x -00,000.0   y -00,000.0     r 00,000.0   φ 000.00°  "),
            fm.height() + 4,
        )
        self.cursor_label.setAutoFillBackground(True)  # opaque: repaints only itself
        self.statusBar().addPermanentWidget(self.cursor_label)
        self._build_menus()
        self.model.listeners.append(self._on_model)
        self.undo_stack.cleanChanged.connect(self._clean_changed)
        self.resize(1280, 800)
        self._restore_settings()
        self.fit_inset()
        self._on_model("scene", None)
        self._update_title()

    # --- construction ---------------------------------------------------------------
    def _dock(self, title: str, widget: QtWidgets.QWidget, name: str) -> QtWidgets.QDockWidget:
        d = QtWidgets.QDockWidget(title, self)
        d.setObjectName(f"dock_{name}")
        d.setWidget(widget)
        d.setFeatures(
            QtWidgets.QDockWidget.DockWidgetMovable | QtWidgets.QDockWidget.DockWidgetFloatable
        )
        self.addDockWidget(QtCore.Qt.RightDockWidgetArea, d)
        return d

    def _action(self, menu, text, slot, shortcut=None) -> QtWidgets.QAction:
        a = QtWidgets.QAction(text, self)
        if shortcut is not None:
            a.setShortcut(QtGui.QKeySequence(shortcut))
            a.setShortcutContext(QtCore.Qt.WindowShortcut)
        a.triggered.connect(slot)
        menu.addAction(a)
        self.addAction(a)
        return a

    def _build_menus(self) -> None:
        mb = self.menuBar()
        f = mb.addMenu("&File")
        self._action(f, "&Open…", self.open_dialog, QtGui.QKeySequence.Open)
        self.recent_menu = f.addMenu("Open &recent")
        self._action(f, "&Save", self.save_current, QtGui.QKeySequence.Save)
        self._action(f, "Save &as…", self.save_dialog, QtGui.QKeySequence.SaveAs)
        f.addSeparator()
        self._action(f, "&Export figure…", self.export_dialog, "Ctrl+E")
        f.addSeparator()
        self._action(f, "&Quit", self.close, QtGui.QKeySequence.Quit)
        e = mb.addMenu("&Edit")
        undo = self.undo_stack.createUndoAction(self, "&Undo")
        undo.setShortcut(QtGui.QKeySequence.Undo)
        redo = self.undo_stack.createRedoAction(self, "&Redo")
        redo.setShortcut(QtGui.QKeySequence.Redo)
        for a in (undo, redo):
            e.addAction(a)
            self.addAction(a)
        e.addSeparator()
        self._action(e, "&Add feature at view centre", self.add_at_center, "Ctrl+N")
        self._action(e, "&Duplicate feature", self.duplicate_selected, "Ctrl+D")
        self._action(e, "De&lete feature", self.delete_selected, QtGui.QKeySequence.Delete)
        v = mb.addMenu("&View")
        self._action(v, "&Fit view", self.fit_view, "F")
        self._action(v, "Fit &inset to the eyes", self.fit_inset, "Shift+F")
        v.addSeparator()
        t = v.addMenu("&Trajectory")
        for kind in ("horizontal", "circular", "vertical"):
            t.addAction(kind.capitalize(), lambda k=kind: self.show_trajectory(k))
        self._action(v, "&Play / pause trajectory", self.toggle_play, "Space")
        self._refresh_recent()

    # --- settings -------------------------------------------------------------------
    def _restore_settings(self) -> None:
        geo = self.settings.value("window/geometry")
        if geo is not None:
            self.restoreGeometry(geo)
        st = self.settings.value("window/state")
        if st is not None:
            self.restoreState(st)

    def closeEvent(self, event) -> None:  # noqa: N802 (Qt name)
        self.settings.setValue("window/geometry", self.saveGeometry())
        self.settings.setValue("window/state", self.saveState())
        self.settings.sync()
        self._frame_pending = True  # no frame after close
        self.plotter.close()
        super().closeEvent(event)

    def recent_files(self) -> list[str]:
        v = self.settings.value("recent", [])
        if isinstance(v, str):
            v = [v]
        return [str(p) for p in (v or [])]

    def _add_recent(self, path: Path) -> None:
        p = str(Path(path).resolve())
        rec = [p] + [r for r in self.recent_files() if r != p]
        self.settings.setValue("recent", rec[:RECENT_MAX])
        self.settings.sync()
        self._refresh_recent()

    def _refresh_recent(self) -> None:
        self.recent_menu.clear()
        for p in self.recent_files():
            a = self.recent_menu.addAction(p)
            a.triggered.connect(lambda _c=False, p=p: self.open_path(p))
        self.recent_menu.setEnabled(bool(self.recent_files()))

    # --- files ----------------------------------------------------------------------
    def _clean_changed(self, _clean: bool) -> None:
        try:
            self._update_title()
        except RuntimeError:  # the stack is being destroyed with the window
            pass

    def _update_title(self) -> None:
        name = self.path.name if self.path else "untitled"
        star = "" if self.undo_stack.isClean() else " *"
        self.setWindowTitle(f"eyeviz — {name}{star}")

    def show_error(self, title: str, text: str) -> None:
        """A window-modal, non-blocking dialog (tests can read and close it)."""
        self.last_error = text
        self.statusBar().showMessage(text, 10000)
        box = QtWidgets.QMessageBox(
            QtWidgets.QMessageBox.Critical, title, text, QtWidgets.QMessageBox.Ok, self
        )
        box.open()
        self.error_box = box

    def open_dialog(self) -> None:
        start = str(self.path.parent) if self.path else str(Path.cwd())
        p, _ = QtWidgets.QFileDialog.getOpenFileName(self, "Open scene", start, "Scenes (*.toml)")
        if p:
            self.open_path(p)

    def open_path(self, path) -> bool:
        """Load a scene; an invalid file shows a dialog and the open scene is kept."""
        try:
            scene = load(path)
        except SceneError as exc:
            self.show_error("Cannot open scene", str(exc))
            return False
        self.path = Path(path)
        self.undo_stack.clear()
        self.model.selected = None
        self.model.set_scene(scene)
        self.fit_inset()
        self._add_recent(self.path)
        self._update_title()
        return True

    def save_dialog(self) -> bool:
        start = str(self.path) if self.path else str(Path.cwd() / "scene.toml")
        p, _ = QtWidgets.QFileDialog.getSaveFileName(self, "Save scene", start, "Scenes (*.toml)")
        return self.save_path(p) if p else False

    def save_current(self) -> bool:
        return self.save_path(self.path) if self.path else self.save_dialog()

    def save_path(self, path) -> bool:
        try:
            save(self.model.scene, path)
        except (OSError, SceneError) as exc:
            self.show_error("Cannot save scene", f"{path}: {exc}")
            return False
        self.path = Path(path)
        self.undo_stack.setClean()
        self._add_recent(self.path)
        self._update_title()
        self.statusBar().showMessage(f"saved {path}", 5000)
        return True

    # --- edits ----------------------------------------------------------------------
    def _push(self, before: Scene, after: Scene, text: str, merge_key=None) -> None:
        self.undo_stack.push(SceneCommand(self.model, before, after, text, merge_key))

    def add_at_center(self) -> None:
        self.model.add_feature(*self.model.scene.view.center)

    def duplicate_selected(self) -> None:
        if self.model.selected is not None:
            self.model.duplicate_feature(self.model.selected)

    def delete_selected(self) -> None:
        if self.model.selected is not None:
            self.model.delete_feature(self.model.selected)

    # --- model -> view ---------------------------------------------------------------
    def _on_model(self, what: str, index: int | None) -> None:
        if what == "feature" and index is not None:
            # a live change (drag, animation): update the model only; one frame is
            # pending at most and draws every change made before it runs
            self._dirty.add(index)
            self.request_frame()
            return
        self._dirty.clear()
        self._refresh(what, index)
        self.render()

    def _refresh(self, what: str, index: int | None) -> None:
        scene = self.model.scene
        st = self.model.state
        self.actors.update(scene, st, self.model.selected)
        self._refresh_overlays(scene, st)
        self.title_actor.SetInput(scene.title)
        self.readout.refresh()
        self.bitmaps.setVisible(scene.shows("bitmaps"))
        self.bitmaps.refresh()
        if what == "feature":
            # the table follows a drag at <= 10 Hz (a row repaint per frame costs ~1 ms);
            # the drag's end refreshes it at once
            self._table_index = index
            if not self._table_timer.isActive():
                self._table_timer.start()
        else:
            self._table_timer.stop()
            self.features_panel.refresh()
            self.eyes_panel.refresh()
            self.layers_panel.refresh()
            self._refresh_docks(scene)
            self.apply_cameras()

    def _refresh_overlays(self, scene: Scene, st) -> None:
        preds = self.model.predictions  # {} unless the predictions layer is shown
        colors = {}
        if preds:
            from eyeviz.render.mpl.vector import estimator_colors

            colors = estimator_colors(scene.estimators)
        skip = design_skips(self.model) if preds else set()
        self.overlays.update_predictions(scene, st, preds, colors, skip=skip)
        i = self.model.selected
        sel_color = scene.features[i].color if i is not None and i < st.n else None
        self.overlays.update_ambiguity(scene, self.model.ambiguity, sel_color)
        path = self.trajectory_panel.path if self.trajectory_panel is not None else None
        self.overlays.update_trajectory(scene, path)

    def _refresh_docks(self, scene: Scene) -> None:
        """The predictions and trajectory docks, built the first time they are needed."""
        if scene.shows("predictions"):
            if self.picker is None:
                from eyeviz.app.docks import EstimatorPicker

                self.picker = EstimatorPicker(self.model)
                self._docks["predictions"] = self._dock("Estimators", self.picker, "predictions")
                self.tabifyDockWidget(self._docks["features"], self._docks["predictions"])
            self.picker.refresh()
        if "predictions" in self._docks:
            self._docks["predictions"].setVisible(scene.shows("predictions"))
        if scene.shows("trajectory"):
            self._trajectory_dock().refresh()
            path = self.trajectory_panel.path
            self.overlays.update_trajectory(scene, path)
        if "trajectory" in self._docks:
            self._docks["trajectory"].setVisible(scene.shows("trajectory"))
            if not scene.shows("trajectory") and self.trajectory_panel.timer.isActive():
                self.trajectory_panel.set_playing(False)

    def _trajectory_dock(self):
        if self.trajectory_panel is None:
            from eyeviz.app.docks import TrajectoryPanel

            self.trajectory_panel = TrajectoryPanel(self.model)
            d = self._dock("Trajectory (Figure 14)", self.trajectory_panel, "trajectory")
            self.tabifyDockWidget(self._docks["features"], d)
            self._docks["trajectory"] = d
            QtCore.QTimer.singleShot(0, d.raise_)
        return self.trajectory_panel

    def show_trajectory(self, kind: str) -> None:
        """View > Trajectory: a path of this kind for the selected feature, with its plot."""
        panel = self._trajectory_dock()
        panel.ensure_trajectory(kind)
        if not self.model.scene.shows("trajectory"):
            self.model.set_layer("trajectory", True)
        self._docks["trajectory"].show()
        panel.refresh()

    def toggle_play(self) -> None:
        panel = self._trajectory_dock()
        if not self.model.scene.shows("trajectory"):
            self.show_trajectory("horizontal")
        panel.set_playing(not panel.timer.isActive())

    # --- export ---------------------------------------------------------------------
    def export_dialog(self) -> None:
        from eyeviz.app.docks import ExportDialog

        base = self.path.with_suffix(".png") if self.path else Path.cwd() / "figure.png"
        dlg = ExportDialog(self, str(base))
        if dlg.exec_() == QtWidgets.QDialog.Accepted:
            self.export_to(*dlg.values())

    def export_to(self, path, scale: float = 1.0, transparent: bool = False) -> Path | None:
        """The scene as a figure (eyeviz.render.mpl.export: PNG, SVG, PDF); errors in a dialog."""
        from eyeviz import EyevizError
        from eyeviz.render.mpl.export import export

        preds = None
        if self.model.scene.shows("predictions"):
            preds = self.model.predictions
        try:
            out = export(self.model.scene, path, scale, transparent, predictions=preds)
        except (EyevizError, OSError, ValueError) as exc:
            self.show_error("Cannot export", str(exc))
            return None
        self.statusBar().showMessage(f"exported {out}", 8000)
        return Path(out)

    def _flush(self) -> None:
        """Bring actors and panels up to the model's live changes (before a render)."""
        if self._dirty:
            dirty, self._dirty = self._dirty, set()
            self._refresh("feature", next(iter(dirty)) if len(dirty) == 1 else None)

    def request_frame(self) -> None:
        """Draw once the pending events are handled (moves arriving meanwhile coalesce)."""
        if not self._frame_pending:
            self._frame_pending = True
            QtCore.QTimer.singleShot(0, self._frame)

    def _frame(self) -> None:
        self._frame_pending = False
        self.render()

    def render(self) -> None:
        """Draw now (with any pending live changes)."""
        self.plotter.draw()

    def flush(self) -> None:
        """Apply pending live changes to actors and panels without rendering."""
        self._flush()

    # --- cameras and pixel <-> model --------------------------------------------------
    def _viewport_px(self, which: str) -> tuple[float, float, float, float]:
        """(left, top, width, height) of a renderer in widget pixels (y down)."""
        w, h = max(self.plotter.width(), 1), max(self.plotter.height(), 1)
        if which == "main":
            return 0.0, 0.0, float(w), float(h)
        x0, y0, x1, y1 = inset_viewport(w, h)
        return x0 * w, (1.0 - y1) * h, (x1 - x0) * w, (y1 - y0) * h

    def _view(self, which: str) -> View:
        return self.model.scene.view if which == "main" else self.inset_view

    def units_per_px(self, which: str = "main") -> float:
        return self._view(which).width / self._viewport_px(which)[2]

    def to_model(self, px: float, py: float, which: str | None = None):
        """Widget pixel -> (which renderer, x, y) in model units."""
        if which is None:
            left, top, w, h = self._viewport_px("inset")
            inside = left <= px <= left + w and top <= py <= top + h
            which = "inset" if (self.inset_shown and inside) else "main"
        left, top, w, h = self._viewport_px(which)
        v = self._view(which)
        u = v.width / w
        return which, v.center[0] + (px - left - w / 2) * u, v.center[1] - (py - top - h / 2) * u

    def to_pixel(self, x: float, y: float, which: str = "main") -> tuple[float, float]:
        left, top, w, h = self._viewport_px(which)
        v = self._view(which)
        u = v.width / w
        return left + w / 2 + (x - v.center[0]) / u, top + h / 2 - (y - v.center[1]) / u

    def apply_cameras(self) -> None:
        w, h = max(self.plotter.width(), 1), max(self.plotter.height(), 1)
        self.inset_ren.SetViewport(*inset_viewport(w, h))
        self._update_inset_visibility()
        for which, ren in (("main", self.main_ren), ("inset", self.inset_ren)):
            _, _, w, h = self._viewport_px(which)
            v = self._view(which)
            cam = ren.GetActiveCamera()
            cam.ParallelProjectionOn()
            cx, cy = v.center
            cam.SetFocalPoint(cx, cy, 0.0)
            cam.SetPosition(cx, cy, CAMERA_DISTANCE)
            cam.SetViewUp(0.0, 1.0, 0.0)
            cam.SetParallelScale(v.width * h / w / 2.0)
            cam.SetClippingRange(1.0, 2.0 * CAMERA_DISTANCE)
        e = self.model.scene.eyes
        self.actors.set_zoom(
            1.0 / self.units_per_px("main"), 1.0 / self.units_per_px("inset"), e.l, e.m
        )

    def _update_inset_visibility(self) -> None:
        """The inset magnifies the eyes; where they are already large on screen (or the
        scene has no eyes) it would only duplicate the main view, so it is hidden."""
        e = self.model.scene.eyes
        eye_px = 2.0 * e.l / self.units_per_px("main")
        want = self.model.scene.shows("eyes") and eye_px < INSET_HIDE_EYE_PX
        if want != self.inset_shown or self.inset_ren.GetDraw() != want:
            self.inset_shown = want
            self.inset_ren.SetDraw(want)
            self.actors.set_inset_shown(want)

    def fit_view(self) -> None:
        sc = self.model.scene
        e = sc.eyes
        xs = (
            [-(e.h + e.l), e.h + e.l]
            + [f.x - f.g for f in sc.features]
            + [f.x + f.g for f in sc.features]
        )
        ys = [-e.l, e.l] + [f.y - f.g for f in sc.features] + [f.y + f.g for f in sc.features]
        _, _, w, h = self._viewport_px("main")
        cx, cy = (min(xs) + max(xs)) / 2, (min(ys) + max(ys)) / 2
        width = max(max(xs) - min(xs), (max(ys) - min(ys)) * w / h) * 1.15
        sc.view = View((cx, cy), width)
        self.apply_cameras()
        self.render()

    def fit_inset(self) -> None:
        e = self.model.scene.eyes
        _, _, w, h = self._viewport_px("inset")
        # the eyes with their A/B labels (y from -1.8 l to 1.3 l) above the m/theta/psi line
        u = max(2 * (e.h + e.l) * 1.08 / w, 3.1 * e.l / max(h - 1.6 * INSET_TEXT_PX, 1.0))
        # centre the content in the part of the inset above the text line
        shift = 0.8 * INSET_TEXT_PX * u
        self.inset_view = View((0.0, -0.25 * e.l - shift), u * w)
        self.inset_auto = True
        self.apply_cameras()
        self.render()

    def _resized(self) -> None:
        if self.inset_auto:
            self.fit_inset()
        else:
            self.apply_cameras()
            self.render()

    def _zoom(self, which: str, px: float, py: float, factor: float) -> None:
        _, x, y = self.to_model(px, py, which)
        v = self._view(which)
        self.inset_auto = self.inset_auto and which == "main"
        width = min(max(v.width * factor, 1e-6), 1e9)
        k = width / v.width
        v.center = (x + (v.center[0] - x) * k, y + (v.center[1] - y) * k)
        v.width = width
        self.apply_cameras()
        self.render()

    def _pan(self, which: str, ev: MouseEvent):
        v = self._view(which)
        self.inset_auto = self.inset_auto and which == "main"
        c0, px0, py0 = v.center, ev.px, ev.py
        ev = yield
        while ev.type == "move":
            u = self.units_per_px(which)
            v.center = (c0[0] - (ev.px - px0) * u, c0[1] + (ev.py - py0) * u)
            self.apply_cameras()
            self.request_frame()
            ev = yield

    # --- events ---------------------------------------------------------------------
    def _status(self, which: str, x: float, y: float) -> None:
        r = math.hypot(x, y)
        phi = math.degrees(math.atan2(y, x)) % 360.0
        self.cursor_label.setText(f"x {x:,.1f}   y {y:,.1f}     r {r:,.1f}   φ {phi:.2f}°")

    def eventFilter(self, obj, ev) -> bool:  # noqa: N802 (Qt name)
        if obj is not self.plotter:
            return False
        t = ev.type()
        E = QtCore.QEvent
        if t == E.MouseButtonPress:
            which, x, y = self.to_model(ev.x(), ev.y())
            me = MouseEvent("press", x, y, ev.x(), ev.y())
            self._drag = None
            if ev.button() == QtCore.Qt.LeftButton:
                i, part = (None, None)
                if self.model.scene.shows("features"):
                    i, part = hit_test(
                        self.model.scene, self.model.selected, x, y, self.units_per_px(which)
                    )
                if i is not None:
                    self._drag = drag_feature(self.model, me, i, part)
                else:
                    self._drag = self._pan(which, me)
            elif ev.button() == QtCore.Qt.MiddleButton:
                self._drag = self._pan(which, me)
            if self._drag is not None:
                self._drag_which = which
                next(self._drag)
            return True
        if t == E.MouseMove:
            which, x, y = self.to_model(ev.x(), ev.y(), self._drag_which if self._drag else None)
            self._status(which, x, y)
            if self._drag is not None:
                self._send(MouseEvent("move", x, y, ev.x(), ev.y()))
            return True
        if t == E.MouseButtonRelease:
            if self._drag is not None:
                _, x, y = self.to_model(ev.x(), ev.y(), self._drag_which)
                self._send(MouseEvent("release", x, y, ev.x(), ev.y()))
                self._drag = None
            return True
        if t == E.Wheel:
            self._wheel(ev)
            return True
        if t == E.ContextMenu:
            self._context_menu(ev.pos(), ev.globalPos())
            return True
        if t in (E.MouseButtonDblClick, E.KeyPress, E.KeyRelease):
            return True
        if t == E.Resize:
            QtCore.QTimer.singleShot(0, self._resized)
        return False

    def _send(self, me: MouseEvent) -> None:
        try:
            self._drag.send(me)
        except StopIteration:
            self._drag = None

    def _wheel(self, ev) -> None:
        steps = ev.angleDelta().y() / 120.0
        if steps == 0:
            return
        px, py = ev.pos().x(), ev.pos().y()
        which, x, y = self.to_model(px, py)
        sc = self.model.scene
        i = None
        if sc.shows("features"):
            i, _ = hit_test(sc, self.model.selected, x, y, self.units_per_px(which))
        if i is None:
            self._zoom(which, px, py, ZOOM_STEP ** (-steps))
            return
        after = sc.copy()
        after.features[i].g = sc.features[i].g * WHEEL_RADIUS_STEP**steps
        self.model.select(i)
        self.model.commit(after, f"Resize {sc.features[i].name}", merge_key=("wheel", i))

    def _context_menu(self, pos: QtCore.QPoint, global_pos: QtCore.QPoint) -> QtWidgets.QMenu:
        which, x, y = self.to_model(pos.x(), pos.y())
        sc = self.model.scene
        i, _ = hit_test(sc, self.model.selected, x, y, self.units_per_px(which))
        menu = QtWidgets.QMenu(self)
        menu.addAction(f"Add feature at ({x:,.0f}, {y:,.0f})", lambda: self.model.add_feature(x, y))
        if i is not None:
            name = sc.features[i].name
            menu.addAction(f"Duplicate {name}", lambda: self.model.duplicate_feature(i))
            menu.addAction(f"Delete {name}", lambda: self.model.delete_feature(i))
        menu.popup(global_pos)
        self.context_menu = menu
        return menu

    # --- screenshots ----------------------------------------------------------------
    def grab_image(self) -> QtGui.QImage:
        """The whole window as shown, with the VTK view composited from its framebuffer."""
        QtWidgets.QApplication.processEvents()
        self.apply_cameras()
        self.render()
        w2i = vtkWindowToImageFilter()
        w2i.SetInput(self.ren_win)
        w2i.SetInputBufferTypeToRGB()
        w2i.ReadFrontBufferOff()
        w2i.Update()
        data = w2i.GetOutput()
        vw, vh, _ = data.GetDimensions()
        arr = vtk_to_numpy(data.GetPointData().GetScalars()).reshape(vh, vw, 3)[::-1].copy()
        vtk_img = QtGui.QImage(arr.data, vw, vh, 3 * vw, QtGui.QImage.Format_RGB888).copy()
        img = self.grab().toImage().convertToFormat(QtGui.QImage.Format_RGB888)
        p = QtGui.QPainter(img)
        top_left = self.plotter.mapTo(self, QtCore.QPoint(0, 0))
        p.drawImage(QtCore.QRect(top_left, self.plotter.size()), vtk_img)
        p.end()
        return img

    def save_screenshot(self, path) -> Path:
        path = Path(path)
        img = self.grab_image()
        fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".png", dir=path.parent or ".")
        os.close(fd)
        try:
            if not img.save(tmp, "PNG"):
                raise OSError(f"cannot write {path}")
            umask = os.umask(0)
            os.umask(umask)
            os.chmod(tmp, 0o666 & ~umask)
            os.replace(tmp, path)
        finally:
            if os.path.exists(tmp):
                os.unlink(tmp)
        return path


def qimage_to_array(img: QtGui.QImage) -> np.ndarray:
    img = img.convertToFormat(QtGui.QImage.Format_RGB888)
    w, h = img.width(), img.height()
    ptr = img.constBits()
    ptr.setsize(img.byteCount())
    return (
        np.frombuffer(ptr, np.uint8)
        .reshape(h, img.bytesPerLine())[:, : 3 * w]
        .reshape(h, w, 3)
        .copy()
    )


def make_app() -> QtWidgets.QApplication:
    app = QtWidgets.QApplication.instance()
    if app is None:
        QtWidgets.QApplication.setAttribute(QtCore.Qt.AA_ShareOpenGLContexts)
        app = QtWidgets.QApplication(["eyeviz"])
    font = app.font()
    font.setPointSize(APP_FONT_PT)
    app.setFont(font)
    return app


def run_app(scene_path=None, screenshot=None, settings_path=None) -> int:
    if not os.environ.get("DISPLAY") and not os.environ.get("WAYLAND_DISPLAY"):
        from eyeviz import EyevizError

        raise EyevizError(
            "no display: run under `xvfb-run -a eyeviz app --screenshot OUT.png` "
            "or use scripts/run.sh"
        )
    if scene_path is None:
        scene_path = scene_path_of("default")
    scene = load(scene_path)
    app = make_app()
    win = MainWindow(scene, scene_path, settings=make_settings(settings_path))
    win.show()
    app.processEvents()
    win.fit_inset()
    win.render()
    if screenshot is not None:
        for _ in range(3):
            app.processEvents()
        out = win.save_screenshot(screenshot)
        print(out)
        win.close()
        return 0
    return app.exec_()
