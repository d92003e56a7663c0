"""The state of a drag frame: one moved feature's row (``update_state``, through
``eyeviz.core.single``) against the whole vectorised pass (``compute_state``), same run.

The cases of bench_app.py (m = 720 with 10 features, m = 36,000 with 50; the app's default
layers), plus the paper's eyes with 10 features dragged over discs resting on y = 0 (every
frame a tie that the one-feature path hands back to the exact path). The last feature is
moved along a path; per step both are timed (best of 5 repeats of the step) and checked
equal field by field. Targets: the row update <= 0.5x of the whole pass on the drags (at
m = 36,000 the two new owner arrays of 36,000 cells are most of it), and <= 1.1x on the
ties (the exact path decides them either way: the row path must not add to it).

    .venv/bin/python scripts/bench_drag_state.py [--steps 300]
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import statistics
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from bench_app import _scene  # noqa: E402  (the same scenes as the app's latency bench)

from eyeviz.model.state import compute_state, update_state  # noqa: E402

TARGETS = {"drag": 0.5, "ties": 1.1}


def _same(a, b) -> bool:
    for f in dataclasses.fields(a):
        x, y = getattr(a, f.name), getattr(b, f.name)
        if isinstance(x, np.ndarray) and not (x.dtype == y.dtype and np.array_equal(x, y)):
            return False
    return True


def _best(fn, repeat: int = 5) -> float:
    best = math.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best


def measure(scene, path) -> tuple[float, float, bool]:
    """(median µs of update_state, of compute_state, all equal) over the path."""
    f = scene.features[-1]
    st = compute_state(scene)
    row, whole, equal = [], [], True
    for x, y in path:
        f.x, f.y = x, y
        row.append(_best(lambda st=st: update_state(st, scene, {len(scene.features) - 1})))
        whole.append(_best(lambda: compute_state(scene)))
        new = update_state(st, scene, {len(scene.features) - 1})
        equal = equal and _same(new, compute_state(scene))
        st = new
    return 1e6 * statistics.median(row), 1e6 * statistics.median(whole), equal


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=300)
    a = ap.parse_args()
    ring = [
        (150 * math.sin(2 * math.pi * k / 80), 1500 - 60 * (1 - math.cos(2 * math.pi * k / 80)))
        for k in range(a.steps)
    ]
    ties = [(-1000.0 + 7.0 * k, 25.0) for k in range(a.steps)]  # g = y: resting on y = 0
    cases = [
        ("m=720, 10 features", _scene(720, 10), ring, "drag"),
        ("m=36,000, 50 features", _scene(36_000, 50), ring, "drag"),
        ("m=720, ties on y = 0", _scene(720, 10), ties, "ties"),
    ]
    cases[2][1].features[-1].g = 25.0
    print(f"{'case':24s} {'row µs':>8s} {'whole µs':>9s}  ratio  target  equal")
    ok = True
    for name, scene, path, kind in cases:
        row, whole, equal = measure(scene, path)
        ok = ok and equal and row <= TARGETS[kind] * whole
        print(
            f"{name:24s} {row:8.1f} {whole:9.1f}  {row / whole:.2f}x  "
            f"{TARGETS[kind]:.1f}x    {equal}"
        )
    print("targets: the row update against the whole pass as above; every state equal")
    print("all targets met" if ok else "TARGET MISSED")
    return 0 if ok else 1


if __name__ == "__main__":
    raise SystemExit(main())
