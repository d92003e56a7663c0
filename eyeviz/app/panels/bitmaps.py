"""The bitmaps panel: Omega_A and Omega_B, the m/2 the networks see and the whole eye."""

from __future__ import annotations

import math

import numpy as np
from PyQt5 import QtCore, QtGui, QtWidgets

from eyeviz.model.app_model import AppModel
from eyeviz.render.vtk.actors import UNLIT, hex_rgb

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


def _owners_of(st, eye: str) -> np.ndarray:
    from eyeviz.model.state import owners

    return owners(st.LA, st.RA, st.m) if eye == "A" else owners(st.LB, st.RB, st.m)
