"""Real input on the app's windows (shared by the app tests): mouse drags in model
coordinates, and the X keyboard focus that real key presses (xdotool) go to."""

import vtk
from PyQt5 import QtCore, QtGui, QtWidgets
from PyQt5.QtTest import QTest

# the X keyboard focus: shared with the scripts that drive the window (scripts/real_x.py,
# on the import path by conftest.py)
from real_x import x_focus  # noqa: E402, F401

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
