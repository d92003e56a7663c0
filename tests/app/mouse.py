"""Real input on the app's windows (shared by the app tests): mouse drags in model
coordinates, and the X keyboard focus that real key presses (xdotool) go to."""

import subprocess
import time

import vtk
from PyQt5 import QtCore, QtGui, QtWidgets
from PyQt5.QtTest import QTest

from eyeviz.render.vtk.style import Z_FEAT


def pixel_of(win, x, y):
    """Model -> Qt widget pixel through VTK's own camera transform (not the app's maths),
    once pending events have run: a layout change still queued (a status line, a dock's
    size) would move the view after its pixel was read, and the press land beside it."""
    QtWidgets.QApplication.processEvents()
    c = vtk.vtkCoordinate()
    c.SetCoordinateSystemToWorld()
    c.SetValue(x, y, Z_FEAT)
    dx, dy = c.GetComputedDoubleDisplayValue(win.main_ren)
    h = win.ren_win.GetSize()[1]
    return QtCore.QPoint(round(dx), round(h - dy))


def move(widget, pos, buttons=QtCore.Qt.LeftButton, modifiers=QtCore.Qt.NoModifier):
    """A mouse move at ``pos`` (widget pixels) with ``buttons`` held, delivered now, then
    pending events run.

    Not ``QTest.mouseMove``: on a QWidget, Qt 5 warps the X pointer instead, and the move
    reaches the app when the X server sends it back, without the button held. On a loaded
    machine that was after the release had ended the drag, and the drag moved nothing."""
    ev = QtGui.QMouseEvent(
        QtCore.QEvent.MouseMove,
        QtCore.QPointF(pos),
        QtCore.QPointF(widget.mapToGlobal(pos)),
        QtCore.Qt.NoButton,
        buttons,
        modifiers,
    )
    QtWidgets.QApplication.sendEvent(widget, ev)
    QtWidgets.QApplication.processEvents()  # as QTest does: a frame it asked for may draw


def drag(win, start, end, steps=12):
    """Left press at ``start``, ``steps`` moves to ``end``, release."""
    w = win.plotter
    QTest.mousePress(w, QtCore.Qt.LeftButton, QtCore.Qt.NoModifier, start)
    for k in range(1, steps + 1):
        move(w, start + (end - start) * (k / steps))
    QTest.mouseRelease(w, QtCore.Qt.LeftButton, QtCore.Qt.NoModifier, end)


def x_focus(win, widget=None, timeout=5.0):
    """Give ``win`` the X keyboard focus (xdotool's key presses go there) and ``widget``
    Qt's. Retried while X refuses: setting the focus on a window that is not viewable yet
    fails with BadMatch, and a loaded machine (or a window manager) maps windows late."""
    win.activateWindow()
    win.raise_()
    if widget is not None:
        widget.setFocus()
    deadline = time.monotonic() + timeout
    cmd = ["xdotool", "windowfocus", "--sync", str(int(win.winId()))]
    while (r := subprocess.run(cmd, capture_output=True, text=True)).returncode != 0:
        if time.monotonic() > deadline:
            raise AssertionError(f"xdotool could not focus the window: {r.stderr.strip()}")
        QtWidgets.QApplication.processEvents()
        time.sleep(0.05)
    while widget is not None and not widget.hasFocus():
        if time.monotonic() > deadline:
            raise AssertionError(f"{type(widget).__name__} did not take the keyboard focus")
        QtWidgets.QApplication.processEvents()
        time.sleep(0.02)
