"""Help > Keyboard shortcuts (F1) and Help > About the model.

The shortcut table is read from the window's own QActions each time it is shown (menu
path, name, keys), so it cannot go stale when an action or its key changes. The keys and
mouse gestures the views handle themselves (no QAction carries them) follow:
:data:`VIEW_KEYS` (the planar view) and :data:`VIEW3D_KEYS` (the 3D view,
:mod:`eyeviz.app.view3d`), the one list that the 3D view's "Mouse and keys" box is also
written from (:func:`view3d_help_text`; its camera presets are that menu's actions, listed
here with the other actions). The model page
is ``docs/model.md``, shipped with the package as ``assets/help/model.md``.
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator
from pathlib import Path

from PyQt5 import QtCore, QtGui, QtWidgets

from eyeviz.resources import assets_dir

__all__ = [
    "HELP_NAME",
    "LAYER3D_TEXT",
    "SPHERICAL_SECTION",
    "VIEW3D_KEYS",
    "VIEW3D_NOTES",
    "VIEW_KEYS",
    "AboutModelDialog",
    "ShortcutsDialog",
    "about_model_text",
    "model_page_path",
    "shortcut_rows",
    "view3d_help_text",
]

#: Keys the view handles itself (no QAction carries them): shown after the actions' rows.
#: 3D view > Show ...: each spherical layer in words (not its file name: "bfv" is jargon)
LAYER3D_TEXT = {
    "eyes": "the eyes",
    "features": "the balls",
    "bfv": "the binocular field",
    "bitmaps": "the facet maps (Mollweide)",
    "readout": "the readout table",
    "labels": "the names",
    "tangents": "the tangent cones",
    "plane": "the plane z = 0",
    "predictions": "the estimators' answers",
    "cones": "the lit facets' acceptance cones",
    "responses": "the lit facets' graded responses",
}
SPHERICAL_SECTION = "The spherical model (3D scenes)"  # docs/model.md's heading
HELP_NAME = "eyeviz_help_name"  # a QAction property: its name in F1 (when its text changes)

VIEW_KEYS = (
    ("View (with the focus)", "Play / pause the trajectory", "Space"),
    ("View", "Move a feature / pan the view", "drag"),
    ("View", "Zoom / resize a feature", "wheel / Shift+wheel"),
)
#: The 3D view's mouse and keys (eyeviz.app.view3d handles them: VTK's trackball camera on
#: the background, Scene3DHost's event filter on the balls and keys), one (what, keys) row
#: each: Help > Keyboard shortcuts lists them and 3D view > Mouse and keys is written from
#: them, so the two cannot differ.
VIEW3D_KEYS = (
    ("Turn the view", "left-drag on the background"),
    ("Pan", "middle-drag, or Shift+left-drag on the background"),
    ("Zoom", "wheel, or right-drag"),
    ("Move the ball in the plane through its centre facing you", "left-drag on a ball"),
    ("Move the ball along the line of sight (up: farther)", "Shift+ or Ctrl+left-drag on a ball"),
    ("Nudge the selected ball across the screen", "arrow keys (view focused)"),
    ("Move the selected ball farther / nearer", "Shift+Up / Shift+Down (view focused)"),
    ("Select the next ball", "Tab (view focused)"),
    ("Zoom the facet maps about the mouse", "wheel over a map (Facets dock)"),
    ("Pan the zoomed facet maps", "left-drag on a map"),
    ("The whole facet maps again", "double click on a map, or Whole map"),
)
#: What the 3D view's box says besides the rows (no keys of their own).
VIEW3D_NOTES = (
    "The eyes' close-up (left) looks from the scene camera's direction.",
    "A drag is one undo step (Ctrl+Z); consecutive nudges of one ball are one too.",
)
VIEW3D_MENU = "3D view"  # the menu column of VIEW3D_KEYS' rows in the shortcut table


def _first_lower(text: str) -> str:
    return text[:1].lower() + text[1:]


def view3d_help_text(presets: Iterable[tuple[str, str, str]] = ()) -> str:
    """3D view > Mouse and keys: one line per :data:`VIEW3D_KEYS` row ("keys: what"), the
    camera presets (``(name, menu text, key)`` as eyeviz.app.view3d.PRESET_KEYS), then
    :data:`VIEW3D_NOTES`."""
    lines = [f"{keys[:1].upper()}{keys[1:]}: {_first_lower(what)}." for what, keys in VIEW3D_KEYS]
    shown = [f"{key} {_first_lower(_plain(text))}" for _name, text, key in presets]
    if shown:
        lines.append(f"Camera presets (3D view menu): {', '.join(shown)}.")
    return "\n".join(lines) + "\n\n" + " ".join(VIEW3D_NOTES)


def _plain(text: str) -> str:
    return text.replace("&&", "\0").replace("&", "").replace("\0", "&")


def _walk(menu: QtWidgets.QMenu, path: str) -> Iterator[tuple[str, QtWidgets.QAction]]:
    for a in menu.actions():
        sub = a.menu()
        if sub is not None:
            yield from _walk(sub, f"{path} > {_plain(a.text())}")
        elif not a.isSeparator():
            yield path, a


def _name(a: QtWidgets.QAction) -> str:
    """The action's name for F1: its HELP_NAME property (an action whose text changes,
    Undo's), else its text."""
    name = a.property(HELP_NAME)
    return name if isinstance(name, str) and name else _plain(a.text())


def _keys(a: QtWidgets.QAction) -> str:
    seqs = [s.toString(QtGui.QKeySequence.NativeText) for s in a.shortcuts()]
    return ", ".join(s for s in seqs if s)


def shortcut_rows(win: QtWidgets.QMainWindow) -> list[tuple[str, str, str]]:
    """(menu, action, keys) for every action of the window's menus that has a key, then
    the window's actions outside any menu, then :data:`VIEW_KEYS` and
    :data:`VIEW3D_KEYS`."""
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
                rows.append((path, _name(a), keys))
    for a in win.actions():
        if id(a) not in seen and _keys(a):
            rows.append(("Window", _name(a), _keys(a)))
    rows.extend(VIEW_KEYS)
    rows.extend((VIEW3D_MENU, what, keys) for what, keys in VIEW3D_KEYS)
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
        hh.setSectionResizeMode(2, QtWidgets.QHeaderView.Stretch)  # the 3D view's mouse rows
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
            min(fm.averageCharWidth() * 110, 1400), min((len(rows) + 4) * (fm.height() + 10), 900)
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

    def show_section(self, heading: str | None) -> None:
        """Scroll to the section ``heading`` (its title's text) at the top; None: the page's
        top (Help > About the model opens at the spherical model in a 3D scene)."""
        bar = self.browser.verticalScrollBar()
        assert bar is not None
        self.browser.moveCursor(QtGui.QTextCursor.MoveOperation.Start)
        bar.setValue(0)
        if heading is None:
            return
        doc = self.browser.document()
        layout = doc.documentLayout() if doc is not None else None
        cur = doc.find(heading) if doc is not None else None
        if cur is not None and layout is not None and not cur.isNull():
            block = layout.blockBoundingRect(cur.block())
            self.browser.setTextCursor(cur)
            bar.setValue(int(block.top()))
