"""Run by test_screen_fit.py under an X screen of its own (xvfb-run, 1280 x 720): the real
window, 1280 x 720 under a window manager (openbox), through every step of a lecture
scene with real keys (xdotool), at each text scale and mode asked for; prints one JSON
line per step: the status bar's bottom, the screen's free area's bottom, the window's
frame and its minimum height.

    python tests/app/screen_probe.py sphere_lecture 1.0:0 1.75:1   (scale:presenting)
"""

from __future__ import annotations

import json
import sys
import tempfile
from pathlib import Path

# the real-X helpers shared with scripts/lecture_screenshots.py (scripts/real_x.py)
sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "scripts"))
from real_x import key, start_window_manager, stop_window_manager, wait  # noqa: E402


def main() -> None:
    from PyQt5 import QtCore

    from eyeviz.app.launch import make_app
    from eyeviz.app.settings import make_settings
    from eyeviz.app.window import MainWindow
    from eyeviz.model.scene import load
    from eyeviz.resources import scene_path

    name, configs = sys.argv[1], sys.argv[2:]
    app = make_app()
    with tempfile.TemporaryDirectory() as tmp:
        wm = start_window_manager(Path(tmp))
        path = scene_path(name)
        for k, cfg in enumerate(configs):
            scale, present = float(cfg.split(":")[0]), cfg.split(":")[1] == "1"
            scene = load(path)
            win = MainWindow(scene, path, settings=make_settings(Path(tmp) / f"s{k}.json"))
            win._force_close = True
            win.resize(1280, 720)
            win.show()
            wait(app, win.isVisible)
            wait(app, lambda: True, 0.5)  # the window manager's frame, then the fit
            if scale != 1.0:
                win.presenter.set_scale(scale)
            if present:
                key(app, win, "F5", lambda w=win: w.presenter.presenting)
            free = win.screen().availableGeometry()
            for i in range(len(scene.steps)):
                key(app, win, "Next", lambda i=i, w=win: w.step_index == i)
                win.jobs.wait()
                wait(app, lambda: True, 0.6)
                bar = win.statusBar()
                bottom = bar.mapToGlobal(QtCore.QPoint(0, bar.height())).y()
                frame = win.frameGeometry()
                row = {
                    "config": cfg, "step": i + 1, "bar_bottom": bottom,
                    "free_bottom": free.bottom() + 1, "frame_bottom": frame.bottom() + 1,
                    "decorated": frame != win.geometry(), "height": win.height(),
                    "min_height": win.minimumSizeHint().height(), "bar_shown": bar.isVisible(),
                }  # fmt: skip
                print(json.dumps(row), flush=True)
            win.force_close()
            app.processEvents()
        stop_window_manager(wm)


if __name__ == "__main__":
    main()
