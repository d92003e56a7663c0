"""Presenting with eyeviz in a lecture hall: full screen, text scale, presentation mode,
the list of panels, the lecture steps' keys and the Help menu.

- View > Full screen (F11): the window fills the screen (the window manager's full-screen
  state); again to leave.
- View > Larger text / Smaller text / Normal text (Ctrl+= / Ctrl+- / Ctrl+0): the whole
  UI's text and the view's labels are scaled; the scale is kept in the settings
  (``ui/text_scale``) and restored at the next start.
- View > Presentation mode (F5): side panels hidden, text PRESENT_FACTOR larger, a
  high-contrast palette; again to leave (the panels come back as they were).
- View > Panels: every dock's show/hide entry, so a closed panel comes back.
- View > Steps: PageDown / PageUp / Esc walk a scene's lecture steps (eyeviz.app.steps).
- Help > Keyboard shortcuts (F1), Help > About the model (eyeviz.app.help).
"""

from __future__ import annotations

import math
from typing import Any

from PyQt5 import QtCore, QtGui, QtWidgets

from eyeviz.app.help import SPHERICAL_SECTION, AboutModelDialog, ShortcutsDialog
from eyeviz.app.launch import APP_FONT_PT

#: the main window (eyeviz.app.window.MainWindow; not imported: the window imports this)
MainWindow = Any

__all__ = [
    "PRESENT_FACTOR",
    "SCALE_KEY",
    "TEXT_SCALES",
    "Presenter",
    "high_contrast_palette",
    "install_presenting",
    "step_scale",
]

TEXT_SCALES = (0.8, 0.9, 1.0, 1.15, 1.3, 1.5, 1.75, 2.0, 2.5, 3.0)
PRESENT_FACTOR = 1.5
SCALE_KEY = "ui/text_scale"
_BASE_PT = "eyeviz_base_pt"  # a widget's own font size at text scale 1 (a Qt property)


def step_scale(scale: float, direction: int) -> float:
    """The next text scale up (+1) or down (-1) from ``scale``; 0 gives 1.0."""
    if direction == 0:
        return 1.0
    if direction > 0:
        return next((s for s in TEXT_SCALES if s > scale + 1e-9), TEXT_SCALES[-1])
    return next((s for s in reversed(TEXT_SCALES) if s < scale - 1e-9), TEXT_SCALES[0])


def _stored_scale(value: Any) -> float:
    """A stored scale within TEXT_SCALES' range; anything else (a hand-edited settings
    file) is 1.0."""
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        return 1.0
    return float(value) if TEXT_SCALES[0] <= value <= TEXT_SCALES[-1] else 1.0


def high_contrast_palette() -> QtGui.QPalette:
    """Black on white, a saturated blue selection: readable from the back of a hall."""
    pal = QtGui.QPalette()
    white, black = QtGui.QColor("#ffffff"), QtGui.QColor("#000000")
    for role, color in (
        (QtGui.QPalette.Window, white),
        (QtGui.QPalette.WindowText, black),
        (QtGui.QPalette.Base, white),
        (QtGui.QPalette.AlternateBase, QtGui.QColor("#eeeeee")),
        (QtGui.QPalette.Text, black),
        (QtGui.QPalette.Button, QtGui.QColor("#e6e6e6")),
        (QtGui.QPalette.ButtonText, black),
        (QtGui.QPalette.ToolTipBase, white),
        (QtGui.QPalette.ToolTipText, black),
        (QtGui.QPalette.Highlight, QtGui.QColor("#0033cc")),
        (QtGui.QPalette.HighlightedText, white),
    ):
        pal.setColor(role, color)
    grey = QtGui.QColor("#8a8a8a")  # a disabled entry must look disabled (issue 32)
    for role in (QtGui.QPalette.WindowText, QtGui.QPalette.Text, QtGui.QPalette.ButtonText):
        pal.setColor(QtGui.QPalette.Disabled, role, grey)
    return pal


def _app() -> QtWidgets.QApplication:
    app = QtWidgets.QApplication.instance()
    assert isinstance(app, QtWidgets.QApplication)  # the window exists: so does the app
    return app


def _action(win, menu, text, slot, keys=(), checkable=False) -> QtWidgets.QAction:
    a = QtWidgets.QAction(text, win)
    if keys:
        a.setShortcuts([QtGui.QKeySequence(k) for k in keys])
        a.setShortcutContext(QtCore.Qt.ShortcutContext.WindowShortcut)
    a.setCheckable(checkable)
    a.triggered.connect(slot)
    menu.addAction(a)
    win.addAction(a)
    return a


class Presenter(QtCore.QObject):
    """The window's presenting state and actions (made by :func:`install_presenting`)."""

    def __init__(self, win: MainWindow) -> None:
        super().__init__(win)
        self.win = win
        self.scale = _stored_scale(win.settings.value(SCALE_KEY, 1.0))
        self.presenting = False
        self._applied = 1.0  # the effective scale the widgets and labels have now
        self._hidden_docks: list[QtWidgets.QDockWidget] = []
        self._raised: list[QtWidgets.QDockWidget] = []  # tabs on top before F5
        self._step_shown: list[QtWidgets.QDockWidget] = []  # shown in F5 for a step
        self._palette = _app().palette()
        self._vtk_base: dict[Any, tuple[float, int]] = {}  # actor -> (size at 1, size set)
        self.shortcuts_dialog: ShortcutsDialog | None = None
        self.about_dialog: AboutModelDialog | None = None
        self._build_menus()
        win.installEventFilter(self)
        win.model.listeners.append(self._on_model)
        self._remember_fonts(1.0)  # the widgets made so far are at scale 1
        self.apply()

    # --- menus -------------------------------------------------------------------------
    def _build_menus(self) -> None:
        win = self.win
        mb = win.menuBar()
        assert mb is not None  # a QMainWindow makes its menu bar on first use
        view = next(
            (a.menu() for a in mb.actions() if a.text().replace("&", "") == "View"), None
        ) or mb.addMenu("&View")
        assert view is not None
        view.addSeparator()
        self.fullscreen_action = _action(
            win, view, "F&ull screen", self.toggle_fullscreen, ("F11",), checkable=True
        )
        self.present_action = _action(
            win, view, "P&resentation mode", self.toggle_presentation, ("F5",), checkable=True
        )
        _action(win, view, "&Larger text", lambda: self.set_scale(step_scale(self.scale, 1)),
                ("Ctrl+=", "Ctrl++"))  # fmt: skip
        _action(win, view, "&Smaller text", lambda: self.set_scale(step_scale(self.scale, -1)),
                ("Ctrl+-",))  # fmt: skip
        _action(win, view, "N&ormal text", lambda: self.set_scale(1.0), ("Ctrl+0",))
        self.panels_menu = view.addMenu("Pa&nels")
        assert self.panels_menu is not None
        # filled as the View menu opens: a submenu filled in its own aboutToShow opened
        # from the keyboard with no entry active and ignored the arrow keys
        view.aboutToShow.connect(self.fill_panels_menu)
        steps = view.addMenu("St&eps")
        assert steps is not None
        _action(win, steps, "&Next step", win.next_step, ("PgDown",))
        _action(win, steps, "&Previous step", win.previous_step, ("PgUp",))
        win.leave_steps_action = _action(
            win, steps, "Show the &whole scene", win.leave_steps, ("Esc",)
        )
        win.leave_steps_action.setEnabled(False)
        help_menu = mb.addMenu("&Help")
        assert help_menu is not None
        _action(win, help_menu, "&Keyboard shortcuts", self.show_shortcuts, ("F1",))
        _action(win, help_menu, "&About the model", self.show_about)

    def fill_panels_menu(self) -> None:
        """Every dock's show/hide entry, docks made since included."""
        menu = self.panels_menu
        assert menu is not None
        menu.clear()
        for d in sorted(self.page_docks(), key=lambda d: d.windowTitle()):
            a = d.toggleViewAction()
            assert a is not None  # every dock has one
            menu.addAction(a)

    def page_docks(self) -> list[QtWidgets.QDockWidget]:
        """The docks of the page shown: the 3D view's in a spherical scene, else the
        planar window's (each page's docks are hidden while the other page is shown)."""
        host = getattr(self.win, "host3d", None)
        own = list(host.docks.values()) if host is not None else []
        if host is not None and host.active:
            return own
        return [d for d in self.win.findChildren(QtWidgets.QDockWidget) if d not in own]

    # --- help ----------------------------------------------------------------------------
    def show_shortcuts(self) -> ShortcutsDialog:
        if self.shortcuts_dialog is None:
            self.shortcuts_dialog = ShortcutsDialog(self.win)
        self.shortcuts_dialog.refresh()
        self.shortcuts_dialog.show()
        self.shortcuts_dialog.raise_()
        self.shortcuts_dialog.activateWindow()
        return self.shortcuts_dialog

    def show_about(self) -> AboutModelDialog:
        if self.about_dialog is None:
            self.about_dialog = AboutModelDialog(self.win)
        host = getattr(self.win, "host3d", None)
        spherical = host is not None and host.active
        section = SPHERICAL_SECTION if spherical else None
        self.about_dialog.show()
        self.about_dialog.show_section(section)
        dlg = self.about_dialog  # again once laid out (its first layout moves the text)
        QtCore.QTimer.singleShot(0, lambda: dlg.show_section(section))
        self.about_dialog.raise_()
        self.about_dialog.activateWindow()
        return self.about_dialog

    # --- full screen ---------------------------------------------------------------------
    def toggle_fullscreen(self) -> None:
        win = self.win
        if win.isFullScreen():
            win.showNormal()
        else:
            win.showFullScreen()

    def eventFilter(self, obj, ev) -> bool:  # noqa: N802 (Qt name)
        t = ev.type()
        if t == QtCore.QEvent.Type.WindowStateChange:
            self.fullscreen_action.setChecked(self.win.isFullScreen())
        elif t == QtCore.QEvent.Type.Hide and not ev.spontaneous():
            self._restore_app()  # closed: other windows get the app's own font and palette
        elif t == QtCore.QEvent.Type.Show and not ev.spontaneous():
            self.apply(render=False)  # the views' first paints, which follow, render
        return False

    # --- text scale ----------------------------------------------------------------------
    @property
    def effective_scale(self) -> float:
        return self.scale * (PRESENT_FACTOR if self.presenting else 1.0)

    def set_scale(self, scale: float) -> None:
        """Ctrl+= / Ctrl+- / Ctrl+0: scale the UI's text and the view's labels; kept."""
        self.scale = scale
        self.win.settings.setValue(SCALE_KEY, scale)
        self.win.settings.sync()
        self.apply()
        self.win.statusBar().showMessage(f"text {round(scale * 100)} %", 3000)

    def _remember_fonts(self, eff: float) -> None:
        for w in self.win.findChildren(QtWidgets.QWidget):
            if (
                w.testAttribute(QtCore.Qt.WidgetAttribute.WA_SetFont)
                and w.property(_BASE_PT) is None
            ):
                w.setProperty(_BASE_PT, w.font().pointSizeF() / eff)

    def apply(self, render: bool = True) -> None:
        """Give the app, the window's own-font widgets and the view's text the effective
        scale (a widget that set its own font keeps its size relative to the rest), and
        render the views (``render``; not when the window is being shown: its paints do)."""
        eff = self.effective_scale
        self._remember_fonts(self._applied)  # widgets made since the last apply
        app = _app()
        f = QtGui.QFont(app.font())
        f.setPointSizeF(APP_FONT_PT * eff)
        app.setFont(f)
        for w in self.win.findChildren(QtWidgets.QWidget):
            base = w.property(_BASE_PT)
            if isinstance(base, float) and base > 0:
                wf = w.font()
                wf.setPointSizeF(base * eff)
                w.setFont(wf)
        self._applied = eff
        app.setPalette(high_contrast_palette() if self.presenting else self._palette)
        label = self.win.cursor_label
        fm = QtGui.QFontMetrics(f)
        label.setFixedSize(
            fm.horizontalAdvance("x -00,000.0   y -00,000.0     r 00,000.0   φ 000.00°  "),
            fm.height() + 4,
        )
        self._scale_view_text()
        self.win.fit_caption()
        if self.win.isVisible():
            QtCore.QTimer.singleShot(0, self.win.fit_readout)  # its values at the new size
            if render:  # else the view's first paint renders (its live changes applied)
                self.win.render()
            host = getattr(self.win, "host3d", None)
            if host is not None and host.active:
                if render:
                    host.draw()
                else:  # the actors brought up to the model; its view's paint renders
                    host.flush()
                QtCore.QTimer.singleShot(0, host.fit_docks)  # the readout's wider text

    def _vtk_texts(self):
        """The text actors of the planar view and, once built, of the 3D view."""
        wins = [self.win.ren_win]
        host = getattr(self.win, "host3d", None)
        if host is not None and host.view is not None:
            wins.append(host.view.ren_win)
        for ren_win in wins:
            rens = ren_win.GetRenderers()
            rens.InitTraversal()
            for _ in range(rens.GetNumberOfItems()):
                ren = rens.GetNextItem()
                props = ren.GetViewProps()
                props.InitTraversal()
                for _ in range(props.GetNumberOfItems()):
                    p = props.GetNextProp()
                    if hasattr(p, "GetTextProperty"):
                        yield p

    def rescale_view(self) -> None:
        """Labels made since the last scaling (a new scene or step in the 3D view) at the
        effective scale; called by the 3D view before it draws a new scene."""
        if self._applied != 1.0:
            self._scale_view_text()

    def _scale_view_text(self) -> None:
        """The view's labels and captions at the effective scale (their own size x it)."""
        eff = self._applied
        for actor in self._vtk_texts():
            tp = actor.GetTextProperty()
            base, last = self._vtk_base.get(actor, (0.0, -1))
            if tp.GetFontSize() != last:
                # new, or its layer chose another size since (a long inset line): that
                # is its size at scale 1 (labels are made at scale 1 by style_text)
                base = float(tp.GetFontSize())
            size = max(1, round(base * eff))
            if tp.GetFontSize() != size:
                tp.SetFontSize(size)
            self._vtk_base[actor] = (base, size)

    def _on_model(self, what: str, _index: int | None) -> None:
        if what in ("feature", "view", "player", "selection"):
            return  # no new widgets or labels: the drag path stays as it was
        if self._applied != 1.0:
            self._scale_view_text()
            self._remember_fonts(self._applied)
        if self.presenting:
            QtCore.QTimer.singleShot(0, self._hide_docks)  # a layer that showed its dock

    def _restore_app(self) -> None:
        app = _app()
        f = QtGui.QFont(app.font())
        f.setPointSizeF(APP_FONT_PT)
        app.setFont(f)
        app.setPalette(self._palette)

    # --- presentation mode ---------------------------------------------------------------
    def _hide_docks(self) -> None:
        """Hide the side panels but those the lecture step shown needs (its ``panels``)."""
        keep = self.win.step_docks()
        for d in self.win.findChildren(QtWidgets.QDockWidget):
            if d.isVisible() and d.objectName() not in keep:
                if d not in self._hidden_docks:
                    self._hidden_docks.append(d)
                    if not d.visibleRegion().isEmpty():  # the tab on top of its group
                        self._raised.append(d)
                d.hide()

    def step_panels(self) -> None:
        """A lecture step was shown (or left): in presentation mode, its panels shown and
        the others hidden."""
        if not self.presenting:
            return
        keep = self.win.step_docks()
        for d in self.page_docks():
            if d.objectName() in keep and not d.isVisible():
                d.show()
                d.raise_()
                self._step_shown.append(d)
        self._hide_docks()
        QtCore.QTimer.singleShot(0, self.win.fit_readout)  # shown at the presenting size

    def toggle_presentation(self) -> None:
        """F5: large text, side panels hidden (but those the lecture step shown names),
        high contrast; F5 again restores them, each tab group with the tab it had on top."""
        self.presenting = not self.presenting
        self.present_action.setChecked(self.presenting)
        if self.presenting:
            self._hidden_docks, self._raised, self._step_shown = [], [], []
            self._hide_docks()
            self.step_panels()
        else:
            for d in self._step_shown:
                if d not in self._hidden_docks:
                    d.hide()  # shown for a step only
            for d in self._hidden_docks:
                d.show()
            for d in self._raised:
                d.raise_()
            self._hidden_docks, self._raised, self._step_shown = [], [], []
        self.apply()
        if self.presenting:
            self.win.statusBar().showMessage("F5: leave presentation mode", 6000)


def install_presenting(win: MainWindow) -> Presenter:
    """Add the presenting actions and the Help menu to ``win`` (after its menus)."""
    win.presenter = Presenter(win)
    return win.presenter
