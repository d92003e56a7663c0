"""Update time of the 3D panels beside the view (issue 22 items 4-5): the Mollweide bitmaps
(eyeviz/app/panels/bitmaps3d.py) and the readout (readout3d.py) during a drag.

For nside 16 and 180 (the teaching and the paper scenes' balls) the first ball moves along
a path of ``--frames`` steps; the states are computed first (the geometry is not what this
measures: scripts/bench_geometry3d.py does). Each frame times ``set_state`` on the
bitmaps panel (lit polygons set in place and blitted over the kept background, the moving
ball selected: its outline is redrawn every frame too) and on
the readout; right after it, in the same run and state, a full redraw of the bitmaps
canvas (the baseline: what re-creating the figure's artists would at least cost) is timed.
Printed: p50 and p95 in ms and the update / full-redraw ratios. No target is asserted.

    xvfb-run -a .venv/bin/python scripts/bench_panels3d.py [--frames 120]
"""

from __future__ import annotations

import argparse
import os
import shutil
import statistics
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _p(values: list[float], q: float) -> float:
    return statistics.quantiles(values, n=100)[int(q) - 1] if len(values) > 2 else values[0]


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--frames", type=int, default=120)
    args = ap.parse_args()
    if not os.environ.get("DISPLAY"):
        if shutil.which("xvfb-run") is None:
            print("needs a display or xvfb-run", file=sys.stderr)
            return 2
        cmd = ["xvfb-run", "-a", "-s", "-screen 0 1920x1080x24", sys.executable, *sys.argv]
        return subprocess.call(cmd)
    os.environ.setdefault("QT_API", "pyqt5")
    from PyQt5 import QtWidgets

    from eyeviz.app.panels.bitmaps3d import Bitmaps3DPanel
    from eyeviz.app.panels.readout3d import Readout3DPanel
    from eyeviz.model.scene import load
    from eyeviz.model.state3d import compute_state3d

    app = QtWidgets.QApplication.instance() or QtWidgets.QApplication([])
    for name, nside in (("sphere_teaching", 16), ("sphere_paper", 180)):
        sc = load(ROOT / "assets" / "scenes" / f"{name}.toml")
        sc.eyes.nside = nside
        states = []
        for k in range(args.frames):
            s = sc.copy()
            f = s.features[0]
            f.x += 0.08 * f.y * (k / args.frames - 0.5)  # sideways across the view
            f.z += 0.04 * f.y * ((k % 20) / 20 - 0.5)
            states.append((compute_state3d(s), s))
        bm = Bitmaps3DPanel()
        bm.resize(420, 560)
        bm.show()
        ro = Readout3DPanel()
        ro.resize(420, 240)
        ro.show()
        bm.set_state(*states[0], 0)
        ro.set_state(*states[0])
        for _ in range(10):
            app.processEvents()
            time.sleep(0.02)
        upd, full, rd = [], [], []
        for st, s in states[1:]:
            t0 = time.perf_counter()
            bm.set_state(st, s, 0)
            upd.append(time.perf_counter() - t0)
            t0 = time.perf_counter()
            ro.set_state(st, s)
            rd.append(time.perf_counter() - t0)
            t0 = time.perf_counter()
            bm.canvas.draw()
            bm.canvas.repaint()
            full.append(time.perf_counter() - t0)
            app.processEvents()
        lit = int(sum(bm.lit_facets(e).size for e in "AB"))
        print(
            f"nside {nside:>3} ({lit:,} lit facets on both maps at the end): bitmaps update "
            f"p50 {1e3 * _p(upd, 50):.1f} ms, p95 {1e3 * _p(upd, 95):.1f} ms; full redraw "
            f"p50 {1e3 * _p(full, 50):.1f} ms, p95 {1e3 * _p(full, 95):.1f} ms; ratio "
            f"p50 {_p(upd, 50) / _p(full, 50):.2f}x, p95 {_p(upd, 95) / _p(full, 95):.2f}x; "
            f"readout p50 {1e3 * _p(rd, 50):.2f} ms"
        )
        bm.close()
        ro.close()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
