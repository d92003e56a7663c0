"""Screenshots of the whole window, the VTK view composited from its framebuffer."""

from __future__ import annotations

import os
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from PyQt5 import QtCore, QtGui, QtWidgets
from vtkmodules.util.numpy_support import vtk_to_numpy
from vtkmodules.vtkRenderingCore import vtkWindowToImageFilter

from eyeviz import EyevizError
from eyeviz.files.atomic import atomic_output

if TYPE_CHECKING:
    from eyeviz.app.window import MainWindow

__all__ = ["FORMATS", "grab_image", "qimage_to_array", "save_screenshot", "screenshot_format"]

FORMATS = {".png": "PNG", ".jpg": "JPEG", ".jpeg": "JPEG"}


def screenshot_format(path: str | os.PathLike) -> str:
    """Qt's image format for ``path``'s suffix; EyevizError for any other suffix."""
    fmt = FORMATS.get(Path(path).suffix.lower())
    if fmt is None:
        raise EyevizError(
            f"screenshot {str(path)!r}: the file name must end in .png, .jpg or .jpeg"
        )
    return fmt


def grab_image(win: MainWindow) -> QtGui.QImage:
    """The whole window as shown, with the VTK view composited from its framebuffer."""
    QtWidgets.QApplication.processEvents()
    host = win.host3d
    if host.active and host.view is not None:  # a spherical scene: the 3D page's view
        host.draw()
        ren_win, view = host.view.ren_win, host.view
    else:
        win.apply_cameras()
        win.render()
        ren_win, view = win.ren_win, win.plotter
    w2i = vtkWindowToImageFilter()
    w2i.SetInput(ren_win)
    w2i.SetInputBufferTypeToRGB()
    w2i.ReadFrontBufferOff()
    w2i.Update()
    data = w2i.GetOutput()
    vw, vh, _ = data.GetDimensions()
    arr = vtk_to_numpy(data.GetPointData().GetScalars()).reshape(vh, vw, 3)[::-1].copy()
    vtk_img = QtGui.QImage(arr.data, vw, vh, 3 * vw, QtGui.QImage.Format_RGB888).copy()
    # the view's own paint would render once more a frame the line below paints over
    view.grabbing = True
    try:
        img = win.grab().toImage().convertToFormat(QtGui.QImage.Format_RGB888)
    finally:
        view.grabbing = False
    p = QtGui.QPainter(img)
    top_left = view.mapTo(win, QtCore.QPoint(0, 0))
    p.drawImage(QtCore.QRect(top_left, view.size()), vtk_img)
    p.end()
    return img


def save_screenshot(win: MainWindow, path: str | os.PathLike) -> Path:
    """Write the window as PNG or JPEG (by the suffix), atomically."""
    path = Path(path)
    fmt = screenshot_format(path)
    img = grab_image(win)
    with atomic_output(path) as tmp:
        if not img.save(str(tmp), fmt, 95 if fmt == "JPEG" else -1):
            raise OSError(f"cannot write {path}")
    return path


def qimage_to_array(img: QtGui.QImage) -> np.ndarray:
    img = img.convertToFormat(QtGui.QImage.Format_RGB888)
    w, h = img.width(), img.height()
    ptr = img.constBits()
    assert ptr is not None  # None only for a null image
    ptr.setsize(img.byteCount())
    return (
        np.frombuffer(ptr, np.uint8)  # type: ignore[call-overload]  # voidptr is a buffer
        .reshape(h, img.bytesPerLine())[:, : 3 * w]
        .reshape(h, w, 3)
        .copy()
    )
