"""Benchmark of the geometry core: features/s of `intervals` and `bitmaps` (m = 720).

Prints rates at N = 10^6 paper-regime features, the ratio against a per-feature
pure-Python loop of the same formulas (Eq. 11 with atan2, measured in this run on a
subset), and the cost of the exact fallback (the core against its own fast path alone).

    .venv/bin/python scripts/bench_geometry.py [--n 1000000] [--repeats 5]
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np

from eyeviz.core.geometry import EyePair
from eyeviz.reference import stability_cases


def python_loop(eyes: EyePair, xs, ys, gs) -> list[tuple[int, int, int, int]]:
    """One feature at a time, the same formulas in plain Python floats."""
    k = eyes.m / (2 * math.pi)
    out = []
    for x, y, g in zip(xs, ys, gs, strict=True):
        row = []
        for cx in (-eyes.h, eyes.h):
            dx = x - cx
            r = math.hypot(dx, y)
            if r <= g:
                row += [0, eyes.m - 1]
                continue
            phi = math.atan2(y, dx)
            a = math.asin(g / r)
            lo = math.floor((phi - a) * k)
            hi = math.floor((phi + a) * k)
            L = lo % eyes.m
            row += [L, hi - lo + L]
        out.append(tuple(row))
    return out


def best_of(fn, repeats: int) -> float:
    best = float("inf")
    for _ in range(repeats):
        t = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t)
    return best


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=1_000_000)
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--loop-n", type=int, default=100_000, help="features for the Python loop")
    args = ap.parse_args()

    cs = stability_cases.make("paper", args.n, seed=1)
    eyes, x, y, g = cs.eyes, cs.x, cs.y, cs.g
    n = x.size
    sub = slice(0, min(args.loop_n, n))

    t_int = best_of(lambda: eyes.intervals(x, y, g), args.repeats)
    t_fast = best_of(lambda: eyes._intervals(x, y, g, refine=False), args.repeats)
    t_bmp = best_of(lambda: eyes.bitmaps(x, y, g), args.repeats)  # page faults vary: best of
    xs, ys, gs = x[sub].tolist(), y[sub].tolist(), g[sub].tolist()
    t_loop = best_of(lambda: python_loop(eyes, xs, ys, gs), 1) / len(xs) * n

    same = np.array(python_loop(eyes, xs, ys, gs)).T
    core = np.array(eyes.intervals(x[sub], y[sub], g[sub]))
    rate = n / t_int
    print(f"N = {n:,} paper-regime features, m = {eyes.m}, one core (numpy)")
    print(f"intervals             {rate / 1e6:8.2f} M features/s   target >= 10 M/s: "
          f"{'met' if rate >= 10e6 else 'NOT met'}")  # fmt: skip
    print(f"  fast path alone     {n / t_fast / 1e6:8.2f} M features/s   exact fallback costs "
          f"{100 * (t_int / t_fast - 1):+.1f} % (target < 10 %)")  # fmt: skip
    gbits = 2 * n * eyes.m / t_bmp / 1e9
    print(f"bitmaps (both eyes)   {n / t_bmp / 1e6:8.2f} M features/s   ({gbits:.2f} G bits/s)")
    print(f"pure-Python loop      {n / t_loop / 1e6:8.3f} M features/s   (measured on {len(xs):,})")
    print(f"ratio intervals / loop = {t_loop / t_int:.1f}x   target >= 10x: "
          f"{'met' if t_loop / t_int >= 10 else 'NOT met'}")  # fmt: skip
    print(f"loop agrees with the core on {int((same == core).all(axis=0).sum()):,} of {len(xs):,}")


if __name__ == "__main__":
    main()
