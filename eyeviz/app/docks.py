"""Issue 6 panels: the estimator picker, the trajectory player with its accuracy plot,
and the export dialog. Built only when their layer (or menu entry) is first used, so a
scene without them imports neither matplotlib nor the estimators.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from PyQt5 import QtCore, QtGui, QtWidgets

from eyeviz.app.panels import _Unelide, design_note, set_message, wrap_label
from eyeviz.app.panels.common import estimator_help, follows_text_scale, text_scale
from eyeviz.model.app_model import AppModel
from eyeviz.model.scene import TRAJECTORY_KINDS

if TYPE_CHECKING:
    from matplotlib.legend import Legend
    from matplotlib.lines import Line2D

    from eyeviz.model.frame_parts import TrajectoryPath

__all__ = [
    "EstimatorPicker",
    "ExportDialog",
    "TrajectoryPanel",
    "PLOT_PT",
    "estimator_help",
    "text_scale",
]

PLOT_PT = 10  # the smallest text of the accuracy plot (projector-readable), at text scale 1


PLOT_LW = 1.3  # the accuracy curves' width (thin: the curves' detail shows)
LINE_STYLES = ("-", (0, (5, 2)), (0, (1.5, 1.5)), (0, (6, 2, 1.5, 2)))


class EstimatorPicker(QtWidgets.QWidget):
    """A check box per estimator (several at once); each chosen one gets its colour
    (eyeviz.model.palette: fixed by name, as in exported figures)."""

    def __init__(self, model: AppModel, parent: QtWidgets.QWidget | None = None) -> None:
        super().__init__(parent)
        from eyeviz import estimators

        self.model = model
        self._unelide = _Unelide(self)
        self.installEventFilter(self._unelide)
        lay = QtWidgets.QVBoxLayout(self)
        self.boxes: dict[str, QtWidgets.QCheckBox] = {}
        for name in estimators.available():
            b = QtWidgets.QCheckBox(name)
            b.setToolTip(estimator_help(name))
            b.toggled.connect(lambda on, n=name: self._toggled(n, on))
            lay.addWidget(b)
            self.boxes[name] = b
        self.note = wrap_label(QtWidgets.QLabel(""))
        lay.addWidget(self.note)
        lay.addStretch(1)
        self._filling = False

    def refresh(self) -> None:
        from eyeviz.model.palette import estimator_colors

        chosen = self.model.scene.estimators
        cols = estimator_colors(chosen)
        self._filling = True
        try:
            for name, b in self.boxes.items():
                b.setChecked(name in chosen)
                pix = QtGui.QPixmap(16, 16)
                pix.fill(QtGui.QColor(cols.get(name, "#ffffff")))
                b.setIcon(QtGui.QIcon(pix) if name in chosen else QtGui.QIcon())
        finally:
            self._filling = False
        preds = self.model.predictions
        loading = self.model.loading
        bad = [
            f"{n}: {v}"
            for n, v in preds.items()
            if isinstance(v, str) and not (loading and v == loading)
        ]
        for name, b in self.boxes.items():
            note = design_note(self.model, name) if name in chosen else None
            b.setStyleSheet("color: #8a8a8a;" if note else "")
            b.setToolTip(estimator_help(name) + (f"\n{name}: {note}" if note else ""))
            if note:  # this one line replaces any "cannot answer" of the same estimator
                bad = [t for t in bad if not t.startswith(f"{name}: ")]
                bad.append(f"{name}: {note}")
        if bad:
            set_message(self.note, "\n".join(bad))
            self.note.setStyleSheet("color: #b00020;")
        else:  # loading is no error: one grey line
            set_message(self.note, loading)
            self.note.setStyleSheet("color: #777777;")

    def _toggled(self, name: str, on: bool) -> None:
        if self._filling:
            return
        from eyeviz.model.interactions import toggle_estimator

        toggle_estimator(self.model, name, on)


class TrajectoryPanel(QtWidgets.QWidget):
    """Figure 14: play / pause / speed along a horizontal, circular or vertical path, with
    a live plot of AD and DD accuracy (100 % - APE) along it for the chosen estimators."""

    def __init__(self, model: AppModel, parent: QtWidgets.QWidget | None = None) -> None:
        super().__init__(parent)
        from matplotlib.backends.backend_qt5agg import FigureCanvasQTAgg
        from matplotlib.figure import Figure

        self.model = model
        self._unelide = _Unelide(self)
        self.installEventFilter(self._unelide)
        self.path: TrajectoryPath | None = None
        self.message = ""
        self.timer = QtCore.QTimer(self)
        self.timer.setInterval(40)
        self.timer.timeout.connect(self.step)  # type: ignore[arg-type]  # its result unused

        lay = QtWidgets.QVBoxLayout(self)
        row = QtWidgets.QHBoxLayout()
        self.kind = QtWidgets.QComboBox()
        self.kind.addItems(list(TRAJECTORY_KINDS))
        self.kind.activated.connect(self._kind_chosen)
        self.play_button = QtWidgets.QPushButton("▶ Play")
        self.play_button.setCheckable(True)
        self.play_button.toggled.connect(self.set_playing)
        self.speed = QtWidgets.QSlider(QtCore.Qt.Orientation.Horizontal)
        self.speed.setRange(1, 20)
        self.speed.setValue(4)
        self.speed.setToolTip("points of the path per tick (25 ticks a second)")
        row.addWidget(self.kind)
        row.addWidget(self.play_button)
        row.addWidget(QtWidgets.QLabel("speed"))
        self.speed.setMinimumWidth(60)
        row.addWidget(self.speed, 1)  # one row: the plots keep the height (issue 24)
        lay.addLayout(row)
        self.info = wrap_label(QtWidgets.QLabel(""))
        lay.addWidget(self.info)
        self.fig = Figure(figsize=(4.2, 2.0), dpi=100, layout="constrained")
        self.canvas = FigureCanvasQTAgg(self.fig)
        self.canvas.setMinimumHeight(170)  # the dock's plots fit 1280x720 unscrolled
        lay.addWidget(self.canvas, 1)
        self.ax_ad = self.fig.add_subplot(2, 1, 1)
        self.ax_dd = self.fig.add_subplot(2, 1, 2, sharex=self.ax_ad)
        self.placeholder = self.fig.text(
            0.5, 0.5, "", ha="center", va="center", fontsize=PLOT_PT + 1, color="#555555"
        )
        self.cursors: list[Line2D] = []
        self._key: tuple | None = None
        self.legend: Legend | None = None  # the figure's, above the axes (never on the data)
        self._scale = text_scale()  # the text scale the plot was drawn at

    def changeEvent(self, ev) -> None:  # noqa: N802 (Qt name)
        """Ctrl+= / Ctrl+- / Ctrl+0 (the app font changed): the plot's text follows."""
        super().changeEvent(ev)
        drawn = getattr(self, "_scale", None)  # None: still being built
        if follows_text_scale(ev) and drawn is not None and text_scale() != drawn:
            self._plot()

    # --- model (the player's state lives in eyeviz.model.player) ---------------------
    @property
    def player_pos(self) -> float:
        """Where the player is along the path (eyeviz.model.player)."""
        return self.model.player.pos

    @property
    def feature(self) -> int | None:
        return self.model.player.index()

    def ensure_trajectory(self, kind: str | None = None) -> None:
        """Give the scene a trajectory (from the selected feature's distance and radius)."""
        from eyeviz.model.interactions import set_trajectory

        set_trajectory(self.model, kind)

    def _kind_chosen(self, _index: int) -> None:
        self.ensure_trajectory(self.kind.currentText())

    def refresh(self) -> None:
        """Recompute the path and its accuracy curves when the scene's trajectory, eyes or
        estimators change (not when the animated feature moves)."""
        from eyeviz.model.frame import trajectory_path
        from eyeviz.model.predictor import Predictor

        sc = self.model.scene
        t = sc.trajectory
        key = (
            None if t is None else (t.kind, t.distance, t.g),
            sc.eyes.h,
            sc.eyes.l,
            sc.eyes.m,
            tuple(sc.estimators),
        )
        if key == self._key:
            return
        self._key = key
        self.path = None
        self.message = ""
        if t is None:
            self.message = "no trajectory: choose a path"
        else:
            self.kind.setCurrentText(t.kind)
            if self.model.predictor is None:
                self.model.predictor = Predictor()
            try:
                self.path = trajectory_path(sc.eyes.pair(), t, sc.estimators, self.model.predictor)
            except ValueError as exc:
                self.message = str(exc)
        self.model.player.set_path(self.path)
        self._plot()

    def _plot(self) -> None:
        """The AD and DD accuracy along the path; without a path, a placeholder text and no
        axes (empty 0-1 axes looked like a broken plot). Text at PLOT_PT points or more."""
        from eyeviz.model.palette import estimator_colors

        self._scale = text_scale()
        pt = PLOT_PT * self._scale
        self.placeholder.set_fontsize(pt + self._scale)
        for ax in (self.ax_ad, self.ax_dd):
            ax.clear()
            ax.grid(True, color="#dddddd", lw=0.6)
        if self.legend is not None:
            self.legend.remove()
            self.legend = None
        self.cursors = []
        p = self.path
        notes = [self.message] if self.message else []
        self.placeholder.set_visible(p is None)
        for ax in (self.ax_ad, self.ax_dd):
            ax.set_visible(p is not None)
        if p is None:
            why = self.message or "no trajectory"
            self.placeholder.set_text(
                f"{why}\n\nchoose a path above (or View > Trajectory)\nto see the accuracy along it"
            )
        else:
            cols = estimator_colors(self.model.scene.estimators)
            for j, (name, acc) in enumerate(p.accuracy.items()):
                if isinstance(acc, str):
                    notes.append(f"{name}: {acc}")
                    continue
                # thin lines; equal curves stay apart by their dashes
                ls = LINE_STYLES[j % len(LINE_STYLES)]
                self.ax_ad.plot(p.axis, acc[0], color=cols[name], lw=PLOT_LW, ls=ls, label=name)
                self.ax_dd.plot(p.axis, acc[1], color=cols[name], lw=PLOT_LW, ls=ls, label=name)
            for ax in (self.ax_ad, self.ax_dd):
                self.cursors.append(ax.axvline(p.axis[0], color="#333333", lw=1.2))
            lo = min(
                [
                    np.nanmin(a[k])
                    for a in p.accuracy.values()
                    if not isinstance(a, str)
                    for k in (0, 1)
                ]
                + [90.0]
            )
            self.ax_dd.set_ylim(max(0.0, min(lo, 90.0)) - 2, 101)
            t = self.model.scene.trajectory
            assert t is not None  # p is its path (refresh)
            self.ax_dd.set_xlabel(p.axis_label, fontsize=pt)
            notes.insert(
                0, f"{t.kind} path, distance {t.distance:g}, g = {t.g:g}: {p.n} points in the BFV"
            )
            if any(not isinstance(a, str) for a in p.accuracy.values()):
                # outside the data: one row above both axes (constrained layout makes room)
                handles, labels = self.ax_ad.get_legend_handles_labels()
                self.legend = self.fig.legend(
                    handles,
                    labels,
                    loc="outside upper right",
                    ncol=max(len(labels), 1),
                    fontsize=pt,
                    frameon=False,
                    handlelength=2.2,
                    borderaxespad=0.1,
                )
            self.ax_ad.set_title("AD accuracy (%)", fontsize=pt, loc="left")
            self.ax_dd.set_title("DD accuracy (%)", fontsize=pt, loc="left")
            self.ax_ad.tick_params(labelsize=pt, labelbottom=False)
            self.ax_dd.tick_params(labelsize=pt)
        set_message(self.info, "\n".join(notes))
        self.canvas.draw_idle()

    # --- animation ----------------------------------------------------------------------
    def set_playing(self, on: bool) -> None:
        """Play or pause (the model's player holds the state; this only displays it)."""
        if on:
            self.ensure_trajectory()
            self.refresh()
            self.model.player.speed = float(self.speed.value())
            self.model.player.start()
        else:
            self.model.player.stop()
        self.sync_player()

    def sync_player(self) -> None:
        """Timer, button and message follow the model's player."""
        on = self.model.player.playing
        if on and not self.timer.isActive():
            self.timer.start()
        elif not on and self.timer.isActive():
            self.timer.stop()
        self.play_button.blockSignals(True)
        self.play_button.setChecked(on)
        self.play_button.blockSignals(False)
        self.play_button.setText("❚❚ Pause" if on else "▶ Play")
        if self.model.player.message:
            self.info.setText(self.model.player.message)

    def step(self, points: float | None = None) -> tuple[float, float] | None:
        """Move the animated feature ``points`` along the path (default: the speed);
        returns its new centre. The feature gets the trajectory's radius."""
        if self.path is None:
            self.refresh()
        player = self.model.player
        player.speed = float(self.speed.value())
        xy = player.step(points)
        if xy is None:
            self.sync_player()
            return None
        p, k = self.path, int(player.pos)
        assert p is not None  # the player moves only along this panel's path (set_path)
        for c in self.cursors:
            c.set_xdata([p.axis[k], p.axis[k]])
        self.canvas.draw_idle()
        return xy


@dataclass
class ExportChoice:
    """What File > Export asks for (eyeviz.render.mpl.export.export's arguments)."""

    path: Path
    scale: float = 1.0
    transparent: bool = False
    width: float | str = "single"
    title: bool = True
    table: bool = True
    bitmaps: bool = True


class ExportDialog(QtWidgets.QDialog):
    """File > Export: path (.png, .svg or .pdf), the journal's width (single column
    3.5 in, double column 7.2 in, or inches), the parts to include, PNG scale and a
    transparent background. ``last`` (the window's previous choice) fills the fields."""

    WIDTH_ITEMS = (
        ("single column (3.5 in)", "single"),
        ("double column (7.2 in)", "double"),
        ("other width (inches)", None),
    )
    width_box: QtWidgets.QComboBox

    def __init__(
        self, parent: QtWidgets.QWidget | None, start: str, last: ExportChoice | None = None
    ) -> None:
        super().__init__(parent)
        last = last or ExportChoice(Path(start))
        self.setWindowTitle("Export figure")
        form = QtWidgets.QFormLayout(self)
        self.path = QtWidgets.QLineEdit(start)
        self.path.setMinimumWidth(self.path.fontMetrics().horizontalAdvance("x" * 40))
        browse = QtWidgets.QPushButton("Browse…")
        browse.clicked.connect(self._browse)
        row = QtWidgets.QHBoxLayout()
        row.addWidget(self.path, 1)
        row.addWidget(browse)
        form.addRow("file (.png, .svg, .pdf)", row)
        self.width_box = QtWidgets.QComboBox()
        for text, _ in self.WIDTH_ITEMS:
            self.width_box.addItem(text)
        self.inches = QtWidgets.QDoubleSpinBox()
        self.inches.setRange(3.0, 10.0)  # what eyeviz.render.mpl.vector.resolve_width takes
        self.inches.setSingleStep(0.1)
        self.inches.setDecimals(2)
        self.inches.setSuffix(" in")
        if isinstance(last.width, str):
            self.width_box.setCurrentIndex(0 if last.width == "single" else 1)
            self.inches.setValue(3.5 if last.width == "single" else 7.2)
        else:
            self.width_box.setCurrentIndex(2)
            self.inches.setValue(float(last.width))
        self.width_box.currentIndexChanged.connect(self._width_changed)
        self._width_changed(self.width_box.currentIndex())
        wrow = QtWidgets.QHBoxLayout()
        wrow.addWidget(self.width_box, 1)
        wrow.addWidget(self.inches)
        form.addRow("width", wrow)
        self.parts: dict[str, QtWidgets.QCheckBox] = {}
        prow = QtWidgets.QHBoxLayout()
        for key, text in (("title", "title"), ("table", "table"), ("bitmaps", "bitmaps")):
            box = QtWidgets.QCheckBox(text)
            box.setChecked(bool(getattr(last, key)))
            self.parts[key] = box
            prow.addWidget(box)
        prow.addStretch(1)
        form.addRow("include", prow)
        self.scale = QtWidgets.QDoubleSpinBox()
        self.scale.setRange(0.25, 20.0)
        self.scale.setSingleStep(0.5)
        self.scale.setValue(last.scale)
        self.scale.setToolTip("PNG only: 1 = 300 dpi")
        form.addRow("PNG scale", self.scale)
        self.transparent = QtWidgets.QCheckBox("transparent background")
        self.transparent.setChecked(last.transparent)
        form.addRow(self.transparent)
        buttons = QtWidgets.QDialogButtonBox(
            QtWidgets.QDialogButtonBox.Ok | QtWidgets.QDialogButtonBox.Cancel
        )
        buttons.accepted.connect(self.accept)
        buttons.rejected.connect(self.reject)
        form.addRow(buttons)

    def _width_changed(self, index: int) -> None:
        self.inches.setEnabled(self.WIDTH_ITEMS[index][1] is None)

    def choice(self) -> ExportChoice:
        named = self.WIDTH_ITEMS[self.width_box.currentIndex()][1]
        return ExportChoice(
            Path(self.path.text()),
            float(self.scale.value()),
            self.transparent.isChecked(),
            named if named is not None else float(self.inches.value()),
            **{k: box.isChecked() for k, box in self.parts.items()},
        )

    def _browse(self) -> None:
        p, _ = QtWidgets.QFileDialog.getSaveFileName(
            self, "Export figure", self.path.text(), "Figures (*.png *.svg *.pdf)"
        )
        if p:
            self.path.setText(p)
