"""Cost of the Eye design dock during a drag (issue 11 item 4: a drag never waits for it).

In one window at 1366x768 with the dock open, times (median of --repeat):
  - the baseline: a bare render of the main view (the frame a drag move costs anyway);
  - the dock's marker update after a live move of the selected feature (a blit over the
    saved background, what a drag triggers at most every 40 ms);
  - a full redraw of the dock's figure (only when a new curve arrives);
  - one limit curve (the background computation, n = 5000).
Reports each as a ratio to the baseline. Target: the marker update <= 0.25x a view frame.
Runs under Xvfb (re-executes itself with xvfb-run when $DISPLAY is unset).

    xvfb-run -a .venv/bin/python scripts/bench_design_dock.py [--repeat 40]
"""

from __future__ import annotations

import argparse
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
MARKER_RATIO = 0.25


def _median_ms(fn, repeat: int) -> float:
    out = []
    for k in range(repeat):
        t = time.perf_counter()
        fn(k)
        out.append(time.perf_counter() - t)
    return 1000 * statistics.median(out)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=40)
    args = ap.parse_args()
    if not os.environ.get("DISPLAY") and shutil.which("xvfb-run"):
        cmd = ["xvfb-run", "-a", "-s", "-screen 0 1920x1080x24", sys.executable, *sys.argv]
        return subprocess.call(cmd)
    sys.path.insert(0, str(ROOT))
    from eyeviz.app import design_dock
    from eyeviz.app.window import MainWindow, make_app, make_settings
    from eyeviz.model.scene import load
    from eyeviz.resources import scene_path

    app = make_app()
    with tempfile.TemporaryDirectory() as tmp:
        win = MainWindow(load(scene_path("default")), settings=make_settings(Path(tmp) / "s.json"))
        win._force_close = True
        win.show()
        win.resize(1366, 768)
        panel = win.show_design()
        panel.wait()
        for _ in range(20):
            app.processEvents()
        win.model.select(0)
        win.model.begin_live("bench")

        marks = []
        for k in range(args.repeat):  # the feature moves (untimed), then the marker follows
            win.model.live(0, y=1500.0 + 20.0 * (k % 50))
            app.processEvents()
            t = time.perf_counter()
            panel._draw_marker()
            marks.append(time.perf_counter() - t)
        marker = 1000 * statistics.median(marks)
        base = _median_ms(lambda k: win.render(), args.repeat)
        full = _median_ms(lambda k: panel.canvas.draw(), max(5, args.repeat // 4))
        curve = _median_ms(lambda k: design_dock.compute_curve(40.0, 20.0, 720), 5)
        win.model.end_live()
        win.force_close()
    print("Eye design dock, 1366x768, this machine (ratios to a bare view render):")
    print(f"  view render (baseline)      {base:8.2f} ms")
    print(f"  marker update (blit)        {marker:8.2f} ms  {marker / base:6.2f}x")
    print(f"  full redraw of the figure   {full:8.2f} ms  {full / base:6.2f}x")
    print(f"  one limit curve (worker)    {curve:8.2f} ms  {curve / base:6.2f}x")
    ok = marker / base <= MARKER_RATIO
    print(f"  target: marker <= {MARKER_RATIO}x a view frame: {'met' if ok else 'NOT met'}")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
