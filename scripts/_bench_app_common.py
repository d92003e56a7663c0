"""The harness shared by scripts/bench_app.py and scripts/bench_app_scale.py: the scene of
random discs, the window, a drag timed frame by frame and the bare re-render after each.

A drag frame is timed from the mouse-move event to the end of the first frame that
reflects it (the app coalesces moves: it updates the model at once and draws one pending
frame; the clock stops when that VTK render has finished (glFinish) and the Qt panels are
painted). Right after each drag frame a bare re-render of the same window is timed (the
baseline: same run, same state). Mouse events go through the view's native window
(QWindow): Qt's input path into the widget's event filter, delivered at once. QTest on the
QWidget warps the X pointer instead, and every other move then arrived one iteration late
(it was counted as "idle" and the next move timed two frames): half the events were lost
to the stats.
"""

from __future__ import annotations

import math
import os
import shutil
import subprocess
import sys
import time
from dataclasses import dataclass, field

DRAGGED = (0.0, 1500.0)  # the dragged feature's centre: the scene's last (topmost) feature


def pct(v, q: float) -> float:
    """The q-th percentile of v (nearest rank)."""
    s = sorted(v)
    return s[min(len(s) - 1, int(round(q / 100 * (len(s) - 1))))]


def under_display(name: str) -> int | None:
    """None when a display is there; otherwise re-run this script under xvfb-run and
    return its exit code (2 without xvfb-run)."""
    if os.environ.get("DISPLAY"):
        os.environ.setdefault("QT_API", "pyqt5")
        return None
    if not shutil.which("xvfb-run"):
        print(f"{name}: no display and no xvfb-run", file=sys.stderr)
        return 2
    cmd = ["xvfb-run", "-a", "-s", "-screen 0 1920x1080x24", sys.executable, *sys.argv]
    return subprocess.call(cmd)


def scene(m: int, n: int, predictions: bool = False):
    """n random discs (r 1,000-5,000, phi 40-140 degrees, g 20-300) in a 9,000-wide view;
    the last one, dragged, at DRAGGED: the topmost disc, so the press grabs it even where
    a random disc overlaps it."""
    import numpy as np

    from eyeviz.model.scene import OKABE_ITO, Eyes, Feature, Scene, View

    rng = np.random.default_rng(7)
    fs = []
    for i in range(n):
        r = rng.uniform(1000, 5000)
        phi = rng.uniform(math.radians(40), math.radians(140))
        fs.append(
            Feature(
                f"f{i}",
                r * math.cos(phi),
                r * math.sin(phi),
                float(rng.uniform(20, 300)),
                OKABE_ITO[i % len(OKABE_ITO)],
            )
        )
    fs[-1] = Feature("dragged", *DRAGGED, 50.0, OKABE_ITO[0])
    layers = ["eyes", "bfv", "features", "bitmaps", "readout", "labels"]
    if predictions:
        layers.append("predictions")
    sc = Scene(Eyes(40.0, 20.0, m), fs, layers, view=View((0.0, 2600.0), 9000.0))
    sc.estimators = ["analytic", "compact"] if predictions else []
    return sc


def open_window(sc, settings: str, backend: str | None = None):
    """(app, window, seconds to show it): 1280 x 800, the inset fitted."""
    import eyeviz.app.view as view
    from eyeviz.app.window import MainWindow, make_app, make_settings

    if backend is not None:
        view.BACKEND = backend
    app = make_app()
    t0 = time.perf_counter()
    win = MainWindow(sc, settings=make_settings(settings))
    win.resize(1280, 800)
    win.show()
    for _ in range(5):
        app.processEvents()
    win.fit_inset()
    return app, win, time.perf_counter() - t0


@dataclass
class Drag:
    """A timed drag: frame latencies and bare re-renders (ms), the pointer's last place."""

    lat: list[float] = field(default_factory=list)
    base: list[float] = field(default_factory=list)
    end: object = None  # the QPoint of the last move
    handle: object = None  # the view's QWindow (for the release)


def bare_render(win) -> float:
    """One re-render of the window as it is, in ms (to glFinish)."""
    t0 = time.perf_counter()
    win.render()
    win.ren_win.WaitForCompletion()
    return 1e3 * (time.perf_counter() - t0)


def drag(app, win, events: int, skip: int, period: int, warmup: int) -> Drag:
    """Press on the dragged feature and send ``events + skip`` moves along a loop of
    ``period`` moves (the first ``skip`` cross the click/drag threshold and are not
    counted); time each frame and a bare re-render after it. The button stays down."""
    from PyQt5 import QtCore
    from PyQt5.QtTest import QTest

    w = win.plotter
    rw = win.ren_win

    def frame(before: int, was) -> bool:
        """Until the frame drawn after the event; False when the event changed nothing."""
        idle = 0
        while w.frames == before:
            app.processEvents()
            f = win.model.scene.features[-1]
            if not win._frame_pending and (f.x, f.y) == was:
                idle += 1
                if idle > 3:  # Qt sent no event (same pixel) or the feature did not move
                    return False
        rw.WaitForCompletion()
        app.processEvents()  # the panels' paint events
        return True

    for _ in range(warmup):
        win.render()
        rw.WaitForCompletion()
    px, py = win.to_pixel(*DRAGGED)
    start = QtCore.QPoint(round(px), round(py))
    out = Drag(handle=w.windowHandle())
    QTest.mousePress(out.handle, QtCore.Qt.LeftButton, QtCore.Qt.NoModifier, start)
    p = start
    for k in range(events + skip):
        a = 2 * math.pi * k / period
        p = start + QtCore.QPoint(round(150 * math.sin(a)) + k % 3, round(-60 * (1 - math.cos(a))))
        t0 = time.perf_counter()
        before = w.frames
        f = win.model.scene.features[-1]
        was = (f.x, f.y)
        QTest.mouseMove(out.handle, p)
        drew = frame(before, was)
        if k >= skip and drew:
            out.lat.append(1e3 * (time.perf_counter() - t0))
            out.base.append(bare_render(win))
    out.end = p
    return out


def release(win, d: Drag) -> None:
    """Release the button where the drag left it (the gesture's one undo step)."""
    from PyQt5 import QtCore
    from PyQt5.QtTest import QTest

    QTest.mouseRelease(d.handle, QtCore.Qt.LeftButton, QtCore.Qt.NoModifier, d.end)
