"""Qt side panels: bitmaps, readout, eye parameters, feature list, layer toggles.

Panels draw from the model's :class:`~eyeviz.model.state.SceneState` and send edits to the
:class:`~eyeviz.model.app_model.AppModel`; none keeps its own copy of the truth.
"""

from __future__ import annotations

import math
import re

import numpy as np
from PyQt5 import QtCore, QtGui, QtWidgets

from eyeviz.model.app_model import AppModel
from eyeviz.model.scene import LAYERS
from eyeviz.render.vtk.actors import UNLIT, hex_rgb

__all__ = ["BitmapPanel", "EyesPanel", "FeaturePanel", "LayersPanel", "ReadoutPanel", "ValueText"]

ERROR_STYLE = "color: #b00020; font-weight: bold;"
_PATH = re.compile(r"(?:[A-Za-z]:)?(?:[\\/][^\s\\/:'\"()\[\],]+){2,}[\\/]?")
_DEV = re.compile(
    r"\b(?:Traceback|\w*Error|\w*Exception)\b:?\s*|\[Errno \d+\]\s*|\b\w+\.py\b(?::\d+)?"
)


def user_message(text: str, limit: int = 160) -> str:
    """A message fit for a user: one line, local paths reduced to their file name,
    Python exception names and file:line references removed, at most ``limit`` chars."""
    line = str(text).strip().splitlines()[0] if str(text).strip() else ""
    line = _PATH.sub(lambda mt: "‘" + re.split(r"[\\/]", mt.group(0).rstrip("\\/"))[-1] + "’", line)
    line = _DEV.sub("", line).strip(" :")
    return line if len(line) <= limit else line[: limit - 1] + "…"


def wrap_label(label: QtWidgets.QLabel) -> QtWidgets.QLabel:
    """A word-wrapped message label that never widens its panel: its width is the
    panel's (a long word is cut, the whole text is in the tooltip)."""
    label.setWordWrap(True)
    label.setSizePolicy(QtWidgets.QSizePolicy.Ignored, QtWidgets.QSizePolicy.Minimum)
    label.setMinimumWidth(0)
    return label


ANY_DESIGN = frozenset({"analytic", "limit"})  # answer for any h, l, m (no training)


def design_note(model: AppModel, name: str) -> str | None:
    """One short line when estimator ``name`` was made for other eyes than the scene's
    ("trained for h = 40, l = 20, m = 720"), else None (issue 10 item 4). Reads the
    estimator's declared ``domain``; analytic and limit answer for any eyes."""
    if name in ANY_DESIGN or model.predictor is None:
        return None
    est = model.predictor.peek(name)  # never loads here: loading runs on a worker
    d = getattr(est, "domain", None)
    if isinstance(est, str) or d is None or getattr(est, "any_design", False):
        return None
    e = model.scene.eyes
    if (float(d.h), float(d.l), int(d.m)) == (float(e.h), float(e.l), int(e.m)):
        return None
    return f"trained for h = {d.h:g}, l = {d.l:g}, m = {d.m}"


def range_note(model: AppModel, name: str, r: float, g: float) -> str | None:
    """Why feature (r, g) lies outside estimator ``name``'s declared r and g range, or None."""
    est = model.predictor.peek(name) if model.predictor is not None else None
    d = getattr(est, "domain", None)
    if d is None or isinstance(est, str):
        return None
    if not d.r_min <= r <= d.r_max or g > d.g_max:
        return f"outside its range: r in [{d.r_min:g}, {d.r_max:g}], g <= {d.g_max:g}"
    return None


def design_skips(model: AppModel) -> set[str]:
    """Estimators made for other eyes: they draw no ring."""
    if not model.scene.shows("predictions"):
        return set()
    return {n for n in model.scene.estimators if design_note(model, n) is not None}


def unelide_tabs(widget: QtWidgets.QWidget) -> None:
    """Tab names of the window's tabbed docks in full (scroll buttons when they do not all
    fit) instead of "Fe…", "E…"."""
    win = widget.window()
    for bar in win.findChildren(QtWidgets.QTabBar):
        if bar.elideMode() != QtCore.Qt.ElideNone:
            bar.setElideMode(QtCore.Qt.ElideNone)
            bar.setUsesScrollButtons(True)


class _Unelide(QtCore.QObject):
    """Re-applies :func:`unelide_tabs` whenever a tabbed dock appears or is re-tabbed."""

    def eventFilter(self, obj, ev) -> bool:  # noqa: N802 (Qt name)
        if ev.type() in (QtCore.QEvent.Show, QtCore.QEvent.ParentChange):
            unelide_tabs(obj)
        return False


def set_message(label: QtWidgets.QLabel, text: str) -> None:
    """Show ``text`` (several lines allowed) in a :func:`wrap_label`, tooltip = full text."""
    lines = [user_message(t, 400) for t in str(text).splitlines() if t.strip()]
    full = "\n".join(lines)
    if label.text() != full:
        label.setText(full)
        label.setToolTip(full)


INK = QtGui.QColor(30, 30, 30)


def _downsample(owner: np.ndarray, width: int) -> np.ndarray:
    """Per pixel column, the owner of any lit ommatidium in it (max), so nothing lit vanishes."""
    n = owner.shape[0]
    if width <= 0:
        return owner[:0]
    if n <= width:
        return owner
    starts = (np.arange(width) * n) // width
    return np.maximum.reduceat(owner, starts)


class BitmapPanel(QtWidgets.QWidget):
    """Omega_A and Omega_B: the m/2 the networks see and the whole eye, lit [L, R] beside.

    The selected feature is drawn over the others where they overlap (and outlined), so
    it never hides under a neighbour; when an ommatidium is at least ``CELL_PX`` pixels
    wide the cell boundaries are drawn, and their indices where the text fits. A change
    repaints only the rows that changed (a drag lighting the same cells paints nothing).
    """

    ROWS = (("A", False), ("A", True), ("B", False), ("B", True))
    CELL_PX = 6.0  # cell boundaries from this width on

    def __init__(self, model: AppModel, parent=None):
        super().__init__(parent)
        self.model = model
        self.strips: dict[tuple[str, bool], np.ndarray] = {}
        self.colors = np.array([UNLIT], dtype=np.uint8)
        self.intervals: dict[str, tuple[int, int] | None] = {"A": None, "B": None}
        self.sel_color = INK
        self.selected: int | None = None
        self.texts: dict[tuple[str, bool], str] = {}
        self.sel_masks: dict[tuple[str, bool], np.ndarray] = {}
        self._row_keys: dict[tuple[str, bool], bytes] = {}
        self._runs: dict[tuple[str, bool], list[tuple[int, int]]] = {}
        self._geo_key: tuple | None = None
        self._geo = (0, 0, 0)
        self._shown = None
        self.setAttribute(QtCore.Qt.WA_OpaquePaintEvent)  # paints every pixel itself
        self.setMinimumHeight(150)
        self.setMaximumHeight(190)
        self.setSizePolicy(QtWidgets.QSizePolicy.Expanding, QtWidgets.QSizePolicy.Fixed)

    def refresh(self) -> None:
        """Take the state's owners and the selected intervals; repaint the changed rows."""
        from eyeviz.core.geometry import intervals_to_bitmap

        st = self.model.state
        sc = self.model.scene
        strips: dict[tuple[str, bool], np.ndarray] = {}
        masks: dict[tuple[str, bool], np.ndarray] = {}
        intervals: dict[str, tuple[int, int] | None] = {"A": None, "B": None}
        i = self.model.selected
        sel = i if i is not None and i < st.n else None
        if st.LA is not None:
            m = st.m
            oa = st.owner_a if st.owner_a is not None else _owners_of(st, "A")
            ob = st.owner_b if st.owner_b is not None else _owners_of(st, "B")
            if sel is not None:
                intervals = {
                    "A": (int(st.LA[sel]), int(st.RA[sel])),
                    "B": (int(st.LB[sel]), int(st.RB[sel])),
                }
            for eye, own in (("A", oa), ("B", ob)):
                iv = intervals[eye]
                mask = intervals_to_bitmap(iv[0], iv[1], m) if iv is not None else np.zeros(m, bool)
                if sel is not None and mask.any():
                    own = own.copy()
                    own[mask] = sel  # the selected feature on top where features overlap
                strips[(eye, True)] = own
                strips[(eye, False)] = own[: m // 2]
                masks[(eye, True)] = mask
                masks[(eye, False)] = mask[: m // 2]
        colors = np.vstack([UNLIT] + [hex_rgb(f.color) for f in sc.features]).astype(np.uint8)
        shown = sc.shows("bitmaps") and bool(strips)
        self.strips, self.intervals, self.colors, self.selected = strips, intervals, colors, sel
        self.sel_masks = masks
        self._runs = {
            (eye, whole): _interval_runs(intervals[eye], st.m, whole)
            for (eye, whole) in self.ROWS
            if intervals[eye] is not None
        }
        self.sel_color = QtGui.QColor(sc.features[sel].color if sel is not None else "#222")
        m = st.m
        self.texts = {
            (eye, whole): (
                "" if iv is None else (f"[{iv[0]}, {iv[1]}]" if whole else _half_text(iv, m))
            )
            for (eye, whole) in self.ROWS
            for iv in (intervals[eye],)
        }
        whole_panel = shown != self._shown
        self._shown = shown
        # a row is a function of its eye's intervals (L, R of every feature: the owners),
        # the selection, the colours and m: a key of a few hundred bytes, not the strip's
        # m int64 owners (288 kB a row at m = 36,000, built every drag frame)
        lr = {"A": (st.LA, st.RA), "B": (st.LB, st.RB)}
        for r, row in enumerate(self.ROWS):
            if row not in strips:
                continue
            lo, hi = lr[row[0]]
            key = b"".join(
                (
                    np.asarray(lo, np.int64).tobytes(),
                    np.asarray(hi, np.int64).tobytes(),
                    np.array([m, -1 if sel is None else sel, row[1]], np.int64).tobytes(),
                    colors.tobytes(),
                    self.texts[row].encode(),
                    self.sel_color.name().encode(),
                )
            )
            if self._row_keys.get(row) != key:
                self._row_keys[row] = key
                if not whole_panel:
                    self.update(self._row_rect(r))
        if whole_panel:
            self.update()

    def lit(self, eye: str, whole: bool) -> np.ndarray:
        """The bitmap shown in a strip (bool per ommatidium)."""
        return self.strips[(eye, whole)] >= 0

    def _geometry(self, fm: QtGui.QFontMetrics) -> tuple[int, int, int]:
        key = (fm.height(), fm.averageCharWidth(), self.height())
        if self._geo_key != key:  # text widths measured once per font and height
            label_w = fm.horizontalAdvance("Ω_B  whole eye ") + 8
            right_w = fm.horizontalAdvance("[35999, 35999] ∪ [0, 0]") + 8
            row_h = max(fm.height() + 10, (self.height() - 8) // 4)
            self._geo_key, self._geo = key, (label_w, right_w, row_h)
        return self._geo

    def _row_rect(self, r: int) -> QtCore.QRect:
        _, _, row_h = self._geometry(self.fontMetrics())
        return QtCore.QRect(0, 4 + r * row_h, self.width(), row_h)

    def paintEvent(self, event) -> None:  # noqa: N802 (Qt name)
        p = QtGui.QPainter(self)
        p.fillRect(event.rect(), QtGui.QColor("white"))
        if not self.model.scene.shows("bitmaps") or not self.strips:
            p.setPen(INK)
            p.drawText(self.rect(), QtCore.Qt.AlignCenter, "bitmaps layer hidden")
            p.end()
            return
        fm = p.fontMetrics()
        label_w, right_w, row_h = self._geometry(fm)
        x0, x1 = label_w, self.width() - right_w
        width = max(x1 - x0, 1)
        small = QtGui.QFont(p.font())
        small.setPointSizeF(max(7.0, 0.7 * p.font().pointSizeF()))
        sfm = QtGui.QFontMetrics(small)
        for r, (eye, whole) in enumerate(self.ROWS):
            y = 4 + r * row_h
            if not event.rect().intersects(QtCore.QRect(0, y, self.width(), row_h)):
                continue
            own = self.strips[(eye, whole)]
            n = own.shape[0]
            cols = _downsample(own, width)
            rgb = np.ascontiguousarray(self.colors[cols + 1])
            img = QtGui.QImage(
                rgb.data, rgb.shape[0], 1, 3 * rgb.shape[0], QtGui.QImage.Format_RGB888
            )
            target = QtCore.QRect(x0, y + 3, width, row_h - 8)
            p.drawImage(target, img)
            cell = width / max(n, 1)
            if cell >= self.CELL_PX:  # small m: the cells and their indices
                p.setPen(QtGui.QPen(QtGui.QColor("#9a9a9a"), 1))
                for k in range(1, n):
                    xk = round(x0 + k * cell)
                    p.drawLine(xk, target.top(), xk, target.bottom())
                every = max(1, math.ceil(sfm.horizontalAdvance(str(n - 1)) * 1.6 / cell))
                p.setFont(small)
                p.setPen(QtGui.QColor("#555555"))
                for k in range(0, n, every):
                    p.drawText(
                        QtCore.QRectF(x0 + k * cell, target.top(), cell, target.height()),
                        QtCore.Qt.AlignCenter,
                        str(k),
                    )
                p.setFont(self.font())
            runs = self._runs.get((eye, whole), [])
            if runs:  # outline the selected feature's cells
                p.setPen(QtGui.QPen(self.sel_color.darker(130), 2))
                p.setBrush(QtCore.Qt.NoBrush)
                for a, b in runs:
                    xa, xb = x0 + a * width / n, x0 + (b + 1) * width / n
                    p.drawRect(
                        QtCore.QRectF(xa, target.top() + 1, max(xb - xa, 2.0), target.height() - 2)
                    )
            p.setPen(QtGui.QPen(INK, 1))
            p.setBrush(QtCore.Qt.NoBrush)
            p.drawRect(target)
            p.setPen(INK)
            name = f"Ω_{eye}  " + ("whole eye" if whole else "0…m/2−1")
            p.drawText(QtCore.QRect(4, y, label_w - 8, row_h), QtCore.Qt.AlignVCenter, name)
            text = self.texts.get((eye, whole), "")
            if text:
                p.setPen(self.sel_color)
                rect = QtCore.QRect(x1 + 8, y, right_w - 8, row_h)
                p.drawText(
                    rect,
                    QtCore.Qt.AlignVCenter,
                    fm.elidedText(text, QtCore.Qt.ElideRight, rect.width()),
                )
        p.end()


def _runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """(first, last) index of each run of True in ``mask``."""
    d = np.diff(np.concatenate([[0], mask.astype(np.int8), [0]]))
    return list(
        zip(np.flatnonzero(d == 1).tolist(), (np.flatnonzero(d == -1) - 1).tolist(), strict=True)
    )


def _interval_runs(iv: tuple[int, int] | None, m: int, whole: bool) -> list[tuple[int, int]]:
    """(first, last) of each run of the lit set {k mod m : L <= k <= R} (L <= R < L + m,
    eyeviz.core.bits) in a strip of m cells (``whole``) or of the first m/2: what _runs
    finds in the mask, without building it."""
    if iv is None:
        return []
    lo, hi = int(iv[0]), int(iv[1])
    width = m if whole else m // 2
    runs = [(lo, min(hi, m - 1))] + ([(0, hi - m)] if hi >= m else [])
    out: list[tuple[int, int]] = []
    for a, b in sorted((a, min(b, width - 1)) for a, b in runs if a < width and a <= b):
        if out and a <= out[-1][1] + 1:  # the wrapped run meets the first one
            out[-1] = (out[-1][0], max(out[-1][1], b))
        else:
            out.append((a, b))
    return out


def _half_text(iv: tuple[int, int], m: int) -> str:
    """The selected feature's lit indices among the m/2 the networks see."""
    from eyeviz.core.geometry import intervals_to_bitmap

    k = np.flatnonzero(intervals_to_bitmap(iv[0], iv[1], m, m // 2))
    if k.size == 0:
        return "none"
    gaps = np.flatnonzero(np.diff(k) > 1)
    if gaps.size == 0:
        return f"[{k[0]}, {k[-1]}]"
    return f"[{k[0]}, {k[gaps[0]]}] ∪ [{k[gaps[0] + 1]}, {k[-1]}]"


def f_g(scene, i: int) -> float:
    return scene.features[i].g


def _owners_of(st, eye: str) -> np.ndarray:
    from eyeviz.model.state import owners

    return owners(st.LA, st.RA, st.m) if eye == "A" else owners(st.LB, st.RB, st.m)


GOOD, BAD, GREY = "#1b7837", "#b00020", "#777777"
READOUT_MIN_WIDTH = 420


class ValueText(QtWidgets.QWidget):
    """Plain text painted by the widget itself: a new text repaints this widget only.

    A QLabel's ``setText`` asks its parent layout to re-lay out (``updateGeometry``) on
    every change, which re-laid out the whole window on every drag event; this widget
    asks for a new geometry only when its number of lines changes.
    """

    def __init__(self, parent=None):
        super().__init__(parent)
        self._text = ""
        self._lines = 1
        self._color = QtGui.QColor("#1e1e1e")
        self.setAutoFillBackground(True)  # opaque: its repaint does not repaint the dock
        self.setSizePolicy(QtWidgets.QSizePolicy.Ignored, QtWidgets.QSizePolicy.Fixed)
        self.setFixedHeight(self._height(1))

    def _height(self, lines: int) -> int:
        return self.fontMetrics().lineSpacing() * lines + 2

    def text(self) -> str:
        return self._text

    def setText(self, text: str) -> None:  # noqa: N802 (Qt name)
        if text == self._text:
            return
        self._text = text
        lines = text.count("\n") + 1
        if lines != self._lines:
            self._lines = lines
            self.setFixedHeight(self._height(lines))  # a layout only when the shape changes
        self.setToolTip(text if len(text) > 40 else "")
        self.update()

    def set_style(self, color: str, bold: bool) -> None:
        f = self.font()
        if f.bold() != bold:
            f.setBold(bold)
            self.setFont(f)
            self.setFixedHeight(self._height(self._lines))
        self._color = QtGui.QColor(color)
        self.update()

    def sizeHint(self) -> QtCore.QSize:  # noqa: N802 (Qt name)
        return QtCore.QSize(120, self._height(self._lines))

    def paintEvent(self, event) -> None:  # noqa: N802 (Qt name)
        p = QtGui.QPainter(self)
        p.setPen(self._color)
        flags = QtCore.Qt.AlignLeft | QtCore.Qt.AlignTop
        fm = self.fontMetrics()
        y = 0
        for line in self._text.split("\n"):
            p.drawText(
                QtCore.QRect(0, y, self.width(), fm.lineSpacing()),
                flags,
                fm.elidedText(line, QtCore.Qt.ElideRight, self.width()),
            )
            y += fm.lineSpacing()
        p.end()


class ReadoutPanel(QtWidgets.QWidget):
    """The selected feature: r, phi, r_A, phi_A, r_B, phi_B, BFV, visibility, overlap; with
    the predictions layer each estimator's answer and errors, with the ambiguity layer the
    range of centres and radii giving the same bitmaps.

    A grid of plain-text labels, each re-set only when its text changes: a rich-text
    QLabel re-laid out on every drag event cost ~5 ms a frame.
    """

    def __init__(self, model: AppModel, parent=None):
        super().__init__(parent)
        self.model = model
        self._unelide = _Unelide(self)
        self.installEventFilter(self._unelide)
        self.texts: dict[str, str] = {}  # row key -> value text (what tests read)
        lay = QtWidgets.QVBoxLayout(self)
        lay.setContentsMargins(8, 8, 8, 8)
        self.title = QtWidgets.QLabel("")
        font = self.title.font()
        font.setPointSize(17)
        font.setBold(True)
        self.title.setFont(font)
        lay.addWidget(self.title)
        self.grid = QtWidgets.QGridLayout()
        self.grid.setHorizontalSpacing(14)
        self.grid.setVerticalSpacing(3)
        self.grid.setColumnStretch(0, 0)
        self.grid.setColumnStretch(1, 1)
        lay.addLayout(self.grid)
        lay.addStretch(1)
        self._rows: list[tuple[QtWidgets.QLabel, QtWidgets.QLabel]] = []
        self._cache: dict[int, tuple] = {}
        self._title_key = None
        self.setMinimumWidth(READOUT_MIN_WIDTH)
        self.title.setSizePolicy(QtWidgets.QSizePolicy.Ignored, QtWidgets.QSizePolicy.Preferred)

    def _row(self, k: int) -> tuple[QtWidgets.QLabel, QtWidgets.QLabel]:
        while len(self._rows) <= k:
            key, val = QtWidgets.QLabel(), ValueText()
            key.setTextFormat(QtCore.Qt.RichText)
            key.setAlignment(QtCore.Qt.AlignLeft | QtCore.Qt.AlignTop)
            r = len(self._rows)
            self.grid.addWidget(key, r, 0)
            self.grid.addWidget(val, r, 1)
            self._rows.append((key, val))
        return self._rows[k]

    def _set(self, rows: list[tuple[str, str, str, str]]) -> None:
        """rows of (id, key html, value text, value colour)."""
        self.texts = {rid: text for rid, _, text, _ in rows}
        for k, row in enumerate(rows):
            if self._cache.get(k) == row:
                continue
            key, val = self._row(k)
            old = self._cache.get(k)
            _, key_html, text, color = row
            if old is None or old[1] != key_html:
                key.setText(key_html)
            if old is None or old[2] != text:
                val.setText(text)
            if old is None or old[3] != color:
                val.set_style(color, color in (GOOD, BAD))
            if old is None:
                key.show()
                val.show()
            self._cache[k] = row
        for k in range(len(rows), len(self._rows)):
            if self._cache.pop(k, None) is not None:
                self._rows[k][0].hide()
                self._rows[k][1].hide()

    def _set_title(self, text: str, color: str) -> None:
        if self._title_key != (text, color):
            self._title_key = (text, color)
            self.title.setText(text)
            pal = self.title.palette()
            pal.setColor(QtGui.QPalette.WindowText, QtGui.QColor(color))
            self.title.setPalette(pal)

    def refresh(self) -> None:
        st, sc, i = self.model.state, self.model.scene, self.model.selected
        if i is None or i >= len(sc.features):
            self._set_title("no feature selected", "#555555")
            self._set([])
            return
        f = sc.features[i]
        self._set_title(f"● {f.name}", f.color)
        if not sc.shows("readout") or st.r is None:
            # the layer is off: no value at all (other layers may still compute them)
            self._set([("hidden", "", "readout layer hidden\n(tick it in Layers)", GREY)])
            return

        def yes(v, good=True):
            return ("yes" if v else "no"), (GOOD if bool(v) == good else BAD)

        def pair(a, b, good=True):
            (ta, ca), (tb, cb) = yes(a, good), yes(b, good)
            return f"{ta} / {tb}", (ca if ca == cb else "#444444")

        deg = 180.0 / math.pi
        ink = "#1e1e1e"
        vis, vis_c = pair(st.vis_a[i], st.vis_b[i])
        ovl, ovl_c = pair(st.overlap_a[i], st.overlap_b[i], False)
        bfv, bfv_c = yes(st.in_bfv[i])
        rows = [
            ("r", "r, φ", f"{st.r[i]:.1f}, {st.phi[i] * deg:.2f}°", ink),
            ("rA", "r<sub>A</sub>, φ<sub>A</sub>", f"{st.rA[i]:.1f}, {st.phiA[i] * deg:.2f}°", ink),
            ("rB", "r<sub>B</sub>, φ<sub>B</sub>", f"{st.rB[i]:.1f}, {st.phiB[i] * deg:.2f}°", ink),
            ("g", "g", f"{f.g:g}", ink),
            ("bfv", "in BFV", bfv, bfv_c),
            ("visible", "visible A / B", vis, vis_c),
            ("overlap", "overlaps A / B", ovl, ovl_c),
        ]
        if sc.shows("predictions"):
            rows += self._prediction_rows(i)
        if sc.shows("ambiguity"):
            rows.append(self._ambiguity_row())
        if sc.shows("posterior"):  # the limit's posterior (cached per key, issue 10)
            from eyeviz.model.posterior import readout

            text = readout(sc.eyes.pair(), f.x, f.y, f.g)
            rows.append(("posterior", "posterior", text, GREY if text[:5] == "none:" else ink))
        self._set(rows)

    def _prediction_rows(self, i: int) -> list[tuple[str, str, str, str]]:
        from eyeviz.model.derived import errors
        from eyeviz.model.palette import estimator_colors

        st, sc = self.model.state, self.model.scene
        preds = self.model.predictions
        cols = estimator_colors(sc.estimators)
        if not bool(st.in_domain()[i]):
            return [
                (
                    "domain",
                    "predictions",
                    "outside the networks' domain\n(not in the BFV or not seen by both eyes)",
                    BAD,
                )
            ]
        rows = []
        for name in sc.estimators:
            res = preds.get(name, "no prediction")
            key = f"<b style='color:{cols[name]}'>{name}</b>"
            note = design_note(self.model, name)
            if note is not None:  # made for other eyes: no answer shown (greyed)
                rows.append(
                    (f"pred:{name}", f"<span style='color:{GREY}'>{name}</span>", note, GREY)
                )
                continue
            if isinstance(res, str):
                loading = self.model.loading and res == self.model.loading
                rows.append(
                    (f"pred:{name}", key, "loading…" if loading else user_message(res, 120), GREY)
                )
                continue
            r_hat, phi_hat = float(res[0][i]), float(res[1][i])
            if not (math.isfinite(r_hat) and math.isfinite(phi_hat)):
                rows.append((f"pred:{name}", key, "no answer for these bitmaps", GREY))
                continue
            dr, pct, dphi = errors(float(st.r[i]), float(st.phi[i]), r_hat, phi_hat)
            text = (
                f"r {r_hat:.1f}   Δr {dr:+.1f} ({pct:+.2f} %)\n"
                f"φ {math.degrees(phi_hat):.2f}°   Δφ {dphi:+.3f}°"
            )
            out = range_note(self.model, name, float(st.r[i]), float(f_g(sc, i)))
            if out is not None:
                rows.append((f"pred:{name}", key, f"{text}\n{out}", BAD))
                continue
            rows.append((f"pred:{name}", key, text, "#1e1e1e"))
        return rows

    def _ambiguity_row(self) -> tuple[str, str, str, str]:
        amb = self.model.ambiguity
        if amb is None:
            return ("ambiguity", "same bitmaps", "the feature covers an eye centre", GREY)
        lo, hi = amb["r_range"]
        a0, a1 = amb["phi_range"]
        g0, g1 = amb["g_range"]
        more = "" if amb["bounded"] else " (unbounded)"
        text = (
            f"r ∈ [{lo:.0f}, {hi:.0f}]{more}\n"
            f"φ ∈ [{math.degrees(a0):.2f}°, {math.degrees(a1):.2f}°]\n"
            f"g ∈ [{g0:.3g}, {g1:.3g}]"
        )
        return ("ambiguity", "same bitmaps", text, "#1e1e1e")


def _num(v: float) -> str:
    """A float as typed back: the shortest text that reads as the same float ("40", not
    "40.0"; 40.123456789 in full, never rounded to "40.1235")."""
    t = repr(float(v))
    return t[:-2] if t.endswith(".0") else t


EYE_FIELDS = (("h", "origin to eye centre"), ("l", "eye radius"), ("m", "ommatidia per eye"))
PENDING_STYLE = "background: #fff4c2;"  # a typed value not applied yet


class EyesPanel(QtWidgets.QWidget):
    """h, l, m entered together (issue 12 item 11).

    Enter in any field (or Apply) checks the triple as
    :class:`~eyeviz.core.geometry.EyePair` does (0 < l < h, m an even integer >= 4, finite
    numbers; m <= the live limit) and changes the eyes in one undo step. Moving between
    fields applies nothing, so with l = 20 one can type h = 10, then l = 5, then Enter. A
    refused triple leaves the scene as it was, keeps what was typed (never clamped or
    reset behind the user's back) and says why in one line; Revert shows the scene's
    values again. Fields holding a value not applied yet are tinted.
    """

    def __init__(self, model: AppModel, parent=None):
        super().__init__(parent)
        self.model = model
        self._unelide = _Unelide(self)
        self.installEventFilter(self._unelide)
        form = QtWidgets.QFormLayout(self)
        self.edits: dict[str, QtWidgets.QLineEdit] = {}
        for key, tip in EYE_FIELDS:
            e = QtWidgets.QLineEdit()
            e.setObjectName(f"eyes_{key}")
            e.setToolTip(f"{tip}; Enter applies h, l and m together")
            e.returnPressed.connect(self.apply)
            e.textEdited.connect(self._mark)
            form.addRow(f"{key}  ({tip})", e)
            self.edits[key] = e
        row = QtWidgets.QHBoxLayout()
        self.apply_button = QtWidgets.QPushButton("Apply")
        self.apply_button.setToolTip("set h, l and m together (Enter in a field does the same)")
        self.apply_button.clicked.connect(self.apply)
        self.revert_button = QtWidgets.QPushButton("Revert")
        self.revert_button.setToolTip("show the scene's h, l and m again")
        self.revert_button.clicked.connect(self.revert)
        row.addWidget(self.apply_button)
        row.addWidget(self.revert_button)
        row.addStretch(1)
        form.addRow(row)
        self.message = wrap_label(QtWidgets.QLabel(""))
        self.message.setStyleSheet(ERROR_STYLE)
        form.addRow(self.message)
        self._shown: dict[str, str] | None = None  # the scene's values last filled in

    def scene_texts(self) -> dict[str, str]:
        e = self.model.scene.eyes
        return {"h": _num(e.h), "l": _num(e.l), "m": str(int(e.m))}

    def texts(self) -> dict[str, str]:
        return {k: w.text().strip() for k, w in self.edits.items()}

    def refresh(self) -> None:
        """Show the scene's h, l, m when they changed (an edit, undo, a file opened); a
        value typed and not applied survives other refreshes (a drag, a layer toggle)."""
        now = self.scene_texts()
        if now != self._shown:
            self._shown = now
            for key, val in now.items():
                self.edits[key].setText(val)
            self.message.setText("")
        self._mark()

    def pending(self) -> bool:
        return self.texts() != self.scene_texts()

    def _mark(self, *_args) -> None:
        now = self.scene_texts()
        for key, w in self.edits.items():
            w.setStyleSheet(PENDING_STYLE if w.text().strip() != now[key] else "")
        on = self.pending()
        self.apply_button.setEnabled(on)
        self.revert_button.setEnabled(on)

    def revert(self) -> None:
        self._shown = None
        self.refresh()

    def parse(self) -> tuple[float, float, int]:
        """The typed triple as numbers; ValueError naming the field otherwise."""
        t = self.texts()
        vals: list[float] = []
        for key in ("h", "l"):
            try:
                vals.append(float(t[key]))
            except ValueError:
                raise ValueError(f"{key} must be a number, got {t[key]!r}") from None
        try:
            m = int(t["m"])
        except ValueError:
            raise ValueError(f"m must be an even integer >= 4, got {t['m']!r}") from None
        return vals[0], vals[1], m

    def apply(self) -> bool:
        """Check the typed triple together; True if the scene now has it."""
        before = self.scene_texts()
        try:
            h, l, m = self.parse()
            self.model.set_eyes(h, l, m)  # EyePair's checks; nothing changes if refused
        except ValueError as exc:
            keep = ", ".join(f"{k} = {v}" for k, v in before.items())
            set_message(self.message, f"Refused: {exc} (the eyes stay {keep})")
            self._mark()
            return False
        self.message.setText("")
        self.revert()  # the applied values as the scene holds them
        return True


class FeaturePanel(QtWidgets.QWidget):
    """The feature list with editable name, x, y, g; selecting a row selects the feature."""

    COLS = ("name", "x", "y", "g")

    def __init__(self, model: AppModel, parent=None):
        super().__init__(parent)
        self.model = model
        self._unelide = _Unelide(self)
        self.installEventFilter(self._unelide)
        lay = QtWidgets.QVBoxLayout(self)
        lay.setContentsMargins(2, 2, 2, 2)
        self.table = QtWidgets.QTableWidget(0, 4)
        self.table.setHorizontalHeaderLabels(list(self.COLS))
        self.table.verticalHeader().setVisible(False)
        self.table.horizontalHeader().setSectionResizeMode(QtWidgets.QHeaderView.Stretch)
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


class LayersPanel(QtWidgets.QWidget):
    """One check box per layer; toggling is an undoable edit of the scene's layers."""

    def __init__(self, model: AppModel, parent=None):
        super().__init__(parent)
        self.model = model
        self._unelide = _Unelide(self)
        self.installEventFilter(self._unelide)
        grid = QtWidgets.QGridLayout(self)
        self.boxes: dict[str, QtWidgets.QCheckBox] = {}
        for i, name in enumerate(LAYERS):
            b = QtWidgets.QCheckBox(name)
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
