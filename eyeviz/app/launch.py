"""Starting the app: the display check and the QApplication (``eyeviz.app.main`` runs it)."""

from __future__ import annotations

import ctypes
import ctypes.util
import os

from PyQt5 import QtCore, QtWidgets

from eyeviz import EyevizError
from eyeviz.core import kernels

__all__ = ["APP_FONT_PT", "check_display", "make_app", "warm_kernels"]

APP_FONT_PT = 13
_HELD: dict[str, int] = {}  # the connection check_display keeps per display (see there)


def check_display() -> None:
    """EyevizError (one line) when no display can be reached, before Qt aborts the process.

    An X display named in $DISPLAY is opened with Xlib itself (and kept open): a stale
    DISPLAY (a closed ssh -X session, a stopped Xvfb) becomes a message, not Qt's
    "could not connect to display ... Reinstalling the application may fix this problem".
    """
    display = os.environ.get("DISPLAY")
    if not display and not os.environ.get("WAYLAND_DISPLAY"):
        raise EyevizError(
            "no display: run under `xvfb-run -a eyeviz app --screenshot OUT.png` "
            "or use scripts/run.sh"
        )
    if not display or os.environ.get("QT_QPA_PLATFORM", "xcb") not in ("xcb", ""):
        return
    if display in _HELD:
        return  # checked, and its connection kept (one a display, not one a call)
    lib = ctypes.util.find_library("X11")
    if lib is None:
        return  # cannot check without Xlib; Qt will try
    x11 = ctypes.CDLL(lib)
    x11.XOpenDisplay.restype = ctypes.c_void_p
    x11.XOpenDisplay.argtypes = [ctypes.c_char_p]
    x11.XCloseDisplay.argtypes = [ctypes.c_void_p]
    dpy = x11.XOpenDisplay(display.encode())
    if not dpy:
        raise EyevizError(
            f"cannot connect to the X display {display!r} (stale DISPLAY?): "
            "unset it and use `xvfb-run -a eyeviz app --screenshot OUT.png`, or fix DISPLAY"
        )
    # kept open while the process lives: closing the only client of a fresh Xvfb (as
    # `xvfb-run eyeviz app` starts one) resets the server, and Qt's own connection a
    # moment later could meet the reset ("could not connect to display", SIGABRT: 1 run
    # in 16-40 here, issue 32.14's benches)
    _HELD[display] = dpy


def make_app(warm: bool = True) -> QtWidgets.QApplication:
    """The QApplication, set up for the view. ``warm``: start loading the compiled kernels
    on a background thread now; else they wait for :func:`warm_kernels` (``eyeviz app``
    starts them once the window is up: loading numba beside the window's own imports and
    first frames held the GIL and made the start 1-2 s slower, issue 32.14). Either way,
    until they are ready the core answers with its numpy reference."""
    app = QtWidgets.QApplication.instance()
    if app is None:
        QtWidgets.QApplication.setAttribute(QtCore.Qt.ApplicationAttribute.AA_ShareOpenGLContexts)
        app = QtWidgets.QApplication(["eyeviz"])
    assert isinstance(app, QtWidgets.QApplication)  # a widgets app, never a bare QCoreApplication
    # the view is a native X window (VTK renders into it); without this Qt makes every
    # sibling on its way up native too (docks, status bar, bitmaps panel, menu bar), and a
    # drag frame then flushed each repainted panel to X on its own (issue 12, drag latency)
    app.setAttribute(QtCore.Qt.ApplicationAttribute.AA_DontCreateNativeWidgetSiblings)
    font = app.font()
    font.setPointSize(APP_FONT_PT)
    app.setFont(font)
    # the compiled kernels load (or compile) on a background thread; until they are
    # ready the core answers with its numpy reference, so no drag waits for numba
    kernels.defer_until_warm()
    if warm:
        kernels.warm_in_background()
    return app


def warm_kernels() -> None:
    """Start loading the compiled kernels on a background thread (see :func:`make_app`)."""
    kernels.warm_in_background()
