"""The eyeviz main window, assembled: the 2D top view (VTK's Qt widget, see view.py), the
bitmaps strip and the side panels, kept up to date from the model.

Flow (docs/architecture.md): a Qt event becomes a model call (canvas.py ->
eyeviz.model.interactions) -> the model notifies -> ``compute_state`` ->
:class:`SceneActors` and the panels redraw.
The other jobs live beside it: menus and undo (actions.py), files and unsaved changes
(files.py), the canvas event bridge and cameras (canvas.py), screenshots (screenshot.py),
background work (jobs.py), settings (settings.py), start-up (launch.py) and the side
docks (side_docks.py).
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import TYPE_CHECKING, Any

from PyQt5 import QtCore, QtGui, QtWidgets
from vtkmodules.vtkRenderingCore import vtkTextActor

from eyeviz.app import screenshot as _shot
from eyeviz.app.actions import SceneCommand, build_menus
from eyeviz.app.canvas import CanvasMixin
from eyeviz.app.files import RECENT_MAX, FilesMixin, is_bundled
from eyeviz.app.jobs import Job, JobRunner
from eyeviz.app.launch import APP_FONT_PT, check_display, make_app
from eyeviz.app.panels import (
    BitmapPanel,
    EyesPanel,
    FeaturePanel,
    LayersPanel,
    ReadoutPanel,
    design_skips,
    user_message,
)
from eyeviz.app.presenting import install_presenting
from eyeviz.app.screenshot import qimage_to_array
from eyeviz.app.settings import Settings, make_settings
from eyeviz.app.side_docks import SideDocksMixin
from eyeviz.app.steps import StepsMixin
from eyeviz.app.view import VtkView, fast_renderer
from eyeviz.app.view3d import Scene3DHost
from eyeviz.core import paper
from eyeviz.model.app_model import AppModel
from eyeviz.model.camera import eye_overlaps
from eyeviz.model.scene import Eyes, Scene
from eyeviz.model.state import SceneState
from eyeviz.render.vtk.actors import SceneActors
from eyeviz.render.vtk.overlays import OverlayActors
from eyeviz.render.vtk.style import BACKGROUND, INSET_BACKGROUND, halo, style_text

if TYPE_CHECKING:
    from eyeviz.app.docks import ExportChoice, ExportDialog

__all__ = [
    "APP_FONT_PT",
    "MainWindow",
    "RECENT_MAX",
    "check_display",
    "make_app",
    "make_settings",
    "qimage_to_array",
]


LIVE_PANEL_MS = 50  # the readout and bitmaps panels during a drag or play: <= 20 Hz


class MainWindow(CanvasMixin, StepsMixin, FilesMixin, SideDocksMixin, QtWidgets.QMainWindow):
    # made by build_menus (eyeviz.app.actions)
    undo_action: QtWidgets.QAction
    redo_action: QtWidgets.QAction
    play_action: QtWidgets.QAction

    # long: builds the docks, menus and views in the order Qt wires them; each step is one call
    def __init__(
        self, scene: Scene, path: str | os.PathLike | None = None, settings: Settings | None = None
    ) -> None:
        super().__init__()
        # first: each dock's maximum width is a fraction of this (a default 640 px window
        # capped the side panels at 288 px for good)
        self.resize(1280, 720)
        self.settings = settings if settings is not None else make_settings()
        self._set_path(path)
        # a spherical scene opens in the 3D page; the planar page keeps a planar scene
        planar = Scene(Eyes(scene.eyes.h, scene.eyes.l, paper.M)) if scene.in_space else scene
        self.model = AppModel(planar)
        self.undo_stack = QtWidgets.QUndoStack(self)
        self.model.push = self._push
        self.last_error: str = ""
        self.error_box: QtWidgets.QMessageBox | None = None
        self.unsaved_box: QtWidgets.QMessageBox | None = None
        self._force_close = False
        # the window fitted to the screen's free area again after a resize or once the
        # window manager's frame is known (fit_screen)
        self._fit_margins = (0, 0)
        self._fit_timer = QtCore.QTimer(self)
        self._fit_timer.setSingleShot(True)
        self._fit_timer.setInterval(50)
        self._fit_timer.timeout.connect(self.fit_screen)
        self.jobs = JobRunner(lambda text, ms: self.statusBar().showMessage(text, ms), self)
        self._eyes_key: tuple = (scene.eyes.h, scene.eyes.l)

        self._dirty: set[int] = set()  # features changed live, not yet drawn
        self._table_index: int | None = None
        self._table_timer = QtCore.QTimer(self)
        self._table_timer.setSingleShot(True)
        self._table_timer.setInterval(100)
        self._table_timer.timeout.connect(lambda: self.features_panel.refresh(self._table_index))
        # the readout and bitmaps panels follow a live change (drag, play) at <= 20 Hz: their
        # refresh and repaint cost ~0.5-1 ms of a 7-9 ms drag frame (scripts/bench_app.py);
        # an edit, a selection, the drag's release (its undo step) or flush() refresh them
        # at once
        self._panel_timer = QtCore.QTimer(self)
        self._panel_timer.setSingleShot(True)
        self._panel_timer.setInterval(LIVE_PANEL_MS)
        self._panel_timer.timeout.connect(self._refresh_panels)
        self._frame_pending = False
        self._frame_timer = QtCore.QTimer(self)
        self._frame_timer.setSingleShot(True)
        self._frame_timer.setInterval(0)
        self._frame_timer.timeout.connect(self._frame)
        self.inset_shown = True
        self._export_choice: ExportChoice | None = None  # File > Export's last choice
        self.export_dialog_box: ExportDialog | None = None

        self.plotter = VtkView(self)
        self.plotter.set_background(BACKGROUND)
        self.plotter.before_render = self._before_render
        # Space plays while it has focus
        self.plotter.setFocusPolicy(QtCore.Qt.FocusPolicy.StrongFocus)
        self.ren_win = self.plotter.ren_win
        self.main_ren = self.plotter.renderer
        self.inset_ren = fast_renderer(INSET_BACKGROUND)
        self.inset_ren.InteractiveOff()
        self.ren_win.AddRenderer(self.inset_ren)
        self.actors = SceneActors(self.main_ren, self.inset_ren)
        self.overlays = OverlayActors(self.main_ren, self.inset_ren)
        self.posterior_actors = self.actors.layer("posterior")  # issue 10: the limit's posterior
        self.picker = None  # docks built on first use (issue 6 layers)
        self.trajectory_panel = None
        self._docks: dict[str, QtWidgets.QDockWidget] = {}
        self.title_actor = vtkTextActor()
        style_text(self.title_actor.GetTextProperty(), 24, (0.1, 0.1, 0.1))
        self.title_actor.GetTextProperty().SetVerticalJustificationToTop()
        halo(self.title_actor.GetTextProperty())  # geometry panned under it never crosses it
        self.title_actor.GetPositionCoordinate().SetCoordinateSystemToNormalizedViewport()
        self.main_ren.AddViewProp(self.title_actor)
        self.plotter.setMouseTracking(True)
        self.plotter.installEventFilter(self)

        self.bitmaps = BitmapPanel(self.model)
        split = QtWidgets.QSplitter(QtCore.Qt.Orientation.Vertical)
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
        build_menus(self)
        self.host3d = Scene3DHost(self, split)  # the 3D page (issue 22), built on first use
        self.model.listeners.append(self._on_model)
        install_presenting(self)  # View > Full screen, text scale, steps; Help (after the menus)
        self.model.load_in_background = self._load_estimators
        self.undo_stack.cleanChanged.connect(self._clean_changed)
        self._restore_settings()
        if path is not None and not is_bundled(path):
            self._add_recent(Path(path))  # the file named on the command line too
        self.fit_inset()
        self._on_model("scene", None)
        if scene.in_space and self.host3d.check(scene):
            self.host3d.open(scene)
        self._update_title()

    # --- settings -------------------------------------------------------------------
    def _restore_settings(self) -> None:
        geo = self.settings.value("window/geometry")
        if isinstance(geo, bytes):
            self.restoreGeometry(QtCore.QByteArray(geo))
        st = self.settings.value("window/state")
        if isinstance(st, bytes):
            self.restoreState(QtCore.QByteArray(st))

    def showEvent(self, ev) -> None:  # noqa: N802 (Qt name)
        super().showEvent(ev)
        if not ev.spontaneous():
            QtCore.QTimer.singleShot(0, self.fit_screen)

    def _margins(self) -> tuple[int, int]:
        frame = self.frameGeometry()
        return frame.width() - self.width(), frame.height() - self.height()

    def resizeEvent(self, ev) -> None:  # noqa: N802 (Qt name)
        """A window grown (a lecture step's panels) is fitted to the screen again."""
        super().resizeEvent(ev)
        if self.isVisible():
            self._fit_timer.start()

    def moveEvent(self, ev) -> None:  # noqa: N802 (Qt name)
        """The window manager's frame came after the window was shown (its size was not
        known at the show: a 1280x720 window on a 1280x720 screen kept its status bar 20
        px under the screen's edge in every step of sphere_lecture): fitted again when the
        frame's size changes; a move by the user is left alone."""
        super().moveEvent(ev)
        if self.isVisible() and self._margins() != self._fit_margins:
            self._fit_timer.start()

    def fit_screen(self) -> None:
        """The whole window, its frame too, on the screen's free area: a 1280x720 window on
        a 1280x720 screen had its status bar below the screen's edge (issue 32)."""
        if self.isFullScreen() or self.isMaximized():
            return
        self._fit_margins = self._margins()
        screen = self.screen() or QtWidgets.QApplication.primaryScreen()
        if screen is None:
            return
        free, frame = screen.availableGeometry(), self.frameGeometry()
        dw, dh = frame.width() - self.width(), frame.height() - self.height()
        w, h = min(self.width(), free.width() - dw), min(self.height(), free.height() - dh)
        if (w, h) != (self.width(), self.height()):
            self.resize(max(w, 320), max(h, 240))
        x = min(max(frame.left(), free.left()), free.right() + 1 - (w + dw))
        y = min(max(frame.top(), free.top()), free.bottom() + 1 - (h + dh))
        if (x, y) != (frame.left(), frame.top()):
            self.move(x, y)

    def force_close(self) -> None:
        """Close without asking about unsaved changes (--screenshot, tests)."""
        self._force_close = True
        self.close()

    def closeEvent(self, event) -> None:  # noqa: N802 (Qt name)
        if not self._force_close and not self.maybe_save():
            event.ignore()
            return
        self.model.finish_gestures()
        if self.jobs.busy():
            self.jobs.pool.waitForDone(120000)  # an export in flight finishes its file
        self.host3d.leave()  # the planar page's docks are the layout saved
        self.settings.setValue("window/geometry", bytes(self.saveGeometry()))
        self.settings.setValue("window/state", bytes(self.saveState()))
        self.settings.sync()
        self._frame_pending = True  # no frame after close
        self._frame_timer.stop()
        self._table_timer.stop()  # nor a table refresh (it fired into a closed window)
        self._fit_timer.stop()
        self._panel_timer.stop()
        self.host3d.close()
        self.plotter.close()
        super().closeEvent(event)

    # --- edits ----------------------------------------------------------------------
    def _push(self, before: Scene, after: Scene, text: str, merge_key: object = None) -> None:
        self.undo_stack.push(SceneCommand(self.model, before, after, text, merge_key))

    def add_at_center(self) -> None:
        if self.host3d.active:
            return self.host3d.add_ball()
        self.model.add_feature(*self.model.scene.view.center)

    def duplicate_selected(self) -> None:
        if self.host3d.active:
            return self.host3d.duplicate_selected()
        if self.model.selected is not None:
            self.model.duplicate_feature(self.model.selected)

    def delete_selected(self) -> None:
        if self.host3d.active:
            return self.host3d.delete_selected()
        if self.model.selected is not None:
            self.model.delete_feature(self.model.selected)

    # --- model -> view ---------------------------------------------------------------
    def _on_model(self, what: str, index: int | None) -> None:
        if what == "view":
            self.apply_cameras()
            self.request_frame()
            return
        if what == "player":
            if self.trajectory_panel is not None:
                self.trajectory_panel.sync_player()
            if self.model.player.message:
                self.statusBar().showMessage(self.model.player.message, 8000)
            return
        if what == "feature" and index is not None:
            # a live change (drag, animation): update the model only; one frame is
            # pending at most and draws every change made before it runs
            self._dirty.add(index)
            self.request_frame()
            return
        self._dirty.clear()
        if self.last_error and what == "scene":  # a successful edit clears an old error
            self.last_error = ""
            self.statusBar().clearMessage()
        sc_eyes = self.model.scene.eyes
        # h, l, or which features overlap an eye (the inset shows them whole) changed
        eyes = (sc_eyes.h, sc_eyes.l, tuple(eye_overlaps(sc_eyes, self.model.scene.features)))
        if eyes != self._eyes_key:
            self._eyes_key = eyes
            if self.model.inset_auto:  # h or l changed: the inset shows both eyes again
                self.fit_inset()
        self._refresh(what, index)
        if self.plotter.isVisible():
            self.render()
        # else nothing is on the screen yet: the view's first paint renders (the window's
        # start rendered a frame nobody saw; _refresh brought the actors up to date)

    def _refresh(self, what: str, index: int | None, live: bool = False) -> None:
        scene = self.model.scene
        st = self.model.state
        self.actors.update(scene, st, self.model.selected)
        if what == "feature":  # a feature moved under the inset hides it (and back)
            self._update_inset_visibility(index)
        self._refresh_overlays(scene, st)
        self.title_actor.SetInput(scene.title)
        if live:  # a drag or play frame: the panels at <= 20 Hz (the last change included)
            if not self._panel_timer.isActive():
                self._panel_timer.start()
        else:
            self._panel_timer.stop()
            self._refresh_panels()
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

    def _refresh_panels(self) -> None:
        """The readout and bitmaps panels from the model as it is now."""
        self.readout.refresh()
        self.bitmaps.setVisible(self.model.scene.shows("bitmaps"))
        self.bitmaps.refresh()

    def _refresh_overlays(self, scene: Scene, st: SceneState) -> None:
        preds = self.model.predictions  # {} unless the predictions layer is shown
        skip = design_skips(self.model) if preds else set()
        path = self.trajectory_panel.path if self.trajectory_panel is not None else None
        amb = self.model.ambiguity
        self.overlays.update(scene, st, self.model.selected, preds, amb, path, skip=skip)

    def _load_estimators(self, predictor, names: list[str]) -> None:
        """Load estimators (torch, weights) on a worker thread; the window stays live."""

        def finished(_res=None) -> None:
            self.model.loading = ""
            self.model._notify("predictions")

        self.jobs.start(
            lambda: [predictor.estimator(n) for n in names],
            f"loading estimators {', '.join(names)}…",
            finished,
            lambda exc: finished(),
        )

    # --- export (off the GUI thread) ------------------------------------------------
    def export_dialog(self) -> None:
        """File > Export: the dialog starts from the previous choice (width, parts, scale)."""
        from dataclasses import replace

        from eyeviz.app.docks import ExportDialog

        base = self.path.with_suffix(".png") if self.path else Path.cwd() / "figure.png"
        last = replace(self._export_choice, path=base) if self._export_choice else None
        dlg = ExportDialog(self, str(base), last)
        self.export_dialog_box = dlg  # tests and xdotool reach the open dialog
        if dlg.exec_() == QtWidgets.QDialog.Accepted:
            c = dlg.choice()
            self._export_choice = c
            self.export_to(
                c.path,
                c.scale,
                c.transparent,
                wait=False,
                width=c.width,
                title=c.title,
                table=c.table,
                bitmaps=c.bitmaps,
            )

    def export_to(
        self,
        path: str | os.PathLike,
        scale: float = 1.0,
        transparent: bool = False,
        wait: bool = True,
        *,
        width: float | str = "single",
        title: bool = True,
        table: bool = True,
        bitmaps: bool = True,
    ) -> Job | Path | None:
        """The page's scene as a figure (PNG, SVG, PDF) ``width`` wide (single, double or
        inches) with or without its title, table and bitmaps, written with a busy cursor
        on a worker thread (a 3D PNG, rendered by VTK, on this one); errors in a dialog.
        ``wait``: block until done and return the path (None on error); otherwise return
        the job at once. The planar figure is :func:`eyeviz.render.mpl.export.export`'s,
        the 3D page's :func:`eyeviz.app.export3d.export_work3d`'s: one door for both."""
        from eyeviz import EyevizError

        opts: dict[str, Any] = dict(width=width, title=title, table=table, bitmaps=bitmaps)
        if self.host3d.active:  # a spherical scene: the 3D view's PNG or vector figure
            from eyeviz.app.export3d import export_work3d

            work, here = export_work3d(self.host3d, path, scale, transparent, **opts)
        else:
            work, here = self._export_work(path, scale, transparent, **opts), False
        result: list = []

        def done(out) -> None:
            result.append(Path(out))
            self.statusBar().showMessage(f"exported {out}", 8000)

        def failed(exc) -> None:
            # one line, local paths cut to their file name (an estimator's reason can name
            # a weights file under the user's home)
            if isinstance(exc, (EyevizError, OSError, ValueError)):
                self.show_error("Cannot export", user_message(str(exc), 300))
            else:
                self.show_error("Cannot export", f"unexpected error: {user_message(str(exc))}")

        if here:  # VTK renders on the GUI thread (its OpenGL context is per thread)
            try:
                done(work())
            except Exception as exc:  # noqa: BLE001 (shown in a dialog, as the job's)
                failed(exc)
            return result[0] if result else None
        job = self.jobs.start(work, f"exporting {Path(path).name}…", done, failed)
        if not wait:
            return job
        self.jobs.wait()
        return result[0] if result else None

    def _export_work(self, path, scale, transparent, **opts):
        """The planar page's figure as a job's work: the scene as it is now (the job never
        sees later edits), framed as the window shows it."""
        from eyeviz.render.mpl.export import export
        from eyeviz.render.mpl.layout import ASPECT_RANGE

        scene = self.model.scene.copy()
        vp = self.viewport("main")  # the figure frames what the window shows
        lo, hi = ASPECT_RANGE
        aspect = min(max(vp.height / max(vp.width, 1.0), lo), hi)
        preds = dict(self.model.predictions) if scene.shows("predictions") else None
        return lambda: export(
            scene, path, scale, transparent, predictions=preds, aspect=aspect, **opts
        )

    def _before_render(self) -> None:
        """Before any render of the view (a frame, a paint, a draw): the live changes
        applied, and a frame still pending dropped, as this render draws what it would (a
        paint's render and then the frame's drew the same picture twice)."""
        if self._frame_pending and not self.plotter.closed:
            self._frame_pending = False
            self._frame_timer.stop()
        self._flush()

    def _flush(self) -> None:
        """Bring actors and panels up to the model's live changes (before a render)."""
        if self._dirty:
            dirty, self._dirty = self._dirty, set()
            self._refresh("feature", next(iter(dirty)) if len(dirty) == 1 else None, live=True)

    def request_frame(self) -> None:
        """Draw once the pending events are handled (moves arriving meanwhile coalesce)."""
        if not self._frame_pending:
            self._frame_pending = True
            self._frame_timer.start()  # one timer kept: QTimer.singleShot cost ~25 us a move

    def _frame(self) -> None:
        self._frame_pending = False
        self.render()

    def render(self) -> None:  # type: ignore[override]  # shadows QWidget.render(target)
        """Draw now (with any pending live changes)."""
        self.plotter.draw()

    def flush(self) -> None:
        """Apply pending live changes to actors and panels without rendering."""
        self._flush()
        if self._panel_timer.isActive():  # the panels' coalesced refresh: now
            self._panel_timer.stop()
            self._refresh_panels()

    # --- screenshots ----------------------------------------------------------------
    def grab_image(self) -> QtGui.QImage:
        return _shot.grab_image(self)

    def save_screenshot(self, path: str | os.PathLike) -> Path:
        return _shot.save_screenshot(self, path)
