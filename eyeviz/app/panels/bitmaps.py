"""The bitmaps panel: Omega_A and Omega_B, the m/2 the networks see and the whole eye."""

from __future__ import annotations

import functools
import math

import numpy as np
from PyQt5 import QtCore, QtGui, QtWidgets

from eyeviz.model.app_model import AppModel
from eyeviz.render.vtk.style import UNLIT, hex_rgb

INK = QtGui.QColor(30, 30, 30)
CELL_LINE = 0xFF9A9A9A  # cell boundaries (QImage.Format_RGB32)


def _columns(owner: np.ndarray, width: int) -> np.ndarray:
    """The owner shown in each of ``width`` pixel columns: a wide cell spans several
    columns; where a column holds several cells, :func:`_downsample` keeps any lit one."""
    n = owner.shape[0]
    if n > width or n == 0:
        return _downsample(owner, width)
    return owner[(np.arange(width) * n) // width]


@functools.lru_cache(maxsize=8)
def _row_kinds(height: int) -> np.ndarray:
    """Which kind of pixel row each of a strip image's height + 1 rows is: 0 the strip,
    1 under the selection outline's horizontal edges (2 px, one pixel inside), 2 border."""
    which = np.zeros(height + 1, np.intp)
    which[[1, 2, height - 2, height - 1]] = 1
    which[[0, height]] = 2
    return which


def _argb(color: QtGui.QColor) -> int:
    """A colour as a QImage.Format_RGB32 pixel."""
    return 0xFF000000 | (color.red() << 16) | (color.green() << 8) | color.blue()


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
    _small_base = 0.0

    def __init__(self, model: AppModel, parent: QtWidgets.QWidget | None = None) -> None:
        super().__init__(parent)
        self.model = model
        self.strips: dict[tuple[str, bool], np.ndarray] = {}
        self.colors = np.array([UNLIT], dtype=np.uint8)
        self.intervals: dict[str, tuple[int, int] | None] = {"A": None, "B": None}
        self.sel_color = INK
        self.selected: int | None = None
        self.texts: dict[tuple[str, bool], str] = {}
        self._eye_keys: dict[str, bytes] = {}
        self._row_keys: dict[tuple[str, bool], tuple] = {}
        self._runs: dict[tuple[str, bool], list[tuple[int, int]]] = {}
        self._geo_key: tuple | None = None
        self._geo = (0, 0, 0)
        self._shown: bool | None = None  # the bitmaps layer shown at the last refresh
        self._palette_key: tuple[str, ...] | None = None
        self._palette_rgb = np.array([UNLIT], dtype=np.uint8)
        self._argb: np.ndarray = np.zeros(1, np.uint32)
        self._images: dict[tuple[str, bool], tuple[tuple, QtGui.QImage, np.ndarray]] = {}
        self._static: dict[str, QtGui.QStaticText] = {}
        self._small: QtGui.QFont | None = None
        # paints every pixel itself
        self.setAttribute(QtCore.Qt.WidgetAttribute.WA_OpaquePaintEvent)
        self.setMinimumHeight(150)
        self.setMaximumHeight(190)
        self.setSizePolicy(QtWidgets.QSizePolicy.Expanding, QtWidgets.QSizePolicy.Fixed)

    def refresh(self) -> None:
        """Take the state's owners and the selected intervals; repaint the changed rows.

        An eye's rows are a function of its intervals (L, R of every feature: the owners),
        the selection, the colours and m: a key of a few hundred bytes, compared before
        anything of m elements is built (288 kB a row at m = 36,000)."""
        st = self.model.state
        sc = self.model.scene
        i = self.model.selected
        sel = i if i is not None and i < st.n else None
        colors = self._palette(tuple(f.color for f in sc.features))
        self.colors, self.selected = colors, sel
        self.sel_color = QtGui.QColor(sc.features[sel].color if sel is not None else "#222")
        intervals: dict[str, tuple[int, int] | None] = {"A": None, "B": None}
        if st.LA is None or st.RA is None or st.LB is None or st.RB is None:
            self.strips, self.intervals, self._runs = {}, intervals, {}
            self.texts = {row: "" for row in self.ROWS}
            self._eye_keys = {}
            self._shown_changed(False)
            return
        m = st.m
        lr = {"A": (st.LA, st.RA), "B": (st.LB, st.RB)}
        if sel is not None:
            intervals = {e: (int(lr[e][0][sel]), int(lr[e][1][sel])) for e in ("A", "B")}
        self.intervals = intervals
        self._runs = {
            (eye, whole): _interval_runs(intervals[eye], m, whole)
            for (eye, whole) in self.ROWS
            if intervals[eye] is not None
        }
        self.texts = {
            (eye, whole): (
                ""
                if iv is None
                else (f"[{iv[0]}, {iv[1]}]" if whole else _runs_text(self._runs[(eye, whole)]))
            )
            for (eye, whole) in self.ROWS
            for iv in (intervals[eye],)
        }
        tail = b"".join(
            (
                np.array([m, -1 if sel is None else sel], np.int64).tobytes(),
                colors.tobytes(),
                self.sel_color.name().encode(),
            )
        )
        strips = dict(self.strips)
        changed: list[tuple[str, bool]] = []
        for eye in ("A", "B"):
            lo, hi = lr[eye]
            key = b"".join(
                (np.asarray(lo, np.int64).tobytes(), np.asarray(hi, np.int64).tobytes(), tail)
            )
            if self._eye_keys.get(eye) != key or (eye, True) not in strips:
                self._eye_keys[eye] = key
                own = _owners_on_top(st, eye, intervals[eye], sel)
                strips[(eye, True)] = own
                strips[(eye, False)] = own[: m // 2]
        self.strips = strips
        whole_panel = self._shown_changed(sc.shows("bitmaps"))
        for r, row in enumerate(self.ROWS):
            row_key = (self._eye_keys[row[0]], row[1], self.texts[row])
            if self._row_keys.get(row) != row_key:
                self._row_keys[row] = row_key
                changed.append(row)
                if not whole_panel:  # the strip and its text; the row's label never changes
                    rect = self._row_rect(r)
                    rect.setLeft(self._geometry(self.fontMetrics())[0])
                    self.update(rect)
        if self.isVisible() and not whole_panel:  # drawn now, before the view renders
            label_w, right_w, row_h = self._geometry(self.fontMetrics())
            for row in changed:
                self._strip_image(row, max(self.width() - right_w - label_w, 1), row_h - 8)

    def _shown_changed(self, shown: bool) -> bool:
        """Whether the panel shows strips now; a change repaints all of it (True)."""
        if shown != self._shown:
            self._shown = shown
            self.update()
            return True
        return False

    def _palette(self, colors: tuple[str, ...]) -> np.ndarray:
        """UNLIT, then each feature's colour (uint8 rgb rows), rebuilt only when they change."""
        if self._palette_key != colors:
            self._palette_key = colors
            rgb = np.vstack([UNLIT] + [hex_rgb(c) for c in colors]).astype(np.uint8)
            self._palette_rgb = rgb
            c = rgb.astype(np.uint32)  # QImage.Format_RGB32: 0xffRRGGBB
            self._argb = 0xFF000000 | (c[:, 0] << 16) | (c[:, 1] << 8) | c[:, 2]
        return self._palette_rgb

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

    def _strip_image(self, row: tuple[str, bool], width: int, height: int) -> QtGui.QImage:
        """The row's strip, (width + 1) x (height + 1) pixels as on screen, drawn in numpy:
        one pixel column per ``width``-th of the ommatidia (:func:`_downsample`), the cell
        boundaries when a cell is at least CELL_PX wide, the selected feature's cells
        outlined (2 px), a 1 px border. Cached until the row or the size changes; a blit
        costs ~3 us where the QPainter calls it replaces cost ~70 us a row."""
        key = (self._row_keys.get(row), width, height)
        cached = self._images.get(row)
        if cached is not None and cached[0] == key:
            return cached[1]
        own = self.strips[row]
        n = max(own.shape[0], 1)
        # three kinds of pixel row, stacked by one gather: the strip (with the outline's
        # vertical edges), the strip under the outline's horizontal edges, the border
        kinds = np.empty((3, width + 1), np.uint32)
        strip, edge, border = kinds
        strip[:width] = self._argb[_columns(own, width) + 1]
        cell = width / n
        if cell >= self.CELL_PX:
            strip[np.round(np.arange(1, n) * cell).astype(np.intp)] = CELL_LINE
        edge[:] = strip
        sel = _argb(self.sel_color.darker(130))
        for a, b in self._runs.get(row, []) if width >= 4 and height >= 6 else []:
            xa = min(int(a * width / n), width - 2)
            xb = max(min(int(math.ceil((b + 1) * width / n)), width), xa + 2)
            strip[xa : xa + 2] = sel
            strip[xb - 2 : xb] = sel
            edge[xa:xb] = sel
        border[:] = strip[0] = strip[width] = edge[0] = edge[width] = _argb(INK)
        buf = kinds[_row_kinds(height)]
        img = QtGui.QImage(
            buf.data, width + 1, height + 1, 4 * (width + 1), QtGui.QImage.Format_RGB32
        )
        self._images[row] = (key, img, buf)  # buf keeps the image's pixels alive
        return img

    def _text(self, text: str) -> QtGui.QStaticText:
        """``text`` laid out once (QStaticText: ~3 us a draw against ~10 us for drawText)."""
        st = self._static.get(text)
        if st is None:
            if len(self._static) > 64:
                self._static.clear()
            st = self._static[text] = QtGui.QStaticText(text)
            st.setTextFormat(QtCore.Qt.TextFormat.PlainText)
        return st

    def paintEvent(self, event) -> None:  # noqa: N802 (Qt name)
        p = QtGui.QPainter(self)
        area = event.rect()
        p.fillRect(area, QtGui.QColor("white"))
        if not self.model.scene.shows("bitmaps") or not self.strips:
            p.setPen(INK)
            p.drawText(self.rect(), QtCore.Qt.AlignmentFlag.AlignCenter, "bitmaps layer hidden")
            p.end()
            return
        fm = p.fontMetrics()
        label_w, right_w, row_h = self._geometry(fm)
        x0, x1 = label_w, self.width() - right_w
        width = max(x1 - x0, 1)
        text_dy = (row_h - fm.height()) // 2
        for r, (eye, whole) in enumerate(self.ROWS):
            y = 4 + r * row_h
            if not area.intersects(QtCore.QRect(0, y, self.width(), row_h)):
                continue
            n = self.strips[(eye, whole)].shape[0]
            target = QtCore.QRect(x0, y + 3, width, row_h - 8)
            p.drawImage(x0, y + 3, self._strip_image((eye, whole), width, row_h - 8))
            cell = width / max(n, 1)
            if cell >= self.CELL_PX:  # small m: each cell's index
                self._paint_indices(p, target, self.strips[(eye, whole)], cell)
            if area.left() < label_w:  # the label: only on a whole repaint (it never changes)
                name = f"Ω_{eye}  " + ("whole eye" if whole else "0…m/2−1")
                p.setPen(INK)
                p.drawStaticText(4, y + text_dy, self._text(name))
            text = self.texts.get((eye, whole), "")
            if text:
                p.setPen(self.sel_color)
                text = fm.elidedText(text, QtCore.Qt.TextElideMode.ElideRight, right_w - 8)
                p.drawStaticText(x1 + 8, y + text_dy, self._text(text))
        p.end()

    def _paint_indices(
        self, p: QtGui.QPainter, target: QtCore.QRect, own: np.ndarray, cell: float
    ) -> None:
        """Cell indices where an ommatidium is at least CELL_PX wide (every k-th to fit),
        grey on an unlit cell, white on a lit one."""
        n = own.shape[0]
        if self._small is None or self._small_base != p.font().pointSizeF():
            self._small_base = p.font().pointSizeF()
            self._small = QtGui.QFont(p.font())
            self._small.setPointSizeF(max(7.0, 0.7 * self._small_base))
        small = self._small
        x0 = target.left()
        every = max(
            1, math.ceil(QtGui.QFontMetrics(small).horizontalAdvance(str(n - 1)) * 1.6 / cell)
        )
        base = p.font()
        p.setFont(small)
        for k in range(0, n, every):
            p.setPen(QtGui.QColor("#ffffff" if own[k] >= 0 else "#555555"))
            p.drawText(
                QtCore.QRectF(x0 + k * cell, target.top(), cell, target.height()),
                QtCore.Qt.AlignmentFlag.AlignCenter,
                str(k),
            )
        p.setFont(base)


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


def _runs_text(runs: list[tuple[int, int]]) -> str:
    """The selected feature's lit indices among the m/2 the networks see, from the runs of
    :func:`_interval_runs` (at most two: the lit set is one interval modulo m)."""
    if not runs:
        return "none"
    return " ∪ ".join(f"[{a}, {b}]" for a, b in runs)


def _owners_on_top(st, eye: str, iv: tuple[int, int] | None, sel: int | None) -> np.ndarray:
    """The eye's owner per ommatidium with the selected feature drawn over the others
    where they overlap (its lit cells {k mod m : L <= k <= R} written as slices)."""
    own = st.owner_a if eye == "A" else st.owner_b
    if own is None:
        own = _owners_of(st, eye)
    if sel is None or iv is None:
        return own
    m = st.m
    lo, hi = iv
    own = own.copy()
    own[lo : min(hi, m - 1) + 1] = sel
    if hi >= m:
        own[: hi - m + 1] = sel
    return own


def _owners_of(st, eye: str) -> np.ndarray:
    from eyeviz.model.state import owners

    return owners(st.LA, st.RA, st.m) if eye == "A" else owners(st.LB, st.RB, st.m)
