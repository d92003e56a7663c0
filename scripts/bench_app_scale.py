"""The app at scale (issue 25): a drag frame with 10^4 features against one with 10, and
against a bare render of the same window (same run, same state).

Runs under Xvfb (re-executes itself with xvfb-run when $DISPLAY is unset), 1280x800, this
machine's software OpenGL, the app's default view widget. For m = 720 with 10 and with
10,000 features (random discs in the view, as bench_app.py's scenes, the dragged one
last) it presses on the last feature, sends mouse-move events along a path and times each
from the event to the end of the first frame that reflects it (glFinish, then the panels'
paint events); right after each drag frame it times a bare re-render of the window. It
then releases the button (the gesture's one undo step), times the release and an undo,
and counts the Scene copies an edit makes. Printed: p50 / p95 of the drag frames and of
the bare renders, the ratios drag(10^4) / bare(10^4) (target <= 3x) and
drag(10^4) / drag(10), the release and undo times, and Scene.copy at 10^4 features.

What is left at 10^4 is the bare render itself (bare(10^4) / bare(10) is printed too): in
software GL (llvmpipe) ~10^5 disc triangles and ~16 M overlapping fragments of the merged
discs, drawn whether or not anything moved. Measured 2026-11-25 on the 2-core machine
under load ~8: drag p50 618 ms, bare 556 ms at 10^4 (before the level of detail, the
inset's culling and the single name label: 3674 ms and 3626 ms); window up 3.4 s (27.6 s).

    xvfb-run -a .venv/bin/python scripts/bench_app_scale.py [--events 60]
"""

from __future__ import annotations

import argparse
import math
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from bench_app import _pct  # noqa: E402

CASES = (10, 10_000)
M = 720
RATIO_TARGET = 3.0


def _scene(n: int):
    import numpy as np

    from eyeviz.model.scene import OKABE_ITO, Eyes, Feature, Scene, View

    rng = np.random.default_rng(7)
    r = rng.uniform(1000, 5000, n)
    phi = rng.uniform(math.radians(40), math.radians(140), n)
    g = rng.uniform(20, 300, n)
    fs = [
        Feature(
            f"f{i}",
            float(r[i] * math.cos(phi[i])),
            float(r[i] * math.sin(phi[i])),
            float(g[i]),
            OKABE_ITO[i % len(OKABE_ITO)],
        )
        for i in range(n)
    ]
    fs[-1] = Feature("dragged", 0.0, 1500.0, 50.0, OKABE_ITO[0])
    layers = ["eyes", "bfv", "features", "bitmaps", "readout", "labels"]
    return Scene(Eyes(40.0, 20.0, M), fs, layers, view=View((0.0, 2600.0), 9000.0))


def bench_drag(n: int, events: int, settings: str) -> dict:
    from PyQt5 import QtCore
    from PyQt5.QtTest import QTest

    import eyeviz.model.scene as scene_mod
    from eyeviz.app.window import MainWindow, make_app, make_settings

    app = make_app()
    t0 = time.perf_counter()
    win = MainWindow(_scene(n), settings=make_settings(settings))
    win.resize(1280, 800)
    win.show()
    for _ in range(5):
        app.processEvents()
    win.fit_inset()
    up = time.perf_counter() - t0
    w = win.plotter
    rw = win.ren_win

    def frame(before: int, was) -> bool:
        idle = 0
        while w.frames == before:
            app.processEvents()
            f = win.model.scene.features[-1]
            if not win._frame_pending and (f.x, f.y) == was:
                idle += 1
                if idle > 3:
                    return False
        rw.WaitForCompletion()
        app.processEvents()
        return True

    base: list[float] = []

    def bare() -> None:
        t = time.perf_counter()
        win.render()
        rw.WaitForCompletion()
        base.append(1e3 * (time.perf_counter() - t))

    for _ in range(3):
        win.render()
        rw.WaitForCompletion()
    px, py = win.to_pixel(0.0, 1500.0)
    start = QtCore.QPoint(round(px), round(py))
    win_in = w.windowHandle()
    QTest.mousePress(win_in, QtCore.Qt.LeftButton, QtCore.Qt.NoModifier, start)
    lat = []
    p = start
    for k in range(events + 5):
        a = 2 * math.pi * k / 40
        p = start + QtCore.QPoint(round(150 * math.sin(a)) + k % 3, round(-60 * (1 - math.cos(a))))
        t = time.perf_counter()
        before = w.frames
        f = win.model.scene.features[-1]
        was = (f.x, f.y)
        QTest.mouseMove(win_in, p)
        drew = frame(before, was)
        if k >= 5 and drew:
            lat.append(1e3 * (time.perf_counter() - t))
            bare()
    copies = [0]
    real_copy = scene_mod.Scene.copy

    def counted(self):
        copies[0] += 1
        return real_copy(self)

    scene_mod.Scene.copy = counted  # type: ignore[method-assign]
    try:
        t = time.perf_counter()
        QTest.mouseRelease(win_in, QtCore.Qt.LeftButton, QtCore.Qt.NoModifier, p)
        app.processEvents()
        release = 1e3 * (time.perf_counter() - t)
        release_copies = copies[0]
        moved = win.model.scene.features[-1].x != 0.0
        steps = win.undo_stack.count()
        t = time.perf_counter()
        win.model.finish_gestures()
        win.undo_stack.undo()
        app.processEvents()
        rw.WaitForCompletion()
        undo = 1e3 * (time.perf_counter() - t)
        restored = win.model.scene.features[-1].x == 0.0
    finally:
        scene_mod.Scene.copy = real_copy  # type: ignore[method-assign]
    sc = win.model.scene
    t = time.perf_counter()
    for _ in range(5):
        sc.copy()
    copy_ms = 1e3 * (time.perf_counter() - t) / 5
    win.force_close()
    app.processEvents()
    ok = moved and restored and steps == 1
    return {
        "lat": lat,
        "base": base,
        "ok": ok,
        "release": release,
        "undo": undo,
        "copies": release_copies,
        "copy_ms": copy_ms,
        "up": up,
    }


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--events", type=int, default=60, help="mouse-move events per case (>= 20)")
    args = ap.parse_args()
    if args.events < 20:
        ap.error(f"--events must be >= 20, got {args.events}")
    if not os.environ.get("DISPLAY"):
        if not shutil.which("xvfb-run"):
            print("bench_app_scale: no display and no xvfb-run", file=sys.stderr)
            return 2
        cmd = ["xvfb-run", "-a", "-s", "-screen 0 1920x1080x24", sys.executable, *sys.argv]
        return subprocess.call(cmd)
    os.environ.setdefault("QT_API", "pyqt5")
    res = {}
    with tempfile.TemporaryDirectory() as tmp:
        for n in CASES:
            res[n] = bench_drag(n, args.events, str(Path(tmp) / "bench.ini"))
    print(
        f"{'features':>9}{'events':>7}{'drag50':>8}{'drag95':>8}{'bare50':>8}{'bare95':>8}"
        f"{'d50/b50':>9}{'release':>9}{'undo':>8}{'copies':>7}{'copy ms':>8}{'up s':>6}"
    )
    for n, r in res.items():
        lat, base = r["lat"], r["base"]
        print(
            f"{n:>9,}{len(lat):>7}{_pct(lat, 50):>8.1f}{_pct(lat, 95):>8.1f}{_pct(base, 50):>8.1f}"
            f"{_pct(base, 95):>8.1f}{_pct(lat, 50) / _pct(base, 50):>8.2f}x{r['release']:>9.1f}"
            f"{r['undo']:>8.1f}{r['copies']:>7}{r['copy_ms']:>8.2f}{r['up']:>6.1f}"
        )
    big, small = res[CASES[-1]], res[CASES[0]]
    q_bare = _pct(big["lat"], 50) / _pct(big["base"], 50)
    q_small = _pct(big["lat"], 50) / _pct(small["lat"], 50)
    print(
        f"drag p50 at {CASES[-1]:,} / bare render p50 at {CASES[-1]:,}: {q_bare:.2f}x "
        f"(target <= {RATIO_TARGET:g}x)"
    )
    print(f"drag p50 at {CASES[-1]:,} / drag p50 at {CASES[0]}: {q_small:.2f}x")
    print(
        f"bare render p50 at {CASES[-1]:,} / at {CASES[0]}: "
        f"{_pct(big['base'], 50) / _pct(small['base'], 50):.2f}x"
    )
    ok = all(r["ok"] for r in res.values()) and q_bare <= RATIO_TARGET
    print("all targets met" if ok else "SOME TARGETS MISSED")
    return 0


if __name__ == "__main__":
    sys.exit(main())
