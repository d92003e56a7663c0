"""The spherical scene's readout beside the 3D view (issue 22 item 5, docs/spherical.md).

One row per ball: r, azimuth and elevation (degrees; azimuth from +x counter-clockwise
seen from above, forward = 90, docs/conventions.md), g, in the 3D binocular field of view,
visible per eye (Definition 1: at least two facets lit), overlaps per eye and facets lit
per eye. The rows are :func:`eyeviz.render.mpl.figure3d.readout_rows`, the same strings
the exported figure's table shows, so the app and the figure agree. A cell is re-set only
when its text changes; the columns are re-fitted only when the rows change.

With the predictions layer a second table holds a column per estimator for the layer's
ball, named in its corner (:func:`eyeviz.model.predictions3d.prediction_rows`): r,
azimuth and elevation and their errors against the true ball (r relative, in %; the
angles absolute, in degrees), and a note: the limit's Monte-Carlo error of r, a flag when
an answer is a fallback, or why there is no answer (in full in its tooltip).

The r, azimuth, elevation and g cells can be typed into (double-click, or a key on the
current cell; issue 32.6, :mod:`eyeviz.model.typed3d`): one undo step, or a one-line
"Refused: ..." under the table with nothing changed. A click on a row selects its ball.

Both tables fit the dock's width (no horizontal scroll bar, also at 1280x720): the
columns take their contents' width and the first (the names) the rest, eliding a long
name.

Why not :mod:`eyeviz.app.panels.readout` (issue 37.2 keeps the two): the planar readout
is the selected feature's numbers (r, phi about each eye, Proposition 2's four integers,
the ambiguity region) in labels; this is an editable table of every ball in r, azimuth
and elevation, typed into (a ball has no planar page's drag handle). Merging them would
change what either page shows.
"""

from __future__ import annotations

from collections.abc import Callable

from PyQt5 import QtCore, QtGui, QtWidgets

from eyeviz.app.panels.common import ERROR_STYLE, set_message, user_message, wrap_label
from eyeviz.model.app_model3d import AppModel3D
from eyeviz.model.predictions3d import Predictions3D, estimator_color3d, prediction_rows
from eyeviz.model.scene import Scene
from eyeviz.model.state3d import SceneState3D
from eyeviz.render.mpl.figure3d import readout_rows

__all__ = ["COLUMNS", "PRED_ROWS", "Readout3DPanel", "select_row", "type_into"]

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
TABLE_FONT = 0.8  # the tables' font, times the panel's
CELL_PAD_PX = 7  # a column's width beyond its widest text (Qt's margins take 6; with 9
# the Balls table wanted 534 px at F11 + F5 in 1280 x 720, its names elided in 512)
#: column -> the coordinate typed there (eyeviz.model.typed3d.KEYS)
TYPED = {1: "r", 2: "az", 3: "el", 4: "g"}
NAME_MIN_PX = 40  # the names' column at least (elided)
MIN_ROWS = 4  # the Balls table's rows shown whole at any text size (more scroll)
#: the Balls table's columns never hidden for want of width: ball, r, az°, el°, g
KEEP_COLUMNS = 5
NAME_WANT_PX = 100  # ... and what the dock is widened for (eyeviz.app.view3d)
NOTE_WANT_PX = 130  # an estimator's column with a long reason: what the dock widens for
NOTE_CHARS = 110  # a note below the predictions table at most (the dock keeps its size)
#: The predictions table's rows (one column per estimator): each value with its error.
PRED_ROWS = (
    ("r", "the estimator's distance (in brackets: the relative error of r, %)"),
    ("az°", "the estimator's azimuth (in brackets: its error, degrees)"),
    ("el°", "the estimator's elevation (in brackets: its error, degrees)"),
    ("note", "the limit's Monte-Carlo error of r, a flag (fallback answer), or why none"),
)


def _table(columns) -> QtWidgets.QTableWidget:
    """A compact read-only table that fits its width (see the module docstring)."""
    t = QtWidgets.QTableWidget(0, len(columns))
    for j, (name, tip) in enumerate(columns):
        item = QtWidgets.QTableWidgetItem(name)
        item.setToolTip(tip)
        t.setHorizontalHeaderItem(j, item)
    head = t.horizontalHeader()
    side = t.verticalHeader()
    assert head is not None and side is not None  # a table has both
    side.setVisible(False)
    side.setSectionResizeMode(QtWidgets.QHeaderView.ResizeMode.Fixed)
    side.setDefaultSectionSize(t.fontMetrics().height() + 4)
    head.setHighlightSections(False)
    head.setMinimumSectionSize(18)
    head.setStretchLastSection(False)
    t.setHorizontalScrollBarPolicy(QtCore.Qt.ScrollBarPolicy.ScrollBarAlwaysOff)
    t.setTextElideMode(QtCore.Qt.TextElideMode.ElideRight)
    t.setEditTriggers(QtWidgets.QAbstractItemView.EditTrigger.NoEditTriggers)
    t.setSelectionMode(QtWidgets.QAbstractItemView.SelectionMode.NoSelection)
    t.setShowGrid(False)
    t.setWordWrap(False)
    font = t.font()
    if font.pointSizeF() > 0:  # a notch smaller: nine columns fit a 1280x720 side column
        font.setPointSizeF(font.pointSizeF() * TABLE_FONT)
        t.setFont(font)
    side.setDefaultSectionSize(t.fontMetrics().height() + 4)
    head.setSectionResizeMode(QtWidgets.QHeaderView.ResizeMode.Fixed)
    return t


def _text_widths(t: QtWidgets.QTableWidget) -> list[int]:
    """Each column's widest text (header and cells) plus CELL_PAD_PX."""
    fm = QtGui.QFontMetrics(t.font())
    head = t.horizontalHeader()
    assert head is not None
    hfm = QtGui.QFontMetrics(head.font())
    widths = []
    for j in range(t.columnCount()):
        h_item = t.horizontalHeaderItem(j)
        w = hfm.horizontalAdvance(h_item.text() if h_item is not None else "")
        if h_item is not None and not h_item.icon().isNull():
            w += 20  # the swatch
        for i in range(t.rowCount()):
            item = t.item(i, j)
            if item is not None:
                w = max(w, fm.horizontalAdvance(item.text()))
        widths.append(w + CELL_PAD_PX)
    return widths


def _bar_px(t: QtWidgets.QTableWidget) -> int:
    style = t.style()
    return style.pixelMetric(QtWidgets.QStyle.PixelMetric.PM_ScrollBarExtent) if style else 16


def natural_width(t: QtWidgets.QTableWidget) -> int:
    """The width ``t`` wants: every number whole, names up to NAME_WANT_PX, a long reason
    (an estimator's note) up to NOTE_WANT_PX, a vertical scroll bar's room."""
    w = _text_widths(t)
    if not w:
        return 0
    return (min(w[0], NAME_WANT_PX) + sum(min(v, NOTE_WANT_PX) for v in w[1:])
            + 2 * t.frameWidth() + _bar_px(t))  # fmt: skip


def fit_columns(t: QtWidgets.QTableWidget, keep: int | None = None) -> None:
    """Columns 1... as wide as their header and cells; column 0 (the names, elided) the
    rest of the viewport, at least NAME_MIN_PX: no horizontal scroll bar. ``keep``: where
    the numbers and the names (up to NAME_WANT_PX) do not all fit, the columns past the
    first ``keep`` give way from the last (hidden; named in the table's tooltip: F11 + F5
    + 175 % in 1280 x 720, the Balls table scrolled sideways and cut its names); where
    the numbers alone still do not fit (or without ``keep``) they stay whole and the table
    scrolls sideways."""
    head = t.horizontalHeader()
    assert head is not None
    widths = _text_widths(t)
    bar = _bar_px(t)
    side = t.verticalHeader()
    rows_h = t.rowCount() * (side.defaultSectionSize() if side is not None else 20)
    tall = rows_h + head.height() + 2 * t.frameWidth() > t.height()
    avail = t.width() - 2 * t.frameWidth() - (bar if tall else 0)  # a vertical bar's room
    hidden: list[int] = []
    if keep is not None and widths:
        names = min(widths[0], NAME_WANT_PX)
        last = len(widths) - 1
        while last >= keep and sum(min(v, NOTE_WANT_PX) for v in widths[1 : last + 1]) > (
            avail - names
        ):
            hidden.insert(0, last)
            last -= 1
    for j in range(len(widths)):
        if t.isColumnHidden(j) != (j in hidden):
            t.setColumnHidden(j, j in hidden)
    names_of = [t.horizontalHeaderItem(j) for j in hidden]
    gone = ", ".join(h.text() for h in names_of if h is not None)
    t.setToolTip(f"not shown at this width: {gone} (widen the panel)" if gone else "")
    for j in hidden:
        widths[j] = 0
    room = avail - NAME_MIN_PX
    # the numbers alone wider than the table (175 % in a 1280 x 720 screen: every cell
    # was "..."): they keep their width, a note at most NOTE_WANT_PX; the table scrolls
    # (a long note alone still elides, below)
    shown = [v for j, v in enumerate(widths) if j > 0 and j not in hidden]
    short = [v for v in shown if v <= NOTE_WANT_PX]
    sideways = sum(short) + 24 * (len(shown) - len(short)) > room
    t.setHorizontalScrollBarPolicy(
        QtCore.Qt.ScrollBarPolicy.ScrollBarAsNeeded
        if sideways
        else QtCore.Qt.ScrollBarPolicy.ScrollBarAlwaysOff
    )
    if sideways:
        widths[1:] = [min(v, NOTE_WANT_PX) for v in widths[1:]]
    elif len(shown) and sum(shown) > room:
        # too wide (a long reason): the narrow columns keep their width, the widest share
        # what is left, their text elided (water-filling)
        rest = sorted(
            (j for j in range(1, len(widths)) if j not in hidden), key=lambda j: widths[j]
        )
        while rest:
            fair = max(room // len(rest), 24)
            if widths[rest[0]] > fair:
                for j in rest:
                    widths[j] = fair
                break
            room -= widths[rest.pop(0)]
    widths[0] = max(NAME_MIN_PX, avail - sum(widths[1:]))
    for j, w in enumerate(widths):
        if j not in hidden:
            head.resizeSection(j, int(w))


def _cell(t: QtWidgets.QTableWidget, i: int, j: int) -> QtWidgets.QTableWidgetItem:
    item = t.item(i, j)
    if item is None:
        item = QtWidgets.QTableWidgetItem()
        align = QtCore.Qt.AlignmentFlag.AlignVCenter | (
            QtCore.Qt.AlignmentFlag.AlignLeft if j == 0 else QtCore.Qt.AlignmentFlag.AlignRight
        )
        item.setTextAlignment(int(align))
        F = QtCore.Qt.ItemFlag
        typed = t.objectName() == "readout3d" and j in TYPED
        if not typed:
            item.setFlags(QtCore.Qt.ItemFlags() | F.ItemIsEnabled | F.ItemIsSelectable)
        t.setItem(i, j, item)
    return item


class Readout3DPanel(QtWidgets.QWidget):
    """A compact table, one row per ball (see the module docstring)."""

    def __init__(
        self,
        model: Callable[[], AppModel3D | None] | None = None,
        parent: QtWidgets.QWidget | None = None,
    ) -> None:
        """``model`` (the 3D page's model now) takes the typed values and the row clicks."""
        super().__init__(parent)
        self.rows: list[tuple[str, ...]] = []
        self._colors: list[str] = []
        self.table = _table(COLUMNS)
        self.table.setIconSize(QtCore.QSize(10, 10))  # the 10 px swatch, not 16 px of room
        self.table.setObjectName("readout3d")
        AV = QtWidgets.QAbstractItemView
        trig = AV.EditTrigger
        self.table.setEditTriggers(
            AV.EditTriggers() | trig.DoubleClicked | trig.EditKeyPressed | trig.AnyKeyPressed
        )
        self.table.setSelectionMode(AV.SelectionMode.SingleSelection)
        self.table.setSelectionBehavior(AV.SelectionBehavior.SelectRows)
        #: ``on_type(row, key, text)`` -> None, or the one-line reason it was refused
        self.on_type: Callable[[int, str, str], str | None] | None = None
        #: ``on_select(row)``: a click on a row
        self.on_select: Callable[[int], None] | None = None
        if model is not None:
            self.on_type = lambda i, key, text: type_into(model(), i, key, text)
            self.on_select = lambda i: select_row(model(), i)
        self._filling = False
        self.table.itemChanged.connect(self._typed)
        self.table.cellPressed.connect(self._pressed)
        self.message = wrap_label(QtWidgets.QLabel(""))
        self.message.setStyleSheet(ERROR_STYLE)
        self.message.setVisible(False)
        self._fit_height()
        self.note = QtWidgets.QLabel("")
        self.note.setWordWrap(True)
        lay = QtWidgets.QVBoxLayout(self)
        lay.setContentsMargins(4, 4, 4, 4)
        lay.setSpacing(3)  # with the predictions the dock still fits 1280x720
        lay.addWidget(self.table, 1)
        lay.addWidget(self.message)
        lay.addWidget(self.note)
        self.pred_table = _table((("", ""),))
        self.pred_table.setObjectName("predictions3d")
        self.pred_note = wrap_label(QtWidgets.QLabel(""))
        for w in (self.pred_table, self.pred_note):
            w.setVisible(False)
        lay.addWidget(self.pred_table, 1)
        lay.addWidget(self.pred_note)
        self.pred_rows: list[tuple[str, ...]] = []
        for t in (self.table, self.pred_table):
            t.installEventFilter(self)  # re-fitted whenever a table is resized or shown
        self.setMinimumWidth(200)

    def set_state(self, state: SceneState3D, scene: Scene, selected: int | None = None) -> None:
        """Show ``state``'s values for ``scene``'s balls (the figure's readout rows), the
        ``selected`` ball's row selected."""
        self._filling = True
        try:
            self._fill(state, scene)
            if selected is not None and 0 <= selected < self.table.rowCount():
                if self.table.currentRow() != selected:
                    self.table.selectRow(selected)
            else:
                self.table.clearSelection()
        finally:
            self._filling = False

    def _typed(self, item: QtWidgets.QTableWidgetItem) -> None:
        if self._filling or item.column() not in TYPED or self.on_type is None:
            return
        i, j = item.row(), item.column()
        why = self.on_type(i, TYPED[j], item.text())
        if why is None:
            self.message.setVisible(False)
            return
        set_message(self.message, f"Refused: {why}")
        self.message.setVisible(True)
        self._filling = True
        try:  # the cell shows the value kept
            item.setText(self.rows[i][j] if i < len(self.rows) else "")
        finally:
            self._filling = False

    def _pressed(self, row: int, _col: int) -> None:
        if self.on_select is not None and not self._filling:
            self.on_select(row)

    def _fill(self, state: SceneState3D, scene: Scene) -> None:
        rows = readout_rows(state, scene)
        colors = [f.color for f in scene.features]
        reshaped = len(rows) != len(self.rows)
        if reshaped:
            self.table.setRowCount(len(rows))
            self._fit_height()
        for i, row in enumerate(rows):
            old = self.rows[i] if i < len(self.rows) else None
            for j, text in enumerate(row):
                if old is not None and old[j] == text and not (j == 0 and self._recolor(i, colors)):
                    continue
                item = _cell(self.table, i, j)
                item.setText(text)
                if j == 0:
                    item.setIcon(_swatch(colors[i]))
                    item.setToolTip(scene.features[i].name)
        self.rows, self._colors = rows, colors
        fit_columns(self.table, KEEP_COLUMNS)
        hidden = [k for k in ("readout",) if not scene.shows(k)]
        self.note.setText("readout layer hidden: overlaps not computed" if hidden else "")
        self.note.setVisible(bool(hidden))

    def set_predictions(self, preds: Predictions3D | None, scene: Scene) -> None:
        """The predictions table for ``preds`` (hidden without the layer or a ball)."""
        on = scene.shows("predictions") and preds is not None
        self.pred_table.setVisible(on)
        if not on or preds is None:
            self.pred_note.setVisible(False)
            self.pred_rows = []
            return
        name = scene.features[preds.ball].name if preds.ball < len(scene.features) else ""
        rows = prediction_rows(preds)  # per estimator: name, r, dr, az, daz, el, del, note
        t = self.pred_table
        if t.columnCount() != len(rows) + 1 or t.rowCount() != len(PRED_ROWS):
            t.setColumnCount(len(rows) + 1)
            t.setRowCount(len(PRED_ROWS))
            for i, (label, tip) in enumerate(PRED_ROWS):
                item = _cell(t, i, 0)
                item.setText(label)
                item.setToolTip(tip)
        corner = t.horizontalHeaderItem(0)
        if corner is None or corner.text() != name:  # the layer's ball, named above its rows
            corner = QtWidgets.QTableWidgetItem(name)
            t.setHorizontalHeaderItem(0, corner)
        corner.setToolTip(f"the estimators' answers for {name}, errors against the truth")
        notes: list[str] = []
        reasons: set[str] = set()
        for j, row in enumerate(rows, start=1):
            head = t.horizontalHeaderItem(j)
            if head is None or head.text() != row[0]:
                head = QtWidgets.QTableWidgetItem(_swatch(estimator_color3d(row[0])), row[0])
                t.setHorizontalHeaderItem(j, head)
            name, r, dr, az, daz, el, de, note = row
            texts = (
                f"{r} ({dr} %)" if dr else r,
                f"{az} ({daz})" if daz else az,
                f"{el} ({de})" if de else el,
                note if r or not note else user_message(note, 60),
            )
            for i, text in enumerate(texts):
                item = _cell(t, i, j)
                if item.text() != text:
                    item.setText(text)
                    item.setToolTip(text)
            if note and not r:  # no answer: the reason in the cell's tooltip, in full
                _cell(t, 3, j).setToolTip(user_message(f"{name}: {note}", 400))
                reasons.add(note)
        if len(reasons) == 1 and len(rows) > 1 and all(not row[1] for row in rows):
            notes.append(user_message(reasons.pop(), NOTE_CHARS))  # one reason for all
        if preds.note:
            notes.append(user_message(preds.note, NOTE_CHARS))
        self.pred_rows = rows
        fit_columns(t)
        self.pred_note.setText("\n".join(notes))
        self.pred_note.setToolTip("\n".join(notes))
        self.pred_note.setVisible(bool(notes))
        side, top = t.verticalHeader(), t.horizontalHeader()
        row_h = side.defaultSectionSize() if side is not None else 20
        head_h = top.sizeHint().height() if top is not None else row_h
        t.setFixedHeight(row_h * len(PRED_ROWS) + head_h + 2 * t.frameWidth() + 1)

    def natural_width(self) -> int:
        """The panel's width with both tables whole (names up to NAME_WANT_PX)."""
        lay = self.layout()
        m = lay.contentsMargins() if lay is not None else None
        pad = m.left() + m.right() if m is not None else 8
        tables = [self.table] + ([self.pred_table] if self.pred_table.isVisibleTo(self) else [])
        return max(natural_width(t) for t in tables) + pad

    def pred_text(self, name: str, row: str) -> str:
        """The predictions table's text for estimator ``name`` in row ``row`` ("r", "az",
        "el" or "note")."""
        i = {"r": 0, "az": 1, "el": 2, "note": 3}[row]
        t = self.pred_table
        for j in range(1, t.columnCount()):
            head = t.horizontalHeaderItem(j)
            if head is not None and head.text() == name:
                cell = t.item(i, j)
                return cell.text() if cell is not None else ""
        raise KeyError(name)

    def eventFilter(self, obj, ev) -> bool:  # noqa: N802 (Qt name)
        E = QtCore.QEvent.Type
        if ev.type() in (E.Resize, E.Show, E.FontChange) and obj in (self.table, self.pred_table):
            if ev.type() == E.FontChange:  # Ctrl+= / F5: rows as tall as the new text
                side = obj.verticalHeader()
                if side is not None:
                    side.setDefaultSectionSize(obj.fontMetrics().height() + 4)
                if obj is self.table:
                    self._fit_height()
            fit_columns(obj, KEEP_COLUMNS if obj is self.table else None)
        return False

    def _fit_height(self) -> None:
        """The Balls table at least as tall as its header and its rows (two at least,
        MIN_ROWS at most) at the text size now: at F11 + F5 + 175 % in 1280 x 720 it kept
        the height of three rows at 100 % and showed one ball and half of the next."""
        t = self.table
        side, head = t.verticalHeader(), t.horizontalHeader()
        row_h = side.defaultSectionSize() if side is not None else 20
        head_h = head.sizeHint().height() if head is not None else row_h
        rows = min(max(t.rowCount(), 2), MIN_ROWS)
        t.setMinimumHeight(head_h + rows * row_h + 2 * t.frameWidth())

    def _recolor(self, i: int, colors: list[str]) -> bool:
        return i >= len(self._colors) or self._colors[i] != colors[i]

    def text(self, i: int, column: str) -> str:
        """The text shown in row ``i`` under the header ``column``."""
        j = [h for h, _ in COLUMNS].index(column)
        item = self.table.item(i, j)
        return item.text() if item is not None else ""


def select_row(model: AppModel3D | None, i: int) -> None:
    """A click on row ``i``: its ball selected."""
    if model is not None and 0 <= i < len(model.scene.features):
        model.select(i)


def type_into(model: AppModel3D | None, i: int, key: str, text: str) -> str | None:
    """Ball ``i``'s ``key`` typed as ``text`` into ``model`` (one undo step, the ball
    selected): None, or the one-line reason it was refused (nothing changed)."""
    if model is None or not 0 <= i < len(model.scene.features):
        return "no such ball"
    try:
        model.type_value(i, key, text)
    except ValueError as exc:
        return (str(exc).splitlines() or ["not a value"])[0]
    model.select(i)
    return None


def _swatch(color: str) -> QtGui.QIcon:
    pix = QtGui.QPixmap(10, 10)
    pix.fill(QtGui.QColor(color))
    return QtGui.QIcon(pix)
