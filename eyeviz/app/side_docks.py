"""The window's side docks: each panel in a scroll area on the right, never wider than
SIDE_MAX_FRACTION of the window, and the docks built on first use (estimator picker,
trajectory player, eye design).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from PyQt5 import QtCore, QtWidgets

from eyeviz.model.scene import Scene

if TYPE_CHECKING:
    from eyeviz.app.design_dock import DesignPanel
    from eyeviz.app.docks import EstimatorPicker, TrajectoryPanel
    from eyeviz.model.app_model import AppModel
    from eyeviz.model.state import SceneState

    _MainWindow = QtWidgets.QMainWindow
else:
    _MainWindow = object  # MainWindow brings QMainWindow

__all__ = ["DOCK_MIN_PX", "SIDE_MAX_FRACTION", "SIDE_MIN_PX", "SIDE_START_PX", "SideDocksMixin"]

SIDE_MAX_FRACTION = 0.45  # the side panels never take more than this of the window width
SIDE_MIN_PX = 260
SIDE_START_PX = 460  # the side panels' first width: the readout's values and all tabs show
DOCK_MIN_PX = 120


class _SideScroll(QtWidgets.QScrollArea):
    """A side panel's scroll area asking for SIDE_START_PX of width: the dock area starts
    wide enough for the readout's values and every tab name (Qt sizes docks by their
    hints; resizeDocks did not hold)."""

    def sizeHint(self) -> QtCore.QSize:  # noqa: N802 (Qt name)
        return QtCore.QSize(SIDE_START_PX, super().sizeHint().height())


class SideDocksMixin(_MainWindow):
    """Mixed into MainWindow: needs ``model``, ``_docks``, ``picker``, ``trajectory_panel``,
    ``_refresh_overlays`` and QMainWindow's dock methods."""

    # MainWindow's (set in its __init__)
    model: AppModel
    _docks: dict[str, QtWidgets.QDockWidget]
    picker: EstimatorPicker | None
    trajectory_panel: TrajectoryPanel | None
    design_panel: DesignPanel  # set by show_design on first use

    if TYPE_CHECKING:  # for mypy only: at run time QMainWindow's and MainWindow's

        def statusBar(self) -> QtWidgets.QStatusBar: ...  # noqa: N802 (never None in a QMainWindow)

        def _refresh_overlays(self, scene: Scene, st: SceneState) -> None: ...

    def _dock(self, title: str, widget: QtWidgets.QWidget, name: str) -> QtWidgets.QDockWidget:
        d = QtWidgets.QDockWidget(title, self)
        d.setObjectName(f"dock_{name}")
        # in a scroll area: a tall panel scrolls instead of making the window taller than a
        # 1280x720 projector (issue 12 item 7)
        scroll = _SideScroll()
        scroll.setWidgetResizable(True)
        scroll.setFrameShape(QtWidgets.QFrame.NoFrame)
        scroll.setHorizontalScrollBarPolicy(QtCore.Qt.ScrollBarPolicy.ScrollBarAlwaysOff)
        scroll.setWidget(widget)
        scroll.setMinimumWidth(min(widget.minimumSizeHint().width(), SIDE_MIN_PX))
        scroll.setMinimumHeight(DOCK_MIN_PX)
        d.setWidget(scroll)
        # closable: View > Panels (eyeviz.app.presenting) brings a closed one back; Qt
        # disables a dock's toggleViewAction unless it is closable
        d.setFeatures(
            QtWidgets.QDockWidget.DockWidgetMovable
            | QtWidgets.QDockWidget.DockWidgetFloatable
            | QtWidgets.QDockWidget.DockWidgetClosable
        )
        self.addDockWidget(QtCore.Qt.DockWidgetArea.RightDockWidgetArea, d)
        self._limit_dock(d)
        return d

    def _limit_dock(self, d: QtWidgets.QDockWidget) -> None:
        """A dock never takes more than SIDE_MAX_FRACTION of the window's width: a long
        message wraps inside it instead of widening the side panel (issue 12 item 7)."""
        d.setMaximumWidth(max(SIDE_MIN_PX, int(self.width() * SIDE_MAX_FRACTION)))

    def fit_readout(self) -> None:
        """Widen the readout's dock column to the width its values need at the current
        text size (F5, Ctrl+=: the planar lecture's step 7 read "yes / yes, in B..."), at
        most SIDE_MAX_FRACTION of the window; never narrowed."""
        d = self._docks.get("readout")
        if d is None or not d.isVisible():
            return
        readout = d.widget()
        inner = readout.widget() if isinstance(readout, QtWidgets.QScrollArea) else None
        natural = getattr(inner, "natural_width", None)
        if natural is None:
            return
        style = self.style()
        bar = style.pixelMetric(style.PixelMetric.PM_ScrollBarExtent) if style else 16
        want = min(natural() + bar + 8, int(SIDE_MAX_FRACTION * self.width()))
        if d.width() < want:
            self.resizeDocks([d], [want], QtCore.Qt.Orientation.Horizontal)

    def resizeEvent(self, ev) -> None:  # noqa: N802 (Qt name)
        for d in self._docks.values():
            self._limit_dock(d)
        super().resizeEvent(ev)

    def _refresh_docks(self, scene: Scene) -> None:
        """The estimators dock, always there (a tab beside the readout, greyed until the
        predictions layer is on: issue 24), and the trajectory dock, built when needed."""
        on = scene.shows("predictions")
        if self.picker is None:
            from eyeviz.app.docks import EstimatorPicker

            self.picker = EstimatorPicker(self.model)
            self._docks["predictions"] = self._dock("Estimators", self.picker, "predictions")
            self.tabifyDockWidget(self._docks["readout"], self._docks["predictions"])
            self._docks["readout"].raise_()
        self.picker.setEnabled(on)
        self.picker.setToolTip("" if on else "tick the predictions layer (Layers) to use these")
        if on:
            self.picker.refresh()
        if scene.shows("trajectory"):
            self._trajectory_dock().refresh()
            self._refresh_overlays(scene, self.model.state)
        if "trajectory" in self._docks:
            self._docks["trajectory"].setVisible(scene.shows("trajectory"))
            if not scene.shows("trajectory") and self.model.player.playing:
                self.model.player.stop()

    def _trajectory_dock(self) -> TrajectoryPanel:
        if self.trajectory_panel is None:
            from eyeviz.app.docks import TrajectoryPanel

            self.trajectory_panel = TrajectoryPanel(self.model)
            d = self._dock("Trajectory", self.trajectory_panel, "trajectory")
            self.tabifyDockWidget(self._docks["features"], d)
            self._docks["trajectory"] = d
            QtCore.QTimer.singleShot(0, d.raise_)
            QtCore.QTimer.singleShot(0, self._fit_trajectory_dock)
        return self.trajectory_panel

    def _fit_trajectory_dock(self) -> None:
        """The trajectory's plots get most of the side column: both fit unscrolled at
        1280x720 (issue 24); the readout keeps the rest."""
        read, d = self._docks["readout"], self._docks["trajectory"]
        tall = read.height() + d.height()
        self.resizeDocks([read, d], [tall * 2 // 5, tall - tall * 2 // 5],
                         QtCore.Qt.Orientation.Vertical)  # fmt: skip

    def show_design(self) -> DesignPanel:
        """View > Eye design: the limit curves of the current eyes and the paper's (issue 11)."""
        if getattr(self, "design_panel", None) is None:
            from eyeviz.app.design_dock import DesignPanel

            self.design_panel = DesignPanel(self.model)
            d = self._dock("Eye design", self.design_panel, "design")
            # beside the Eyes tab (not one of its tabs): both show while h, l, m are typed
            self.tabifyDockWidget(self._docks["readout"], d)
            self._docks["design"] = d
            # the plots get most of the side column, the Eyes tab the rest
            QtCore.QTimer.singleShot(0, self._fit_design_dock)
        self._docks["design"].show()
        self._docks["design"].raise_()
        eyes = self.findChild(QtWidgets.QDockWidget, "dock_eyes")
        if eyes is not None:
            eyes.raise_()
        return self.design_panel

    def _fit_design_dock(self) -> None:
        d, low = self._docks["design"], self._docks["features"]
        tall = d.height() + low.height()
        self.resizeDocks([d, low], [tall * 3 // 5, tall - tall * 3 // 5],
                         QtCore.Qt.Orientation.Vertical)  # fmt: skip

    def show_trajectory(self, kind: str) -> None:
        """View > Trajectory: a path of this kind for the selected feature, with its plot."""
        panel = self._trajectory_dock()
        panel.ensure_trajectory(kind)
        if not self.model.scene.shows("trajectory"):
            self.model.set_layer("trajectory", True)
        self._docks["trajectory"].show()
        panel.refresh()

    def toggle_play(self) -> None:
        """Space (in the view) or P: play / pause the model's trajectory player."""
        panel = self._trajectory_dock()
        if not self.model.scene.shows("trajectory"):
            self.show_trajectory("horizontal")
        panel.set_playing(not self.model.player.playing)
        if not self.model.player.playing and self.model.player.message:
            self.statusBar().showMessage(self.model.player.message, 8000)
