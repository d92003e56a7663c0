"""The 3D page's status line: the selected ball's name, coordinates and facets lit, in
the first of its forms that fits the status bar (at F11 + F5 + 175 % in 1280 x 720 the
whole one was cut at "facets lit A 15  B"), re-fitted when the bar's width or font
changes (issue 32)."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from PyQt5 import QtCore, QtWidgets

__all__ = ["StatusLine", "ball_status"]


def ball_status(model: Any) -> list[str]:
    """The selected ball's status line of ``model`` (an AppModel3D, or None), longest
    form first: with its coordinates and facets lit, its coordinates, its facets lit,
    its name; [""] without a selected ball."""
    m = model
    if m is None or m.selected is None or m.selected >= len(m.scene.features):
        return [""]
    st, i = m.state, m.selected
    f = m.scene.features[i]
    where = f"{f.name}: x {f.x:,.1f}  y {f.y:,.1f}  z {f.z:,.1f}  g {f.g:,.1f}"
    if st.facets_a is None or st.facets_b is None:
        return [where, f.name]
    lit = f"facets lit A {int(st.facets_a[i]):,}  B {int(st.facets_b[i]):,}"
    return [f"{where}   {lit}", where, f"{f.name}: {lit}", f.name]


class StatusLine(QtCore.QObject):
    """Shows ``forms()``'s first form that fits ``win``'s status bar; re-fits the line it
    showed (not another message: "text 175 %", a job's) when the bar's width or font
    changes while ``active()``."""

    def __init__(
        self,
        win: QtWidgets.QMainWindow,
        forms: Callable[[], list[str]],
        active: Callable[[], bool],
    ) -> None:
        super().__init__(win)
        self._win, self._forms, self._active = win, forms, active
        self.shown: str | None = None  # the line this showed last
        bar = win.statusBar()
        assert bar is not None  # a main window makes its status bar on demand
        bar.installEventFilter(self)

    def show(self) -> None:
        bar = self._win.statusBar()
        assert bar is not None
        forms = self._forms()
        room, fm = bar.width() - 12, bar.fontMetrics()
        self.shown = next((f for f in forms if fm.horizontalAdvance(f) <= room), forms[-1])
        bar.showMessage(self.shown, 0)

    def eventFilter(self, obj, ev) -> bool:  # noqa: N802 (Qt name)
        E = QtCore.QEvent.Type
        if ev.type() in (E.Resize, E.FontChange):
            QtCore.QTimer.singleShot(0, self._refit)
        return False

    def _refit(self) -> None:
        bar = self._win.statusBar()
        if self._active() and bar is not None and bar.currentMessage() == self.shown:
            self.show()
