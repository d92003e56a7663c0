"""Real X input into the app's real window, shared by the scripts that drive it
(lecture_screenshots.py) and the GUI tests (tests/app: mouse.py, screen_probe.py and the
real-key tests): a small window manager (openbox; a bare Xvfb has none, and full screen is
its job), the X keyboard focus, real key presses (xdotool) and waiting for the window.

It lives under scripts/ rather than in eyeviz/: it drives the window from outside, as a
lecturer's keyboard does, with two system tools (openbox, xdotool) that the app itself
never needs; the tests put this folder on their import path (tests/app/conftest.py), and
a script finds it beside itself.
"""

from __future__ import annotations

import shutil
import subprocess
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

__all__ = ["key", "start_window_manager", "stop_window_manager", "wait", "x_focus"]


def start_window_manager(tmp: Path) -> subprocess.Popen | None:
    """openbox on this display, started now; its --startup command (a file in ``tmp``)
    says when it is ready. None when it exited at once: another window manager runs (a
    desktop), and that one is used. openbox missing: SystemExit with how to get it; not
    ready in 10 s: RuntimeError."""
    if shutil.which("openbox") is None:
        raise SystemExit("openbox is needed (apt-get install openbox; scripts/setup.sh)")
    ready = Path(tmp) / "wm_ready"
    proc = subprocess.Popen(
        ["openbox", "--sm-disable", "--startup", f"touch {ready}"],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    for _ in range(200):
        if ready.exists() or proc.poll() is not None:
            break
        time.sleep(0.05)
    if proc.poll() is not None:
        return None  # exited at once: another window manager runs on this display
    if not ready.exists():
        stop_window_manager(proc)
        raise RuntimeError("openbox did not start in 10 s")
    return proc


def stop_window_manager(proc: subprocess.Popen | None) -> None:
    """End the window manager :func:`start_window_manager` started (None: nothing)."""
    if proc is not None and proc.poll() is None:
        proc.terminate()
        proc.wait(10)


def wait(app: Any, until: Callable[[], bool], timeout: float = 10.0) -> None:
    """Run the app's events until ``until()`` holds (at most ``timeout`` s), then a few
    rounds more (a layout or a frame it set off)."""
    end = time.monotonic() + timeout
    while not until() and time.monotonic() < end:
        app.processEvents()
        time.sleep(0.02)
    for _ in range(10):
        app.processEvents()
        time.sleep(0.02)


def x_focus(win: Any, widget: Any = None, timeout: float = 5.0) -> None:
    """Give ``win`` the X keyboard focus (xdotool's key presses go there) and ``widget``
    Qt's. Retried while X refuses: setting the focus on a window that is not viewable yet
    fails with BadMatch, and a loaded machine (or a window manager) maps windows late."""
    from PyQt5 import QtWidgets

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


def key(app: Any, win: Any, keys: str, until: Callable[[], bool], timeout: float = 10.0) -> None:
    """Focus ``win`` (:func:`x_focus`), press ``keys`` (xdotool's names, e.g. "F11",
    "ctrl+equal", "Next") and wait until ``until()`` holds (:func:`wait`)."""
    x_focus(win)
    subprocess.run(["xdotool", "key", "--delay", "40", keys], check=True)
    wait(app, until, timeout)
