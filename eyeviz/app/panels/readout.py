"""The readout panel: the selected feature's values, each estimator's answer and the
ambiguity range, in plain-text rows that repaint only themselves.

Compact enough to show whole, unscrolled, in the side column of a 1280x720 window with the
predictions and the ambiguity layers on (two estimators): the feature's radius g sits on
the title line, "in BFV" shares the visibility row, and rows are 1 px apart.
"""

from __future__ import annotations

import math

from PyQt5 import QtCore, QtGui, QtWidgets

from eyeviz.app.panels.common import _Unelide, user_message
from eyeviz.app.panels.notes import design_note, range_note
from eyeviz.model.app_model import AppModel
from eyeviz.model.scene import Scene


def f_g(scene: Scene, i: int) -> float:
    return scene.features[i].g


GOOD, BAD, GREY = "#1b7837", "#b00020", "#777777"
READOUT_MIN_WIDTH = 420
PRED_LINES = 2  # an estimator's answer: r and its error, phi and its error
ROW_GAP_PX = 1  # between rows (3 px before: the last row did not fit at 1280x720)


class ValueText(QtWidgets.QWidget):
    """Plain text painted by the widget itself: a new text repaints this widget only.

    A QLabel's ``setText`` asks its parent layout to re-lay out (``updateGeometry``) on
    every change, which re-laid out the whole window on every drag event; this widget
    asks for a new geometry only when its number of lines changes.
    """

    def __init__(self, parent: QtWidgets.QWidget | None = None) -> None:
        super().__init__(parent)
        self._text = ""
        self._lines = 1
        self.min_lines = 1  # the height kept however few lines the text has
        self._color = QtGui.QColor("#1e1e1e")
        self._align = QtCore.Qt.AlignmentFlag.AlignLeft
        self.setAutoFillBackground(True)  # opaque: its repaint does not repaint the dock
        self.setSizePolicy(QtWidgets.QSizePolicy.Ignored, QtWidgets.QSizePolicy.Fixed)
        self.setFixedHeight(self._height(1))

    def _height(self, lines: int) -> int:
        # the last line needs the font's height, a pixel more than its line spacing
        return self.fontMetrics().lineSpacing() * lines + 1

    def text(self) -> str:
        return self._text

    def setText(self, text: str) -> None:  # noqa: N802 (Qt name)
        if text == self._text:
            return
        self._text = text
        lines = max(text.count("\n") + 1, self.min_lines)
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

    def set_alignment(self, align: QtCore.Qt.AlignmentFlag) -> None:
        """Left (the default) or right: where each line is painted."""
        self._align = align
        self.update()

    def sizeHint(self) -> QtCore.QSize:  # noqa: N802 (Qt name)
        return QtCore.QSize(120, self._height(self._lines))

    def changeEvent(self, event) -> None:  # noqa: N802 (Qt name)
        # F5 / Ctrl+= change the font: the fixed height follows (the values of the planar
        # lecture's step 7 were cut at the bottom, kept at the height of the old font)
        if event.type() == QtCore.QEvent.Type.FontChange:
            self.setFixedHeight(self._height(self._lines))
        super().changeEvent(event)

    def paintEvent(self, event) -> None:  # noqa: N802 (Qt name)
        p = QtGui.QPainter(self)
        p.setPen(self._color)
        flags = self._align | QtCore.Qt.AlignmentFlag.AlignTop
        fm = self.fontMetrics()
        y = 0
        for line in self._text.split("\n"):
            p.drawText(
                QtCore.QRect(0, y, self.width(), fm.lineSpacing()),
                flags,
                fm.elidedText(line, QtCore.Qt.TextElideMode.ElideRight, self.width()),
            )
            y += fm.lineSpacing()
        p.end()


class ReadoutPanel(QtWidgets.QWidget):
    """The selected feature: its name and radius g on the title line, then r, phi, r_A,
    phi_A, r_B, phi_B, visibility and BFV, overlap; with the predictions layer each
    estimator's answer and errors, with the ambiguity layer the range of centres and radii
    giving the same bitmaps.

    A grid of plain-text labels, each re-set only when its text changes: a rich-text
    QLabel re-laid out on every drag event cost ~5 ms a frame.
    """

    def __init__(self, model: AppModel, parent: QtWidgets.QWidget | None = None) -> None:
        super().__init__(parent)
        self.model = model
        self._unelide = _Unelide(self)
        self.installEventFilter(self._unelide)
        self.texts: dict[str, str] = {}  # row key -> value text (what tests read)
        lay = QtWidgets.QVBoxLayout(self)
        lay.setContentsMargins(8, 4, 8, 4)
        lay.setSpacing(ROW_GAP_PX + 1)
        self.title = QtWidgets.QLabel("")
        font = self.title.font()
        font.setPointSize(17)
        font.setBold(True)
        self.title.setFont(font)
        # the radius on the title line, right-aligned: a row fewer (a ValueText: a drag
        # resizing the feature repaints it alone)
        self.size_text = ValueText()
        self.size_text.set_alignment(QtCore.Qt.AlignmentFlag.AlignRight)
        head = QtWidgets.QHBoxLayout()
        head.setSpacing(14)
        head.addWidget(self.title, 3)
        head.addWidget(self.size_text, 2, QtCore.Qt.AlignmentFlag.AlignBottom)
        lay.addLayout(head)
        self.grid = QtWidgets.QGridLayout()
        self.grid.setHorizontalSpacing(14)
        self.grid.setVerticalSpacing(ROW_GAP_PX)
        self.grid.setColumnStretch(0, 0)
        self.grid.setColumnStretch(1, 1)
        lay.addLayout(self.grid)
        lay.addStretch(1)
        self._rows: list[tuple[QtWidgets.QLabel, ValueText]] = []
        self._cache: dict[int, tuple] = {}
        self._title_key: tuple[str, str] | None = None
        self.setMinimumWidth(READOUT_MIN_WIDTH)
        self.title.setSizePolicy(QtWidgets.QSizePolicy.Ignored, QtWidgets.QSizePolicy.Preferred)

    def _row(self, k: int) -> tuple[QtWidgets.QLabel, ValueText]:
        while len(self._rows) <= k:
            key, val = QtWidgets.QLabel(), ValueText()
            key.setTextFormat(QtCore.Qt.TextFormat.RichText)
            key.setAlignment(
                QtCore.Qt.Alignment(QtCore.Qt.AlignmentFlag.AlignLeft)
                | QtCore.Qt.AlignmentFlag.AlignTop
            )
            r = len(self._rows)
            self.grid.addWidget(key, r, 0)
            self.grid.addWidget(val, r, 1)
            self._rows.append((key, val))
        return self._rows[k]

    def _set(self, rows: list[tuple[str, str, str, str]], size: str = "") -> None:
        """rows of (id, key html, value text, value colour); ``size`` the title line's
        radius text (kept in ``texts`` as "g" when shown)."""
        self.size_text.setText(size)
        self.texts = {rid: text for rid, _, text, _ in rows}
        if size:
            self.texts["g"] = size
        for k, row in enumerate(rows):
            if self._cache.get(k) == row:
                continue
            key, val = self._row(k)
            # an estimator's row keeps its two lines while it loads or fails: the height
            # the dock was laid out for when the window opened (loading) is its final one
            val.min_lines = PRED_LINES if row[0].startswith("pred:") else 1
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

    def natural_width(self) -> int:
        """The width (px) its shown rows need at the current font, nothing elided: the
        title line (name and radius) or the widest key plus the widest value line."""
        lay = self.layout()
        m = lay.contentsMargins() if lay is not None else QtCore.QMargins()
        gap = self.grid.horizontalSpacing()
        keys, vals = 0, 0
        for key, val in self._rows:
            if not val.isHidden():
                keys = max(keys, key.sizeHint().width())
                fm = val.fontMetrics()
                vals = max([vals] + [fm.horizontalAdvance(t) for t in val.text().split("\n")])
        title = self.title.sizeHint().width() + 14
        title += self.size_text.fontMetrics().horizontalAdvance(self.size_text.text())
        return m.left() + m.right() + max(keys + gap + vals, title) + 2

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
        # with r, compute_state sets every array below (the readout layer needs them all)
        assert st.phi is not None and st.rA is not None and st.phiA is not None
        assert st.rB is not None and st.phiB is not None and st.in_bfv is not None
        assert st.vis_a is not None and st.vis_b is not None
        assert st.overlap_a is not None and st.overlap_b is not None

        def yes(v: object, good: bool = True) -> tuple[str, str]:
            return ("yes" if v else "no"), (GOOD if bool(v) == good else BAD)

        def pair(a: object, b: object, good: bool = True) -> tuple[str, str]:
            (ta, ca), (tb, cb) = yes(a, good), yes(b, good)
            return f"{ta} / {tb}", (ca if ca == cb else "#444444")

        deg = 180.0 / math.pi
        ink = "#1e1e1e"
        vis, vis_c = pair(st.vis_a[i], st.vis_b[i])
        ovl, ovl_c = pair(st.overlap_a[i], st.overlap_b[i], False)
        if st.overlap_a[i] or st.overlap_b[i]:  # a warning, not a grey value (issue 24)
            ovl, ovl_c = f"⚠ {ovl}: inside an eye", BAD
        bfv = "in BFV" if st.in_bfv[i] else "not in BFV"
        bfv_c = GOOD if st.in_bfv[i] else BAD
        vis, vis_c = f"{vis}, {bfv}", (vis_c if vis_c == bfv_c else "#444444")
        rows = [
            ("r", "r, φ", f"{st.r[i]:.1f}, {st.phi[i] * deg:.2f}°", ink),
            ("rA", "r<sub>A</sub>, φ<sub>A</sub>", f"{st.rA[i]:.1f}, {st.phiA[i] * deg:.2f}°", ink),
            ("rB", "r<sub>B</sub>, φ<sub>B</sub>", f"{st.rB[i]:.1f}, {st.phiB[i] * deg:.2f}°", ink),
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
        self._set(rows, f"g = {f.g:g}")

    def _prediction_rows(self, i: int) -> list[tuple[str, str, str, str]]:
        from eyeviz.model.frame_parts import errors
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
        r, phi = st.r, st.phi
        assert r is not None and phi is not None  # refresh's readout arrays
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
            dr, pct, dphi = errors(float(r[i]), float(phi[i]), r_hat, phi_hat)
            # compact: each line fits the narrowest side panel with a 4-digit error (issue 24)
            rd = 1 if abs(r_hat) < 1000 else 0  # a decimal fewer from four digits on
            dd = 1 if abs(dr) < 1000 else 0
            text = (
                f"r {r_hat:.{rd}f}  Δr {dr:+.{dd}f} ({pct:+.1f} %)\n"
                f"φ {math.degrees(phi_hat):.2f}°  Δφ {dphi:+.3f}°"
            )
            out = range_note(self.model, name, float(r[i]), float(f_g(sc, i)))
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
