"""What every panel shares: user-facing messages (one line, no local paths, no
Python names), word-wrapped labels that never widen their panel, tab names in full."""

from __future__ import annotations

import re

from PyQt5 import QtCore, QtWidgets

ERROR_STYLE = "color: #b00020; font-weight: bold;"
# an absolute path (not one written ~/..., nor a relative one such as eyeviz/assets/...: those name
# no local user and are kept whole, e.g. the folders an estimator searched)
_PATH = re.compile(r"(?<![~\w.])(?:[A-Za-z]:)?(?:[\\/][^\s\\/:'\"()\[\],]+){2,}[\\/]?")
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


#: The most of the screen's height a :class:`LinesLabel`'s lines may need.
LINES_SCREEN_SHARE = 0.1


class LinesLabel(QtWidgets.QLabel):
    """A label of ``lines`` lines, each elided ("…") to the panel's width instead of wrapped
    onto more; it asks for its lines' height whatever its text (a new text moves nothing).
    Where its lines would take over :data:`LINES_SCREEN_SHARE` of the screen's height
    (large text on a small screen) it needs none: it gives way first in a short panel and
    shows the lines that fit (F11 + F5 + 175 % in 1280 x 720: the 3D Facets panel's two
    counts lines wrapped onto four, and its minimum made the window 824 px tall, the status
    bar off the screen). The whole text is in the tooltip. ``wrap``: the text is wrapped
    instead, onto the lines there are room for (the Facets panel's hover line: its two
    lines, 114 px at that size, left the Balls table no row in step 8)."""

    def __init__(self, lines: int, text: str = "", wrap: bool = False) -> None:
        super().__init__()
        self._full, self._lines = "", lines
        self._forms: list[tuple[str, ...]] = []
        self.setWordWrap(wrap)
        self.setSizePolicy(QtWidgets.QSizePolicy.Ignored, QtWidgets.QSizePolicy.Maximum)
        self.setMinimumSize(0, 0)
        self.setAlignment(QtCore.Qt.AlignmentFlag.AlignTop)  # and left
        self.setText(text)

    def text(self) -> str:
        """The whole text (the shown one may be elided or lack its last lines)."""
        return self._full

    def setText(self, text: str | None) -> None:  # noqa: N802 (Qt name)
        self.set_lines([(line,) for line in (text or "").split("\n")] if text else [])

    def set_lines(self, lines: list[tuple[str, ...]]) -> None:
        """Each line in the first of its forms that fits the width (the last one elided):
        the Facets panel's "lit: A 15, B 15; 'target' outlined" was "lit: A 15, B 15;
        'targ…" at F11 + F5 + 175 % in 1280 x 720, where "lit: A 15, B 15" fits whole.
        :meth:`text` is the lines' first forms."""
        self._forms = [tuple(f) for f in lines if f]
        self._full = "\n".join(f[0] for f in self._forms)
        self.setToolTip(self._full)
        self._elide()

    def _height(self, lines: int) -> int:
        return lines * self.fontMetrics().lineSpacing() + 2 * self.margin() + 4 if lines else 0

    def sizeHint(self) -> QtCore.QSize:  # noqa: N802 (Qt name)
        return QtCore.QSize(0, self._height(self._lines))

    def minimumSizeHint(self) -> QtCore.QSize:  # noqa: N802 (Qt name)
        screen = self.screen() or QtWidgets.QApplication.primaryScreen()
        h = self._height(self._lines)
        tall = screen is not None and h > LINES_SCREEN_SHARE * screen.availableGeometry().height()
        return QtCore.QSize(0, 0 if tall else h)

    def hasHeightForWidth(self) -> bool:  # noqa: N802 (Qt name)
        return False  # wrapped too: its lines' height, not its text's

    def resizeEvent(self, ev) -> None:  # noqa: N802 (Qt name)
        super().resizeEvent(ev)
        self._elide()

    def changeEvent(self, ev) -> None:  # noqa: N802 (Qt name)
        super().changeEvent(ev)
        if ev.type() == QtCore.QEvent.Type.FontChange:
            self._elide()
            self.updateGeometry()

    def _elide(self) -> None:
        if self.wordWrap():
            super().setText(self._full)
            return
        fm, width = self.fontMetrics(), max(self.contentsRect().width(), 1)
        lines = list(self._forms)
        while lines and self._height(len(lines)) > self.height():  # the last lines give way
            lines.pop()
        mode = QtCore.Qt.TextElideMode.ElideRight

        def fit(forms: tuple[str, ...]) -> str:
            text = next((f for f in forms if fm.horizontalAdvance(f) <= width), forms[-1])
            return fm.elidedText(text, mode, width)

        super().setText("\n".join(fit(f) for f in lines))


def unelide_tabs(widget: QtWidgets.QWidget) -> None:
    """Tab names of the window's tabbed docks in full (scroll buttons when they do not all
    fit) instead of "Fe…", "E…"."""
    win = widget.window()
    assert win is not None  # a widget's window is itself at worst
    for bar in win.findChildren(QtWidgets.QTabBar):
        if bar.elideMode() != QtCore.Qt.TextElideMode.ElideNone:
            bar.setElideMode(QtCore.Qt.TextElideMode.ElideNone)
            bar.setUsesScrollButtons(True)


class _Unelide(QtCore.QObject):
    """Re-applies :func:`unelide_tabs` whenever a tabbed dock appears or is re-tabbed."""

    def eventFilter(self, obj, ev) -> bool:  # noqa: N802 (Qt name)
        if ev.type() in (QtCore.QEvent.Type.Show, QtCore.QEvent.Type.ParentChange):
            unelide_tabs(obj)
        return False


def set_message(label: QtWidgets.QLabel, text: str) -> None:
    """Show ``text`` (several lines allowed) in a :func:`wrap_label`, tooltip = full text."""
    lines = [user_message(t, 400) for t in str(text).splitlines() if t.strip()]
    full = "\n".join(lines)
    if label.text() != full:
        label.setText(full)
        label.setToolTip(full)


def estimator_help(name: str) -> str:
    """The registry's one-line help of estimator ``name`` (one place for names and help:
    :mod:`eyeviz.estimators.registry`); "" for a name the registry does not know."""
    from eyeviz import EyevizError
    from eyeviz.estimators import registry

    try:
        return registry.get(name).help
    except EyevizError:  # an uninstalled or unregistered name: no help, never a crash
        return ""


def text_scale() -> float:
    """The window's text scale now (View > Larger text, presentation mode): the app font's
    size over its size at scale 1 (eyeviz.app.presenting sets the app font)."""
    from eyeviz.app.launch import APP_FONT_PT

    app = QtWidgets.QApplication.instance()
    pt = app.font().pointSizeF() if isinstance(app, QtWidgets.QApplication) else -1.0
    return pt / APP_FONT_PT if pt > 0 else 1.0


def follows_text_scale(ev: QtCore.QEvent | None) -> bool:
    """Whether ``ev`` may change the text scale (the app's font changed)."""
    return ev is not None and ev.type() in (
        QtCore.QEvent.Type.FontChange,
        QtCore.QEvent.Type.ApplicationFontChange,
    )
