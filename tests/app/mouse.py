"""Real mouse input on the app's view, in model coordinates (shared by the app tests)."""

import vtk
from PyQt5 import QtCore, QtWidgets
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


def drag(win, start, end, steps=12):
    """Left press at ``start``, ``steps`` moves to ``end``, release."""
    w = win.plotter
    QTest.mousePress(w, QtCore.Qt.LeftButton, QtCore.Qt.NoModifier, start)
    for k in range(1, steps + 1):
        QTest.mouseMove(w, start + (end - start) * (k / steps))
    QTest.mouseRelease(w, QtCore.Qt.LeftButton, QtCore.Qt.NoModifier, end)
