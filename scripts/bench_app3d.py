"""Latency of the app's 3D view: a ball's drag frame against a bare render of the same
window, window-up time, and memory at nside 180 (issue 22, item 7).

Runs under Xvfb (re-executes itself with xvfb-run when $DISPLAY is unset), 1280x800,
this machine's software OpenGL. For nside 16 and nside 180 (the paper's eyes: 388,800
facets per eye) with 8 balls in the paper's regime (r 1000-5000, elevation within 30
degrees) it presses on a ball in the 3D view, sends >= 200 mouse-move events along a
path and times each from the event to the end of the first frame that reflects it (the
view coalesces moves: the model moves the ball at once, the lit sets are recomputed and
one pending frame draws them; the clock stops when that VTK render has finished and the
Qt panels are painted; the Mollweide and readout docks follow inside the timed
frames). Right after each drag frame it times a bare re-render of the same window
(the baseline, same run, same state): drag p50 and p95 are reported as ratios to the
bare render's p50 and p95 (targets: p50 <= 1.5x, p95 <= 1.6x), beside the absolute
figures.

Runs on 2026-11-25, the shared 2-core machine, llvmpipe (ratios from the same run):
at load ~8, nside 16 drag p50 116.4 ms / p95 179.5 ms against bare 98.8 / 147.9 ms
(1.18x, 1.21x), nside 180 124.1 / 209.1 ms against 97.6 / 164.6 ms (1.27x, 1.27x), window
up 4.02 s; at load ~4, window up 1.56-1.67 s and frames of 30-45 ms (nside 16: 32.5 ms
against 24.7 ms; nside 180: 42.4 against 31.5 ms); 404-413 MB resident at nside 180
(peak 411-423 MB). The docks are refreshed at most every fourth drag frame and <= 4 Hz
(the Mollweide maps' update takes 15-75 ms at nside 180; refreshed on every frame they
made the nside 180 ratios 1.45-1.66x).

Window-up: a whole process, start to the first rendered frame of sphere_paper.toml
(nside 180), median of 3, target <= 3 s; the same process reports its resident memory
(VmRSS and the peak VmHWM) once the window is up and after 20 renders.

    xvfb-run -a .venv/bin/python scripts/bench_app3d.py [--events 240] [--predictions]
    xvfb-run -a .venv/bin/python scripts/bench_app3d.py --bee   # measured eyes only

``--responses`` also drags each case with the responses layer on (issue 34 item 2).
``--predictions`` also drags each case with the predictions layer on (issue 23 item 4:
the fast estimators answer the dragged ball on every frame, the limit waits for the
drag's end) and prints its frames against the same run's layer-off drag.
"""

from __future__ import annotations

import argparse
import math
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
CASES = (16, 180)
N_BALLS = 8
P50_RATIO, P95_RATIO = 1.5, 1.6
UP_TARGET_S = 3.0


def _scene(nside: int, predictions: bool = False):
    import numpy as np

    from eyeviz.model.scene import OKABE_ITO, Eyes, Feature, Scene

    rng = np.random.default_rng(7)
    fs = []
    for i in range(N_BALLS - 1):
        r = rng.uniform(1000, 5000)
        az = rng.uniform(math.radians(40), math.radians(140))
        el = rng.uniform(math.radians(-30), math.radians(30))
        fs.append(
            Feature(
                f"b{i}",
                r * math.cos(el) * math.cos(az),
                r * math.cos(el) * math.sin(az),
                float(rng.uniform(30, 300)),
                OKABE_ITO[i % len(OKABE_ITO)],
                r * math.sin(el),
            )
        )
    fs.append(Feature("dragged", 0.0, 1500.0, 120.0, OKABE_ITO[0], 0.0))
    layers = ["eyes", "features", "bfv", "bitmaps", "readout", "labels", "tangents", "plane"]
    if predictions:
        layers.append("predictions")
    sc = Scene(Eyes(40.0, 20.0, nside=nside), fs, layers)
    sc.estimators = ["analytic3d", "learned3d", "limit3d"]
    return sc


def _pct(v, q):
    s = sorted(v)
    return s[min(len(s) - 1, int(round(q / 100 * (len(s) - 1))))]


def _bee():
    """The shipped honeybee (measured eyes, 2 x 3,187 facets; docs/app_measured.md)."""
    from eyeviz.model.scene import load
    from eyeviz.resources import scene_path

    return load(scene_path("bee"))


def bench_drag(
    nside, events: int, settings: str, predictions: bool = False, responses: bool = False
) -> dict:
    """One case: ``nside`` (HEALPix eyes, the balls of :func:`_scene`) or ``"bee"``;
    ``responses``: with the responses layer on."""
    from PyQt5 import QtCore
    from PyQt5.QtTest import QTest

    from eyeviz.app.window import MainWindow, make_app, make_settings

    app = make_app()
    scene = _bee() if nside == "bee" else _scene(nside, predictions)
    if responses:
        scene.layers = [*scene.layers, "responses"]
    win = MainWindow(scene, settings=make_settings(settings))
    win.resize(1280, 800)
    win.show()
    for _ in range(5):
        app.processEvents()
    host = win.host3d
    host.set_preset("default")
    w = host.view
    rw = w.ren_win
    dragged = len(host.model.scene.features) - 1

    def centre():
        assert dragged is not None
        f = host.model.scene.features[dragged]
        return (f.x, f.y, f.z)

    def frame(before: int, was) -> bool:
        """Until the frame drawn after the event; False when the event changed nothing."""
        idle = 0
        while w.frames == before:
            app.processEvents()
            if not host._frame_timer.isActive() and not host._dirty and centre() == was:
                idle += 1
                if idle > 3:
                    return False
        rw.WaitForCompletion()
        app.processEvents()  # the docks' paint events
        return True

    base = []

    def bare() -> None:
        t0 = time.perf_counter()
        w.draw()
        rw.WaitForCompletion()
        base.append(1e3 * (time.perf_counter() - t0))

    win.jobs.wait()  # the limit of the first selected ball
    for _ in range(10):  # warm-up
        w.draw()
        rw.WaitForCompletion()
    px, py = host.scene_pixel(centre())
    start = QtCore.QPoint(round(px), round(py))
    win_in = w.windowHandle()
    QTest.mousePress(win_in, QtCore.Qt.LeftButton, QtCore.Qt.NoModifier, start)
    assert host._drag is not None, "the press did not grab a ball"
    dragged = host.model.selected  # the nearest ball under the pointer
    c0 = centre()
    lat = []
    p = start
    for k in range(events + 10):
        a = 2 * math.pi * k / 80
        p = start + QtCore.QPoint(round(120 * math.sin(a)) + k % 3, round(-50 * (1 - math.cos(a))))
        t0 = time.perf_counter()
        before = w.frames
        was = centre()
        QTest.mouseMove(win_in, p)
        drew = frame(before, was)
        if k >= 10 and drew:  # the first moves cross the click/drag threshold
            lat.append(1e3 * (time.perf_counter() - t0))
            bare()
    jobs_in_drag = host.limit_jobs
    QTest.mouseRelease(win_in, QtCore.Qt.LeftButton, QtCore.Qt.NoModifier, p)
    win.jobs.wait()
    jobs_after = host.limit_jobs
    moved = centre() != c0
    steps = win.undo_stack.count()
    lit = int(host.model.state.facets_a[dragged]) + int(host.model.state.facets_b[dragged])
    win.force_close()
    app.processEvents()
    return {
        "lat": lat, "base": base, "moved": moved, "undo_steps": steps, "lit": lit,
        "jobs": (jobs_in_drag, jobs_after),
    }  # fmt: skip


def bench_up(settings: str) -> tuple[float, list[str]]:
    code = (
        "import time; t0 = time.perf_counter()\n"
        "from eyeviz.app.window import MainWindow, make_app, make_settings\n"
        "from eyeviz.model.scene import load\n"
        "app = make_app()\n"
        f"w = MainWindow(load({str(ROOT / 'assets/scenes/sphere_paper.toml')!r}), "
        f"settings=make_settings({settings!r}))\n"
        "w.show(); app.processEvents(); w.host3d.draw()\n"
        "w.host3d.view.ren_win.WaitForCompletion()\n"
        "print('up', flush=True)\n"
        "def mem():\n"
        "    d = dict(l.split(':', 1) for l in open('/proc/self/status') if ':' in l)\n"
        "    return d['VmRSS'].strip(), d['VmHWM'].strip()\n"
        "print('mem up', *mem(), flush=True)\n"
        "for _ in range(20): w.host3d.draw(); app.processEvents()\n"
        "print('mem 20 renders', *mem(), flush=True)\n"
        "w.force_close()\n"
    )
    times = []
    mem: list[str] = []
    for _ in range(3):
        t0 = time.perf_counter()
        p = subprocess.Popen(
            [sys.executable, "-c", code],
            stdout=subprocess.PIPE,
            text=True,
            stderr=subprocess.DEVNULL,
        )
        assert p.stdout is not None
        mem = []
        for line in p.stdout:
            if line.strip() == "up":
                times.append(time.perf_counter() - t0)
            elif line.startswith("mem"):
                mem.append(line.strip())
        p.wait()
    return statistics.median(times), mem


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--events", type=int, default=240, help="mouse-move events per case (>= 200)")
    ap.add_argument(
        "--predictions", action="store_true", help="also drag with the predictions layer on"
    )
    ap.add_argument(
        "--bee", action="store_true", help="the shipped honeybee only (measured eyes, bee.toml)"
    )
    ap.add_argument(
        "--nside", type=int, action="append", help="only these nsides (repeatable), no window-up"
    )
    ap.add_argument(
        "--responses", action="store_true", help="also drag with the responses layer on"
    )
    ap.add_argument("--profile", help="write a cProfile of the drags to this file")
    args = ap.parse_args()
    if not os.environ.get("DISPLAY"):
        xvfb = shutil.which("xvfb-run")
        if xvfb is None:
            print("needs a display or xvfb-run", file=sys.stderr)
            return 2
        cmd = [xvfb, "-a", "-s", "-screen 0 1920x1080x24", sys.executable, *sys.argv]
        return subprocess.call(cmd)
    os.environ.setdefault("QT_API", "pyqt5")
    settings = str(Path(tempfile.mkdtemp()) / "settings.json")
    ok = True
    balls = "bee.toml's 3 balls" if args.bee else f"{N_BALLS} balls"
    print(f"3D view drag frame vs bare render of the same window ({balls}, 1280x800)")
    prof = None
    if args.profile:
        import cProfile

        prof = cProfile.Profile()
    for nside in ["bee"] if args.bee else (args.nside or CASES):
        if prof is not None:
            prof.enable()
        r = bench_drag(nside, args.events, settings)
        if prof is not None:
            prof.disable()
        lat, base = r["lat"], r["base"]
        p50, p95 = _pct(lat, 50), _pct(lat, 95)
        b50, b95 = _pct(base, 50), _pct(base, 95)
        r50, r95 = p50 / b50, p95 / b95
        good = r50 <= P50_RATIO and r95 <= P95_RATIO and r["moved"] and r["undo_steps"] == 1
        ok &= good
        print(
            (
                "honeybee (bee.toml, 3,187 facets/eye)"
                if nside == "bee"
                else f"nside {nside:>3} ({12 * nside * nside:,} facets/eye)"
            )
            + f": {len(lat)} frames; "
            f"drag p50 {p50:.1f} ms p95 {p95:.1f} ms; bare p50 {b50:.1f} ms p95 {b95:.1f} ms; "
            f"ratio p50 {r50:.2f}x (<= {P50_RATIO}) p95 {r95:.2f}x (<= {P95_RATIO}); "
            f"moved {r['moved']}, undo steps {r['undo_steps']}, dragged ball lights {r['lit']:,} "
            f"facets: {'OK' if good else 'MISSED'}"
        )
        if args.predictions and nside != "bee":
            q = bench_drag(nside, args.events, settings, predictions=True)
            q50, q95 = _pct(q["lat"], 50), _pct(q["lat"], 95)
            c50, c95 = _pct(q["base"], 50), _pct(q["base"], 95)
            print(
                f"  predictions on: drag p50 {q50:.1f} ms p95 {q95:.1f} ms; bare p50 "
                f"{c50:.1f} ms p95 {c95:.1f} ms; ratio p50 {q50 / c50:.2f}x p95 "
                f"{q95 / c95:.2f}x; against the layer off p50 {q50 / p50:.2f}x p95 "
                f"{q95 / p95:.2f}x; limit jobs started up to the release (the window's "
                f"first ball, the press's selection) {q['jobs'][0]}, after it "
                f"{q['jobs'][1] - q['jobs'][0]}"
            )
        if args.responses:
            q = bench_drag(nside, args.events, settings, responses=True)
            q50, q95 = _pct(q["lat"], 50), _pct(q["lat"], 95)
            c50, c95 = _pct(q["base"], 50), _pct(q["base"], 95)
            ok &= q50 / c50 <= P50_RATIO
            print(
                f"  responses on: drag p50 {q50:.1f} ms p95 {q95:.1f} ms; bare p50 "
                f"{c50:.1f} ms p95 {c95:.1f} ms; ratio p50 {q50 / c50:.2f}x (<= {P50_RATIO}) "
                f"p95 {q95 / c95:.2f}x; against the layer off p50 {q50 / p50:.2f}x"
            )
    if prof is not None:
        prof.dump_stats(args.profile)
    if args.bee or args.nside:
        return 0 if ok else 1
    up, mem = bench_up(settings)
    ok &= up <= UP_TARGET_S
    print(f"window up (sphere_paper.toml, nside 180): {up:.2f} s median of 3 (<= {UP_TARGET_S} s)")
    for m in mem:
        words = m.split()
        when, rss, hwm = " ".join(words[1:-4]), " ".join(words[-4:-2]), " ".join(words[-2:])
        print(f"memory at nside 180 ({when}): VmRSS {rss}, peak VmHWM {hwm}")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
