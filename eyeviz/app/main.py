"""Start the app: open a scene in the main window, or render it to a screenshot and exit.

Kept apart from :mod:`eyeviz.app.launch` (the QApplication and the display check, which
the window uses) so that no module of the app imports the window from inside a function.
"""

from __future__ import annotations

import os

from PyQt5 import QtCore

from eyeviz.app.launch import check_display, make_app, warm_kernels
from eyeviz.app.screenshot import screenshot_format
from eyeviz.app.settings import make_settings
from eyeviz.app.window import MainWindow
from eyeviz.model.draw_bounds import check_drawable_eyes
from eyeviz.model.scene import load
from eyeviz.resources import scene_path as scene_path_of

__all__ = ["run_app"]


def run_app(
    scene_path: str | os.PathLike | None = None,
    screenshot: str | os.PathLike | None = None,
    settings_path: str | os.PathLike | None = None,
) -> int:
    if screenshot is not None:
        screenshot_format(screenshot)  # refuse a wrong suffix before any window opens
    if scene_path is None:
        scene_path = scene_path_of("default")
    scene = load(scene_path)
    check_drawable_eyes(scene, "app")  # one line before any window (issue 36)
    check_display()
    settings = make_settings(settings_path)
    # a screenshot reads the saved window state but never changes it (nor recent files)
    settings.read_only = screenshot is not None
    app = make_app(warm=False)  # the kernels load once the window is up (below)
    win = MainWindow(scene, scene_path, settings=settings)
    if settings.refused:
        win.statusBar().showMessage(settings.refused, 15000)
    win.show()
    app.processEvents()
    win.fit_inset()
    win.frame_bundled()
    win.render()
    if screenshot is not None:
        win.jobs.wait()  # estimators loading: the picture shows their answers
        for _ in range(3):
            app.processEvents()
        out = win.save_screenshot(screenshot)
        print(out)
        win.force_close()
        return 0  # a screenshot never loads them: the reference drew it
    QtCore.QTimer.singleShot(0, warm_kernels)  # the first event after the first frame
    return app.exec_()
