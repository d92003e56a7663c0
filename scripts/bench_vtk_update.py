"""Python cost of one drag frame in the app's VTK view: ``SceneActors.update`` and the
overlays' update (the Frames built and every layer written in place), off-screen, without
the render itself. (The overlays are called through the API of the checkout measured:
``OverlayActors.update`` since the VTK layers were split, the three ``update_*`` before.)

The same two cases as bench_app.py (m = 720 with 10 features, m = 36,000 with 50), the
last feature dragged along a path: per step the model's state is recomputed (not timed)
and ``update(scene, state, selected)`` is timed (process CPU time, less sensitive to other
load than wall time). With ``--against DIR`` (another checkout, e.g. the commit before a
change) both run in alternating subprocesses, several rounds, and the ratio
this / against is printed per case: the figure to compare, measured in the same run.

With ``--predictions`` the scenes show the predictions layer (estimators analytic and
compact) and the timed step also asks the Predictor (as a drag frame of the app does) and
redraws the prediction ghosts.

    .venv/bin/python scripts/bench_vtk_update.py [--steps 300] [--rounds 3] [--against DIR]
        [--predictions]
"""

from __future__ import annotations

import argparse
import json
import math
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
CASES = ((720, 10), (36_000, 50))


def _scene(m: int, n: int):
    import numpy as np

    from eyeviz.model.scene import OKABE_ITO, Eyes, Feature, Scene, View

    rng = np.random.default_rng(7)
    fs = []
    for i in range(n):
        r = rng.uniform(1000, 5000)
        phi = rng.uniform(math.radians(40), math.radians(140))
        x, y, g = r * math.cos(phi), r * math.sin(phi), float(rng.uniform(20, 300))
        fs.append(Feature(f"f{i}", x, y, g, OKABE_ITO[i % len(OKABE_ITO)]))
    fs[-1] = Feature("dragged", 0.0, 1500.0, 50.0, OKABE_ITO[0])
    layers = ["eyes", "bfv", "features", "bitmaps", "readout", "labels"]
    return Scene(Eyes(40.0, 20.0, m), fs, layers, view=View((0.0, 2600.0), 9000.0))


def _overlays(ov, sc, st, sel: int, preds=None) -> None:
    """What the window calls per frame (predictions as given), no ambiguity or path."""
    preds = {} if preds is None else preds
    if hasattr(ov, "update"):
        ov.update(sc, st, sel, preds, None, None)
    else:  # the API before the split
        ov.update_predictions(sc, st, {}, {})
        ov.update_ambiguity(sc, None, None)
        ov.update_trajectory(sc, None)


def measure(steps: int, predictions: bool = False) -> dict[str, float]:
    """Median microseconds of SceneActors.update per drag step, per case."""
    import pyvista as pv

    from eyeviz.model.predictor import Predictor
    from eyeviz.model.state import compute_state
    from eyeviz.render.vtk.actors import SceneActors
    from eyeviz.render.vtk.overlays import OverlayActors

    out = {}
    for m, n in CASES:
        pl = pv.Plotter(off_screen=True, window_size=(640, 400))
        inset = pv.Renderer(pl)
        pl.ren_win.AddRenderer(inset)
        act = SceneActors(pl.renderer, inset)
        ov = OverlayActors(pl.renderer)
        sc = _scene(m, n)
        predictor = Predictor() if predictions else None
        if predictor is not None:
            sc.layers.append("predictions")
            sc.estimators = ["analytic", "compact"]

        def preds(st, sc=sc, predictor=predictor):
            return None if predictor is None else predictor.predict(sc, st)

        sel = n - 1
        st0 = compute_state(sc)
        act.update(sc, st0, sel)
        _overlays(ov, sc, st0, sel, preds(st0))
        times = []
        for k in range(steps + 10):
            a = 2 * math.pi * k / 80
            sc.features[sel].x = 150.0 * math.sin(a)
            sc.features[sel].y = 1500.0 + 60.0 * (1 - math.cos(a))
            st = compute_state(sc)
            t0 = time.process_time()
            act.update(sc, st, sel)
            _overlays(ov, sc, st, sel, preds(st))
            if k >= 10:
                times.append(1e6 * (time.process_time() - t0))
        pl.close()
        out[f"m={m:,}, {n} features"] = statistics.median(times)
    return out


def _run(root: Path, steps: int, predictions: bool) -> dict[str, float]:
    env = dict(os.environ, PYTHONPATH=str(root))
    code = (
        "import json, sys; sys.path.insert(0, sys.argv[1]); "
        "from bench_vtk_update import measure; "
        "print(json.dumps(measure(int(sys.argv[2]), sys.argv[3] == '1')))"
    )
    res = subprocess.run(
        [sys.executable, "-c", code, str(ROOT / "scripts"), str(steps), str(int(predictions))],
        env=env,
        cwd=str(root),
        capture_output=True,
        text=True,
        check=True,
    )
    return json.loads(res.stdout.strip().splitlines()[-1])


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=300, help="timed drag steps per case")
    ap.add_argument("--rounds", type=int, default=3, help="alternating rounds with --against")
    ap.add_argument("--against", type=Path, help="a baseline checkout to compare with")
    ap.add_argument(
        "--predictions", action="store_true", help="the scenes show the predictions layer"
    )
    args = ap.parse_args()
    if args.against is None:
        for case, us in measure(args.steps, args.predictions).items():
            print(f"{case:24s} update {us:8.0f} µs (median)")
        return 0
    this: dict[str, list[float]] = {}
    base: dict[str, list[float]] = {}
    for _ in range(args.rounds):
        for root, store in ((args.against, base), (ROOT, this)):
            for case, us in _run(root, args.steps, args.predictions).items():
                store.setdefault(case, []).append(us)
    print(f"{'case':24s} {'this µs':>9s} {'base µs':>9s}  ratio (median of rounds)")
    for case in this:
        a, b = statistics.median(this[case]), statistics.median(base[case])
        print(f"{case:24s} {a:9.0f} {b:9.0f}  {a / b:.2f}x")
    return 0


if __name__ == "__main__":
    sys.exit(main())
