"""Screenshots of the window for the README (issue 24): a scene at a window size, in
normal or presentation mode, optionally at one of its lecture steps.

    xvfb-run -a -s "-screen 0 1920x1080x24" .venv/bin/python scripts/presenting_screenshots.py \
        --scene lecture --size 1280x720 --present --step 6 docs/img/app_present_1280.png

The README's pictures: ``--scene default|predictions|trajectory|figure3b`` at 1280x720
(docs/img/app_<scene>.png), ``--scene default --size 1366x768 --design --m 2880``
(app_design_dock.png), ``--scene lecture --step 6`` at 1280x720 / 1920x1080 with and
without ``--present`` (app_lecture_*.png, app_present_*.png), ``--scene sphere_teaching``,
``sphere_paper`` and ``sphere_lecture --step 3`` at 1280x720 (app3d_*.png); saved as
256-colour PNGs.
"""

from __future__ import annotations

import argparse
import tempfile
from pathlib import Path


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out")
    ap.add_argument("--scene", default="lecture", help="a bundled scene's name or a file")
    ap.add_argument("--size", default="1280x720", help="window size WxH")
    ap.add_argument("--present", action="store_true", help="presentation mode")
    ap.add_argument("--step", type=int, default=0, help="show lecture step N (1-based)")
    ap.add_argument("--scale", type=float, default=1.0, help="text scale")
    ap.add_argument("--design", action="store_true", help="open View > Eye design too")
    ap.add_argument("--m", type=int, default=0, help="set the eyes' m after opening")
    a = ap.parse_args()
    w, h = (int(v) for v in a.size.lower().split("x"))

    from eyeviz.app.launch import check_display, make_app
    from eyeviz.app.settings import make_settings
    from eyeviz.app.window import MainWindow
    from eyeviz.model.scene import load
    from eyeviz.resources import scene_path

    check_display()
    path = Path(a.scene) if Path(a.scene).is_file() else scene_path(a.scene)
    app = make_app()
    with tempfile.TemporaryDirectory() as tmp:
        settings = make_settings(Path(tmp) / "settings.json")
        win = MainWindow(load(path), path, settings=settings)
        win.resize(w, h)
        win.show()
        for _ in range(5):
            app.processEvents()
        if a.scale != 1.0:
            win.presenter.set_scale(a.scale)
        if a.design:
            win.show_design()
            win.design_panel.wait()
            for _ in range(5):
                app.processEvents()
        if a.m:
            e = win.model.scene.eyes
            win.model.set_eyes(e.h, e.l, a.m)
            if a.design:
                win.design_panel.wait()
            for _ in range(5):
                app.processEvents()
        if a.present:
            win.presenter.toggle_presentation()
        for _ in range(a.step):
            win.next_step()
        win.fit_inset()
        win.frame_bundled()
        win.jobs.wait()
        for _ in range(5):
            app.processEvents()
        print(win.save_screenshot(a.out), win.width(), win.height())
        win.force_close()


if __name__ == "__main__":
    main()
