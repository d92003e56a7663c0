"""The layers panel: one check box per layer of the layer table that applies to the
planar eyes (its help as the tip); the 3D page lists its layers in View > 3D view."""

from __future__ import annotations

from PyQt5 import QtWidgets

from eyeviz.app.panels.common import _Unelide
from eyeviz.model.app_model import AppModel
from eyeviz.model.layers import LAYERS


class LayersPanel(QtWidgets.QWidget):
    """One check box per layer; toggling is an undoable edit of the scene's layers."""

    def __init__(self, model: AppModel, parent: QtWidgets.QWidget | None = None) -> None:
        super().__init__(parent)
        self.model = model
        self._unelide = _Unelide(self)
        self.installEventFilter(self._unelide)
        grid = QtWidgets.QGridLayout(self)
        self.boxes: dict[str, QtWidgets.QCheckBox] = {}
        kind = model.scene.eyes.kind  # the planar page's scene: the layers its eyes take
        for i, spec in enumerate(s for s in LAYERS if kind in s.kinds):
            name = spec.name
            b = QtWidgets.QCheckBox(name)
            b.setToolTip(spec.help)
            b.toggled.connect(lambda on, n=name: self._toggled(n, on))
            grid.addWidget(b, i // 2, i % 2)
            self.boxes[name] = b
        self._filling = False

    def refresh(self) -> None:
        self._filling = True
        try:
            for name, b in self.boxes.items():
                b.setChecked(name in self.model.scene.layers)
        finally:
            self._filling = False

    def _toggled(self, name: str, on: bool) -> None:
        if not self._filling:
            self.model.set_layer(name, on)
