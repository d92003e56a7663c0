"""The feature table: editable name, x, y, g; a selected row selects the feature."""

from __future__ import annotations

from collections.abc import Sequence

from PyQt5 import QtGui, QtWidgets

from eyeviz.app.panels.common import ERROR_STYLE, _Unelide, set_message, wrap_label
from eyeviz.model.app_model import AppModel


class FeaturePanel(QtWidgets.QWidget):
    """The feature list with editable name, x, y, g; selecting a row selects the feature."""

    COLS = ("name", "x", "y", "g")

    def __init__(self, model: AppModel, parent: QtWidgets.QWidget | None = None) -> None:
        super().__init__(parent)
        self.model = model
        self._unelide = _Unelide(self)
        self.installEventFilter(self._unelide)
        lay = QtWidgets.QVBoxLayout(self)
        lay.setContentsMargins(2, 2, 2, 2)
        self.table = QtWidgets.QTableWidget(0, 4)
        self.table.setHorizontalHeaderLabels(list(self.COLS))
        v_head, h_head = self.table.verticalHeader(), self.table.horizontalHeader()
        assert v_head is not None and h_head is not None  # a QTableWidget has both
        v_head.setVisible(False)
        h_head.setSectionResizeMode(QtWidgets.QHeaderView.Stretch)
        self.table.setSelectionBehavior(QtWidgets.QAbstractItemView.SelectRows)
        self.table.setSelectionMode(QtWidgets.QAbstractItemView.SingleSelection)
        lay.addWidget(self.table)
        self.message = wrap_label(QtWidgets.QLabel(""))
        self.message.setStyleSheet(ERROR_STYLE)
        lay.addWidget(self.message)
        self._filling = False
        self.table.itemChanged.connect(self._edited)
        self.table.itemSelectionChanged.connect(self._selected)

    @staticmethod
    def _fmt(v: float) -> str:
        return f"{v:.6g}"

    def refresh(self, index: int | None = None) -> None:
        fs = self.model.scene.features
        self._filling = True
        try:
            rows: Sequence[int]
            if index is not None and self.table.rowCount() == len(fs):
                rows = [index]
            else:
                self.table.setRowCount(len(fs))
                rows = range(len(fs))
            for r in rows:
                f = fs[r]
                for c, val in enumerate((f.name, self._fmt(f.x), self._fmt(f.y), self._fmt(f.g))):
                    item = self.table.item(r, c)
                    if item is None:
                        item = QtWidgets.QTableWidgetItem()
                        self.table.setItem(r, c, item)
                    if item.text() != val:
                        item.setText(val)
                name_item = self.table.item(r, 0)
                assert name_item is not None  # made by the loop above
                name_item.setForeground(QtGui.QBrush(QtGui.QColor(f.color)))
                font = name_item.font()
                font.setBold(True)
                name_item.setFont(font)
            sel = self.model.selected
            if sel is not None and sel < len(fs) and self.table.currentRow() != sel:
                self.table.selectRow(sel)
        finally:
            self._filling = False

    def _selected(self) -> None:
        if self._filling:
            return
        rows = {i.row() for i in self.table.selectedIndexes()}
        if len(rows) == 1:
            self.model.select(rows.pop())

    def _edited(self, item: QtWidgets.QTableWidgetItem) -> None:
        if self._filling:
            return
        r, c = item.row(), item.column()
        try:
            self.model.set_feature(r, **{self.COLS[c]: item.text()})
            self.message.setText("")
        except ValueError as exc:
            msg = str(exc)
            if msg.startswith("could not convert"):
                msg = f"{self.COLS[c]} must be a number, got {item.text()!r}"
            set_message(self.message, f"Refused: {msg}")
            self.refresh()
