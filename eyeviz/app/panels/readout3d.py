"""The spherical scene's readout beside the 3D view (issue 22 item 5, docs/spherical.md).

One row per ball: r, azimuth and elevation (degrees; azimuth from +x counter-clockwise
seen from above, forward = 90, docs/conventions.md), g, in the 3D binocular field of view,
visible per eye (Definition 1: at least two facets lit), overlaps per eye and facets lit
per eye. The rows are :func:`eyeviz.render.mpl.figure3d.readout_rows`, the same strings
the exported figure's table shows, so the app and the figure agree. A cell is re-set only
when its text changes; the columns are re-fitted only when the rows change.
"""

from __future__ import annotations

from PyQt5 import QtCore, QtGui, QtWidgets

from eyeviz.model.scene import Scene
from eyeviz.model.state3d import SceneState3D
from eyeviz.render.mpl.figure3d import readout_rows

__all__ = ["COLUMNS", "Readout3DPanel"]

#: (header, tooltip) per column, in readout_rows' order.
COLUMNS = (
    ("ball", "the feature's name"),
    ("r", "distance from the origin (midway between the eye centres)"),
    ("az°", "azimuth: from +x counter-clockwise seen from above; forward = 90"),
    ("el°", "elevation above the plane z = 0"),
    ("g", "the ball's radius"),
    ("BFV", "in the 3D binocular field of view (docs/spherical.md)"),
    ("vis", "visible to eye A, B (Definition 1: at least two facets lit)"),
    ("ovl", "the ball overlaps eye A, B"),
    ("lit A/B", "facets lit on eye A / eye B"),
)


class Readout3DPanel(QtWidgets.QWidget):
    """A compact table, one row per ball (see the module docstring)."""

    def __init__(self, parent: QtWidgets.QWidget | None = None) -> None:
        super().__init__(parent)
        self.rows: list[tuple[str, ...]] = []
        self._colors: list[str] = []
        self.table = QtWidgets.QTableWidget(0, len(COLUMNS))
        self.table.setObjectName("readout3d")
        for j, (name, tip) in enumerate(COLUMNS):
            item = QtWidgets.QTableWidgetItem(name)
            item.setToolTip(tip)
            self.table.setHorizontalHeaderItem(j, item)
        head = self.table.horizontalHeader()
        side = self.table.verticalHeader()
        assert head is not None and side is not None  # a table has both
        side.setVisible(False)
        side.setSectionResizeMode(QtWidgets.QHeaderView.ResizeMode.Fixed)
        side.setDefaultSectionSize(self.fontMetrics().height() + 4)
        head.setHighlightSections(False)
        head.setMinimumSectionSize(24)
        head.setStretchLastSection(True)
        self.table.setEditTriggers(QtWidgets.QAbstractItemView.EditTrigger.NoEditTriggers)
        self.table.setSelectionMode(QtWidgets.QAbstractItemView.SelectionMode.NoSelection)
        self.table.setShowGrid(False)
        self.table.setWordWrap(False)
        self.table.setHorizontalScrollMode(QtWidgets.QAbstractItemView.ScrollMode.ScrollPerPixel)
        self.note = QtWidgets.QLabel("")
        self.note.setWordWrap(True)
        lay = QtWidgets.QVBoxLayout(self)
        lay.setContentsMargins(4, 4, 4, 4)
        lay.addWidget(self.table, 1)
        lay.addWidget(self.note)
        self.setMinimumWidth(200)

    def set_state(self, state: SceneState3D, scene: Scene) -> None:
        """Show ``state``'s values for ``scene``'s balls (the figure's readout rows)."""
        rows = readout_rows(state, scene)
        colors = [f.color for f in scene.features]
        reshaped = len(rows) != len(self.rows)
        if reshaped:
            self.table.setRowCount(len(rows))
        for i, row in enumerate(rows):
            old = self.rows[i] if i < len(self.rows) else None
            for j, text in enumerate(row):
                if old is not None and old[j] == text and not (j == 0 and self._recolor(i, colors)):
                    continue
                item = self.table.item(i, j)
                if item is None:
                    item = QtWidgets.QTableWidgetItem()
                    align = QtCore.Qt.AlignmentFlag.AlignVCenter | (
                        QtCore.Qt.AlignmentFlag.AlignLeft
                        if j == 0
                        else QtCore.Qt.AlignmentFlag.AlignRight
                    )
                    item.setTextAlignment(int(align))
                    self.table.setItem(i, j, item)
                item.setText(text)
                if j == 0:
                    item.setIcon(_swatch(colors[i]))
                    item.setToolTip(scene.features[i].name)
        changed = reshaped or rows != self.rows
        self.rows, self._colors = rows, colors
        if changed:
            self.table.resizeColumnsToContents()
        hidden = [k for k in ("readout",) if not scene.shows(k)]
        self.note.setText("readout layer hidden: overlaps not computed" if hidden else "")
        self.note.setVisible(bool(hidden))

    def _recolor(self, i: int, colors: list[str]) -> bool:
        return i >= len(self._colors) or self._colors[i] != colors[i]

    def text(self, i: int, column: str) -> str:
        """The text shown in row ``i`` under the header ``column``."""
        j = [h for h, _ in COLUMNS].index(column)
        item = self.table.item(i, j)
        return item.text() if item is not None else ""


def _swatch(color: str) -> QtGui.QIcon:
    pix = QtGui.QPixmap(10, 10)
    pix.fill(QtGui.QColor(color))
    return QtGui.QIcon(pix)
