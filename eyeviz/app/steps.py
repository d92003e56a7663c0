"""Walking a scene's lecture steps (``[[steps]]``, :mod:`eyeviz.model.steps`) in the window.

PageDown shows the next step, PageUp the previous one (a presenter's clicker sends the
same keys), Esc shows the whole scene again. Each step's caption is shown in a bar under
the view. Walking never edits the scene: the whole scene is kept aside and comes back on
leaving, and saving while walking leaves the steps first, so the file gets the whole scene.
An edit made while a step is shown changes that step's picture only.

A spherical scene's steps walk the same way in the 3D view (eyeviz.app.view3d): the
model walked is the page shown (the 3D page's AppModel3D while it is active, else the
planar AppModel), and the caption bar sits under that page's view.

Each step frames what it shows (issue 32): its ``camera`` (a preset or an explicit view),
else the view fitted to the eyes and the step's features; and presentation mode (F5)
keeps the side panels the step names (``panels``) while it hides the others.
"""

from __future__ import annotations

import os
from typing import TYPE_CHECKING

from PyQt5 import QtCore, QtGui, QtWidgets

from eyeviz.app.launch import APP_FONT_PT
from eyeviz.model.steps import Step, apply_step

if TYPE_CHECKING:
    from eyeviz.app.presenting import Presenter
    from eyeviz.model.app_model import AppModel
    from eyeviz.model.app_model3d import AppModel3D
    from eyeviz.model.scene import Scene, View

    _MainWindow = QtWidgets.QMainWindow
else:
    _MainWindow = object  # MainWindow brings QMainWindow

__all__ = ["CAPTION_MARGIN", "CAPTION_PT", "CAPTION_SHARE", "PANEL_DOCKS", "StepsMixin"]

CAPTION_PT = 16  # the caption bar's text at text scale 1
CAPTION_MARGIN = 6
#: The most of the window's height the caption bar takes: a longer caption at a large
#: text scale is set smaller, down to the window's own text size (F11 + F5 + 175 % in
#: 1280 x 720: step 7's six 42 pt lines took 420 px and left the 3D view 165 px)
CAPTION_SHARE = 0.3
#: a step's panel names (eyeviz.model.steps.PANELS) -> the docks' object names, by side
PANEL_DOCKS: dict[str, dict[str, str]] = {
    "planar": {
        "readout": "dock_readout",
        "features": "dock_features",
        "eyes": "dock_eyes",
        "layers": "dock_layers",
        "estimators": "dock_predictions",
        "trajectory": "dock_trajectory",
        "design": "dock_design",
    },
    "spherical": {
        "maps": "dock_bitmaps3d",
        "readout": "dock_readout3d",
        "estimators": "dock_estimators3d",
    },
}


class _WidthWatch(QtCore.QObject):
    """Refits the caption bar when its width changes (a side panel shown or hidden by a
    step or by F5 narrows the view: the wrapped caption needs more lines)."""

    def __init__(self, bar: QtWidgets.QLabel, fit) -> None:
        super().__init__(bar)
        self._fit = fit
        bar.installEventFilter(self)

    def eventFilter(self, obj, ev) -> bool:  # noqa: N802 (Qt name)
        if ev.type() == QtCore.QEvent.Type.Resize and ev.size().width() != ev.oldSize().width():
            QtCore.QTimer.singleShot(0, self._fit)
        return False


class StepsMixin(_MainWindow):
    """Mixed into MainWindow (before FilesMixin: its ``save_path`` leaves the steps)."""

    model: AppModel
    _steps_base: Scene | None = None  # the whole scene while walking
    _steps_shown: Scene | None = None  # the scene a step put in the model
    step_index = -1
    _fitted_view: View | None = None  # CanvasMixin's (the main view as the last fit left it)
    caption_bar: QtWidgets.QLabel | None = None
    leave_steps_action: QtWidgets.QAction | None = None  # View > Steps (eyeviz.app.presenting)
    presenter: Presenter  # set by install_presenting

    if TYPE_CHECKING:  # for mypy only

        def statusBar(self) -> QtWidgets.QStatusBar: ...  # noqa: N802

    # --- state ------------------------------------------------------------------------
    @property
    def walking(self) -> bool:
        return self._steps_base is not None

    def _step_model(self) -> AppModel | AppModel3D:
        """The model of the page shown: the 3D view's while it is active, else the planar."""
        host = getattr(self, "host3d", None)
        if host is not None and host.active and host.model is not None:
            return host.model
        return self.model

    def _host3d_shown(self):  # the 3D page when it is shown, else None
        host = getattr(self, "host3d", None)
        return host if host is not None and host.active and host.model is not None else None

    def step_docks(self) -> set[str]:
        """The object names of the docks the step shown needs (empty when not walking)."""
        if not self.walking or self.step_index < 0:
            return set()
        steps = self._steps()
        if self.step_index >= len(steps):
            return set()
        names = steps[self.step_index].panels or []
        table = PANEL_DOCKS["spherical" if self._host3d_shown() else "planar"]
        return {table[n] for n in names if n in table}

    def _frame_step(self, step: Step | None) -> None:
        """The view framing what ``step`` shows (None: the whole scene)."""
        cam = step.camera if step is not None else None
        host = self._host3d_shown()
        if host is not None:
            if isinstance(cam, dict):
                from eyeviz.model.camera3d import Camera3D

                host.preset = None  # kept as given across resizes
                host.set_camera(
                    Camera3D(
                        tuple(cam["position"]),
                        tuple(cam["focal_point"]),
                        tuple(cam["view_up"]),
                        cam.get("view_angle", 30.0),
                    )
                )
            else:
                host.set_preset("default" if cam in (None, "fit") else cam)
        elif isinstance(cam, dict):
            from eyeviz.model import interactions
            from eyeviz.model.scene import View as PlanarView

            cx, cy = cam["center"]
            interactions.set_view(self.model, "main", PlanarView((cx, cy), cam["width"]))
            self._fitted_view = None  # not fitted: kept as given across resizes
        else:
            self.fit_view()  # CanvasMixin's

    def _steps(self) -> list:
        base = self._steps_base if self._steps_base is not None else self._step_model().scene
        return base.steps

    def _place_caption(self, bar: QtWidgets.QLabel) -> None:
        """The bar right under the view shown (the planar view or the 3D one)."""
        split = self.centralWidget()
        if not isinstance(split, QtWidgets.QSplitter) or split.indexOf(bar) < 0:
            return
        host = getattr(self, "host3d", None)
        view = host.view if host is not None and host.active else None
        at = split.indexOf(view) if view is not None else -1
        at = at if at >= 0 else 0
        if split.indexOf(bar) != at + 1:
            split.insertWidget(at + 1 if split.indexOf(bar) > at else at, bar)
            split.setStretchFactor(split.indexOf(bar), 0)

    def _caption_bar(self) -> QtWidgets.QLabel:
        if self.caption_bar is None:
            bar = QtWidgets.QLabel("")
            bar.setObjectName("step_caption")
            bar.setWordWrap(True)
            bar.setMargin(CAPTION_MARGIN)
            bar.setAlignment(QtCore.Qt.AlignmentFlag.AlignCenter)
            bar.setSizePolicy(QtWidgets.QSizePolicy.Ignored, QtWidgets.QSizePolicy.Maximum)
            presenter = getattr(self, "presenter", None)
            scale = presenter.effective_scale if presenter is not None else 1.0
            f = bar.font()
            f.setPointSizeF(CAPTION_PT * scale)
            f.setBold(True)
            bar.setFont(f)
            bar.setProperty("eyeviz_base_pt", float(CAPTION_PT))  # the text scale's base
            bar.setStyleSheet("background: #1a1a1a; color: #ffffff;")
            _WidthWatch(bar, self.fit_caption)
            split = self.centralWidget()
            if isinstance(split, QtWidgets.QSplitter):
                split.insertWidget(1, bar)  # under the view, above the bitmaps
                split.setStretchFactor(1, 0)
            else:  # a layout this mixin does not know: the status bar's left side
                self.statusBar().addWidget(bar, 1)
            self.caption_bar = bar
        return self.caption_bar

    # --- walking ------------------------------------------------------------------------
    def next_step(self) -> None:
        """PageDown: the next step (the first one when not walking)."""
        self._go(self.step_index + 1 if self.walking else 0)

    def previous_step(self) -> None:
        """PageUp: the step before (stays on the first)."""
        if not self.walking:
            self._go(0)
        else:
            self._go(max(self.step_index - 1, 0))

    def _go(self, i: int) -> None:
        if self.walking and self._steps_shown is not self._step_model().scene:
            self._check_scene()  # another file opened meanwhile: its own steps
        model = self._step_model()
        steps = self._steps()
        if not steps:
            self.statusBar().showMessage("this scene has no steps ([[steps]] in its file)", 6000)
            return
        i = min(i, len(steps) - 1)
        if self._steps_base is None:
            self._steps_base = model.scene.copy()
        self.step_index = i
        shown = apply_step(self._steps_base, steps[i])
        shown.view = model.scene.view  # where the presenter put it
        model.set_scene(shown)
        self._steps_shown = model.scene
        bar = self._caption_bar()
        self._place_caption(bar)
        bar.setText(f"{i + 1} / {len(steps)}   {steps[i].caption}")
        bar.show()
        self.fit_caption()
        if self.leave_steps_action is not None:
            self.leave_steps_action.setEnabled(True)
        self._panels_changed()
        # a resize after this (the caption bar's, the panels') keeps the framing
        self._frame_step(steps[i])

    def _panels_changed(self) -> None:
        presenter = getattr(self, "presenter", None)
        if presenter is not None:
            presenter.step_panels()

    def fit_caption(self) -> None:
        """The caption bar as tall as its wrapped text at the window's width (a splitter
        does not ask a word-wrapped label for its height), at most CAPTION_SHARE of the
        window's height where a smaller font (not below the window's text) lets it."""
        bar = self.caption_bar
        if bar is None or not bar.isVisible():
            return
        presenter = getattr(self, "presenter", None)
        scale = presenter.effective_scale if presenter is not None else 1.0
        pt, floor = CAPTION_PT * scale, APP_FONT_PT * scale
        limit = CAPTION_SHARE * self.height()
        inner = max(bar.width() - 2 * CAPTION_MARGIN - 8, 50)
        flags = int(QtCore.Qt.TextFlag.TextWordWrap) | int(QtCore.Qt.AlignmentFlag.AlignCenter)
        font = QtGui.QFont(bar.font())
        while True:
            font.setPointSizeF(pt)
            fm = QtGui.QFontMetrics(font)
            h = fm.boundingRect(QtCore.QRect(0, 0, inner, 0), flags, bar.text()).height()
            h += 2 * CAPTION_MARGIN + 4
            if h <= limit or pt <= floor:
                break
            pt = max(pt * 0.92, floor)
        if abs(bar.font().pointSizeF() - pt) > 1e-6:
            bar.setFont(font)
        bar.setFixedHeight(h)

    def resizeEvent(self, ev) -> None:  # noqa: N802 (Qt name)
        super().resizeEvent(ev)
        self.fit_caption()

    def _check_scene(self) -> None:
        """A scene with other steps in the model (a file opened while walking) ends the
        walk without bringing the old scene back."""
        base = self._steps_base
        if base is not None and self._step_model().scene.steps != base.steps:
            self._end(restore=False)

    def leave_steps(self) -> None:
        """Esc: the whole scene again, as it was before the first step."""
        self._end(restore=True)

    def _end(self, restore: bool) -> None:
        base = self._steps_base
        self._steps_base = None
        self._steps_shown = None
        self.step_index = -1
        if self.caption_bar is not None:
            self.caption_bar.hide()
        if self.leave_steps_action is not None:
            self.leave_steps_action.setEnabled(False)
        if restore and base is not None:
            model = self._step_model()
            base.view = model.scene.view
            model.set_scene(base)
        self._panels_changed()
        if restore and base is not None:
            self._frame_step(None)

    def save_path(self, path: str | os.PathLike) -> bool:
        """Saving while walking writes the whole scene: the steps are left first."""
        if self.walking:
            self._check_scene()
        if self.walking:
            self.leave_steps()
            self.statusBar().showMessage("left the steps: the whole scene is saved", 6000)
        return super().save_path(path)  # FilesMixin's (after this mixin in the MRO)
