"""Help > Keyboard shortcuts (F1) and Help > About the model.

The shortcut table is read from the window's own QActions each time it is shown (menu
path, name, keys), so it cannot go stale when an action or its key changes. The model page
is ``docs/model.md``, shipped with the package as ``assets/help/model.md``.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

from PyQt5 import QtCore, QtGui, QtWidgets

from eyeviz.resources import assets_dir

__all__ = [
    "VIEW_KEYS",
    "AboutModelDialog",
    "ShortcutsDialog",
    "about_model_text",
    "model_page_path",
    "shortcut_rows",
]

#: Keys the view handles itself (no QAction carries them): shown after the actions' rows.
VIEW_KEYS = (
    ("View (with the focus)", "Play / pause the trajectory", "Space"),
    ("View", "Move a feature / pan the view", "drag"),
    ("View", "Zoom / resize a feature", "wheel / Shift+wheel"),
)


def _plain(text: str) -> str:
    return text.replace("&&", "\0").replace("&", "").replace("\0", "&")


def _walk(menu: QtWidgets.QMenu, path: str) -> Iterator[tuple[str, QtWidgets.QAction]]:
    for a in menu.actions():
        sub = a.menu()
        if sub is not None:
            yield from _walk(sub, f"{path} > {_plain(a.text())}")
        elif not a.isSeparator():
            yield path, a


def _keys(a: QtWidgets.QAction) -> str:
    seqs = [s.toString(QtGui.QKeySequence.NativeText) for s in a.shortcuts()]
    return ", ".join(s for s in seqs if s)


def shortcut_rows(win: QtWidgets.QMainWindow) -> list[tuple[str, str, str]]:
    """(menu, action, keys) for every action of the window's menus that has a key, then
    the window's actions outside any menu, then :data:`VIEW_KEYS`."""
    rows: list[tuple[str, str, str]] = []
    seen: set[int] = set()
    mb = win.menuBar()
    assert mb is not None  # a QMainWindow makes its menu bar on first use
    for top in mb.actions():
        menu = top.menu()
        if menu is None:
            continue
        for path, a in _walk(menu, _plain(top.text())):
            seen.add(id(a))
            keys = _keys(a)
            if keys:
                rows.append((path, _plain(a.text()), keys))
    for a in win.actions():
        if id(a) not in seen and _keys(a):
            rows.append(("Window", _plain(a.text()), _keys(a)))
    rows.extend(VIEW_KEYS)
    return rows


class ShortcutsDialog(QtWidgets.QDialog):
    """A table of the window's shortcuts, filled from its actions when shown."""

    def __init__(self, win: QtWidgets.QMainWindow) -> None:
        super().__init__(win)
        self.win = win
        self.setWindowTitle("Keyboard shortcuts")
        lay = QtWidgets.QVBoxLayout(self)
        self.table = QtWidgets.QTableWidget(0, 3)
        self.table.setHorizontalHeaderLabels(["Menu", "Action", "Keys"])
        vh = self.table.verticalHeader()
        assert vh is not None  # a table widget has both headers
        vh.setVisible(False)
        self.table.setEditTriggers(QtWidgets.QAbstractItemView.NoEditTriggers)
        self.table.setSelectionBehavior(QtWidgets.QAbstractItemView.SelectRows)
        hh = self.table.horizontalHeader()
        assert hh is not None
        hh.setSectionResizeMode(0, QtWidgets.QHeaderView.ResizeToContents)
        hh.setSectionResizeMode(1, QtWidgets.QHeaderView.Stretch)
        hh.setSectionResizeMode(2, QtWidgets.QHeaderView.ResizeToContents)
        lay.addWidget(self.table)
        close = QtWidgets.QDialogButtonBox(QtWidgets.QDialogButtonBox.Close)
        close.rejected.connect(self.reject)
        lay.addWidget(close)
        self.refresh()

    def refresh(self) -> None:
        rows = shortcut_rows(self.win)
        self.table.setRowCount(len(rows))
        for i, row in enumerate(rows):
            for j, text in enumerate(row):
                self.table.setItem(i, j, QtWidgets.QTableWidgetItem(text))
        self.table.resizeRowsToContents()
        fm = self.fontMetrics()
        self.resize(
            min(fm.averageCharWidth() * 90, 1400), min((len(rows) + 4) * (fm.height() + 10), 900)
        )

    def rows(self) -> list[tuple[str, ...]]:
        """The table as shown (tests)."""
        t = self.table
        return [
            tuple(t.item(i, j).text() for j in range(t.columnCount()))  # type: ignore[union-attr]
            for i in range(t.rowCount())
        ]


def model_page_path() -> Path:
    """The shipped copy of docs/model.md."""
    return assets_dir() / "help" / "model.md"


def about_model_text() -> str:
    """The model page's Markdown, or a one-line note when the file is missing."""
    try:
        return model_page_path().read_text(encoding="utf-8")
    except OSError:
        return "The model page (docs/model.md) is not installed with this copy of eyeviz."


class AboutModelDialog(QtWidgets.QDialog):
    """Help > About the model: docs/model.md in a scrolling text view."""

    def __init__(self, parent: QtWidgets.QWidget | None = None) -> None:
        super().__init__(parent)
        self.setWindowTitle("About the model")
        lay = QtWidgets.QVBoxLayout(self)
        self.browser = QtWidgets.QTextBrowser()
        self.browser.setOpenExternalLinks(False)
        self.browser.setMarkdown(about_model_text())
        lay.addWidget(self.browser)
        close = QtWidgets.QDialogButtonBox(QtWidgets.QDialogButtonBox.Close)
        close.rejected.connect(self.reject)
        lay.addWidget(close)
        fm = self.fontMetrics()
        self.resize(min(fm.averageCharWidth() * 95, 1400), min(fm.height() * 40, 900))
        self.setWindowModality(QtCore.Qt.WindowModality.NonModal)
