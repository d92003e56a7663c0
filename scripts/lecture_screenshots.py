"""Screenshots of a lecture scene's every step as a lecturer shows it (issue 32): the real
window on a screen of the given size, full screen (F11) and presentation mode (F5), then
PageDown once per step, all as real key presses (xdotool) under a window manager.

    xvfb-run -a -s "-screen 0 1280x720x24" .venv/bin/python scripts/lecture_screenshots.py \
        --scene sphere_lecture --size 1280x720 docs/img/sphere_lecture_1280

writes ``<prefix>_step<N>.png`` (N = 1 .. the number of steps) as 256-colour PNGs;
``--scale 1.75`` presses Ctrl+= until the text is at 175 % (before F11 and F5). The X
screen must be the size asked for (F11 fills the screen). openbox is started for the run
when no window manager runs; xdotool is needed.
"""

from __future__ import annotations

import argparse
import shutil
import tempfile
from pathlib import Path

from real_x import key, start_window_manager, stop_window_manager, wait  # beside this script


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
    ap.add_argument(
        "--scale",
        type=float,
        default=1.0,
        help="text scale, reached by Ctrl+= / Ctrl+- key presses",
    )
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
        wm = start_window_manager(Path(tmp))
        settings = make_settings(Path(tmp) / "settings.json")
        scene = load(path)
        win = MainWindow(scene, path, settings=settings)
        win.resize(min(w, 1200), min(h, 700))
        win.show()
        wait(app, win.isVisible)
        wait(app, lambda: True, 0.5)  # the window manager's frame
        # the text scale as a lecturer sets it: Ctrl+= (or Ctrl+-) until it is reached
        while abs(win.presenter.scale - a.scale) > 1e-9:
            before, up = win.presenter.scale, win.presenter.scale < a.scale
            key(app, win, "ctrl+equal" if up else "ctrl+minus",
                lambda b=before: win.presenter.scale != b)  # fmt: skip
            now = win.presenter.scale
            if now == before or (now > a.scale if up else now < a.scale):  # stuck, past
                raise SystemExit(f"Ctrl+=/- does not reach {a.scale} (at {win.presenter.scale})")
        key(app, win, "F11", lambda: win.isFullScreen() and win.width() == w)
        key(app, win, "F5", lambda: win.presenter.presenting)
        out = []
        for i in range(len(scene.steps)):
            key(app, win, "Next", lambda i=i: win.step_index == i)
            win.jobs.wait()
            wait(app, lambda: True, 0.5)
            p = Path(f"{a.prefix}_step{i + 1}.png")
            _save(win, p)
            out.append(p)
        print(" ".join(str(p) for p in out), win.width(), win.height())
        win.force_close()
        stop_window_manager(wm)


if __name__ == "__main__":
    main()
