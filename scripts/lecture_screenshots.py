"""Screenshots of a lecture scene's every step as a lecturer shows it (issue 32): the real
window on a screen of the given size, full screen (F11) and presentation mode (F5), then
PageDown once per step, all as real key presses (xdotool) under a window manager.

    xvfb-run -a -s "-screen 0 1280x720x24" .venv/bin/python scripts/lecture_screenshots.py \
        --scene sphere_lecture --size 1280x720 docs/img/sphere_lecture_1280

writes ``<prefix>_step<N>.png`` (N = 1 .. the number of steps) as 256-colour PNGs. The X
screen must be the size asked for (F11 fills the screen). openbox is started for the run
when no window manager runs; xdotool is needed.
"""

from __future__ import annotations

import argparse
import shutil
import subprocess
import tempfile
import time
from pathlib import Path


def _window_manager(tmp: Path) -> subprocess.Popen | None:
    if shutil.which("openbox") is None:
        raise SystemExit("openbox is needed (apt-get install openbox)")
    ready = tmp / "wm_ready"
    proc = subprocess.Popen(
        ["openbox", "--sm-disable", "--startup", f"touch {ready}"],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    for _ in range(200):
        if ready.exists() or proc.poll() is not None:
            break
        time.sleep(0.05)
    return proc if proc.poll() is None else None  # exited: another one runs


def _wait(app, until, timeout: float = 10.0) -> None:
    end = time.monotonic() + timeout
    while not until() and time.monotonic() < end:
        app.processEvents()
        time.sleep(0.02)
    for _ in range(10):
        app.processEvents()
        time.sleep(0.01)


def _key(app, win, key: str, until) -> None:
    win.activateWindow()
    subprocess.run(["xdotool", "windowfocus", "--sync", str(int(win.winId()))], check=True)
    subprocess.run(["xdotool", "key", "--delay", "40", key], check=True)
    _wait(app, until)


def _save(win, path: Path) -> None:
    from PIL import Image

    win.save_screenshot(path)
    with Image.open(path) as im:
        small = im.convert("RGB").quantize(256, dither=Image.Dither.NONE)
    small.save(path, optimize=True)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("prefix", help="output path prefix: <prefix>_step<N>.png")
    ap.add_argument("--scene", default="sphere_lecture", help="a bundled scene or a file")
    ap.add_argument("--size", default="1280x720", help="the screen's size WxH (checked)")
    ap.add_argument("--scale", type=float, default=1.0, help="text scale (Ctrl+=)")
    a = ap.parse_args()
    w, h = (int(v) for v in a.size.lower().split("x"))
    if shutil.which("xdotool") is None:
        raise SystemExit("xdotool is needed (apt-get install xdotool)")

    from PyQt5 import QtWidgets

    from eyeviz.app.launch import check_display, make_app
    from eyeviz.app.settings import make_settings
    from eyeviz.app.window import MainWindow
    from eyeviz.model.scene import load
    from eyeviz.resources import scene_path

    check_display()
    path = Path(a.scene) if Path(a.scene).is_file() else scene_path(a.scene)
    app = make_app()
    screen = QtWidgets.QApplication.primaryScreen().geometry()
    if (screen.width(), screen.height()) != (w, h):
        raise SystemExit(f"the X screen is {screen.width()}x{screen.height()}, not {w}x{h}")
    with tempfile.TemporaryDirectory() as tmp:
        wm = _window_manager(Path(tmp))
        settings = make_settings(Path(tmp) / "settings.json")
        scene = load(path)
        win = MainWindow(scene, path, settings=settings)
        win.resize(min(w, 1200), min(h, 700))
        win.show()
        _wait(app, win.isVisible)
        if a.scale != 1.0:
            win.presenter.set_scale(a.scale)
        _key(app, win, "F11", lambda: win.isFullScreen() and win.width() == w)
        _key(app, win, "F5", lambda: win.presenter.presenting)
        out = []
        for i in range(len(scene.steps)):
            _key(app, win, "Next", lambda i=i: win.step_index == i)
            win.jobs.wait()
            _wait(app, lambda: True, 0.5)
            p = Path(f"{a.prefix}_step{i + 1}.png")
            _save(win, p)
            out.append(p)
        print(" ".join(str(p) for p in out), win.width(), win.height())
        win.force_close()
        if wm is not None:
            wm.terminate()
            wm.wait(10)


if __name__ == "__main__":
    main()
