"""The 3D view's Estimators dock (issue 23 item 4): a check box per estimator of the
spherical eyes (:func:`eyeviz.estimators.registry.available` ``("spherical")``), each with
its fixed colour (:func:`eyeviz.model.predictions3d.estimator_color3d`), as the planar
window's picker: a tab beside the readout, greyed until the predictions layer is on. The
choice is the scene's ``[predictions] estimators`` (the planar key); at least one stays
ticked (a scene file showing predictions must name one). An estimator that cannot answer
for the scene's eyes (learned3d's weights are for one design) is greyed, with the
registry's one line below.
"""

from __future__ import annotations

from collections.abc import Callable

from PyQt5 import QtGui, QtWidgets

from eyeviz.app.panels.common import estimator_help, user_message, wrap_label
from eyeviz.model.predictions3d import Predictions3D, estimator_color3d, estimators3d
from eyeviz.model.scene import Scene

__all__ = ["Estimators3DPanel"]


class Estimators3DPanel(QtWidgets.QWidget):
    """Check boxes; ``choose(names)`` is called with the new choice."""

    def __init__(
        self, choose: Callable[[list[str]], None], parent: QtWidgets.QWidget | None = None
    ) -> None:
        super().__init__(parent)
        from eyeviz.estimators import registry

        self.choose = choose
        self.names = registry.available("spherical")
        lay = QtWidgets.QVBoxLayout(self)
        self.boxes: dict[str, QtWidgets.QCheckBox] = {}
        for name in self.names:
            b = QtWidgets.QCheckBox(name)
            b.setToolTip(estimator_help(name))
            b.toggled.connect(lambda on, n=name: self._toggled(n, on))
            lay.addWidget(b)
            self.boxes[name] = b
        self.note = wrap_label(QtWidgets.QLabel(""))
        self.note.setStyleSheet("color: #b00020;")
        lay.addWidget(self.note)
        lay.addStretch(1)
        self._filling = False
        self.chosen: list[str] = []

    def refresh(self, scene: Scene, preds: Predictions3D | None) -> None:
        """Tick the scene's estimators; grey the panel unless the layer is on."""
        on = scene.shows("predictions")
        self.setEnabled(on)
        self.setToolTip("" if on else "tick 3D view > Show predictions to use these")
        self.chosen = estimators3d(scene, self.names)
        self._filling = True
        try:
            for name, b in self.boxes.items():
                b.setChecked(name in self.chosen)
                pix = QtGui.QPixmap(16, 16)
                pix.fill(QtGui.QColor(estimator_color3d(name)))
                b.setIcon(QtGui.QIcon(pix))
        finally:
            self._filling = False
        bad = []
        for name, b in self.boxes.items():
            a = preds.answers.get(name) if preds is not None else None
            unavailable = isinstance(a, str) and a.startswith("unavailable")
            b.setStyleSheet("color: #8a8a8a;" if unavailable else "")
            if unavailable:
                bad.append(user_message(f"{name}: {a}", 200))
        self.note.setText("\n".join(bad))
        self.note.setVisible(bool(bad))

    def _toggled(self, name: str, on: bool) -> None:
        if self._filling:
            return
        names = [n for n in self.chosen if n != name]
        if on:
            names = [n for n in self.names if n in names or n == name]
        if not names:  # at least one stays chosen
            self._filling = True
            try:
                self.boxes[name].setChecked(True)
            finally:
                self._filling = False
            return
        self.chosen = names
        self.choose(names)
