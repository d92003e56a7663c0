"""Benchmark of the geometry core, new against the pre-issue-14 code, in one run (m = 720).

Every figure is a ratio against a baseline measured in this same run (the machine is
shared, so absolute rates drift; the ratios much less):

* intervals: the core, the legacy core (``eyeviz.reference.legacy_fastpath``) and a
  per-feature pure-Python loop of the same formulas (measured on a subset);
* the exact fallback's cost on paper-regime data (the core against its fast path alone);
* ties: per-feature cost on the "resting on y = 0" and "touching an eye's vertical line"
  classes against the paper regime, new and legacy;
* bitmaps: expanding intervals to bool bits against ``np.zeros`` + fill of the same
  output size; packed bits (``eyeviz.core.bits.packed_bitmaps``).

    .venv/bin/python scripts/bench_geometry.py [--n 1000000] [--repeats 5] [--rounds 3]
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np

from eyeviz.core import bits
from eyeviz.core.geometry import EyePair, intervals_to_bitmap
from eyeviz.reference import stability_cases
from eyeviz.reference.legacy_fastpath import LegacyEyePair, legacy_intervals_to_bitmap


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


def interleaved(fns: dict, repeats: int) -> dict[str, float]:
    """Best time per item of each (fn, items), the functions run in turn ``repeats`` times."""
    best = dict.fromkeys(fns, float("inf"))
    for _ in range(repeats):
        for name, (fn, items) in fns.items():
            t = time.perf_counter()
            fn()
            best[name] = min(best[name], (time.perf_counter() - t) / items)
    return best


def per_feature(fn, n: int, repeats: int) -> float:
    return best_of(fn, repeats) / n


def one_round(args, paper, ties, legacy_ties) -> dict[str, float]:
    eyes, x, y, g = paper.eyes, paper.x, paper.y, paper.g
    old = LegacyEyePair.of(eyes)
    n, r = x.size, args.repeats
    sub = slice(0, min(args.loop_n, n))
    xs, ys, gs = x[sub].tolist(), y[sub].tolist(), g[sub].tolist()
    # interleaved, best of r each: load changes hit all four alike
    res = interleaved(
        {
            "intervals new": (lambda: eyes.intervals(x, y, g), n),
            "intervals old": (lambda: old.intervals(x, y, g), n),
            "fast alone new": (lambda: eyes._intervals(x, y, g, refine=False), n),
            "python loop": (lambda: python_loop(eyes, xs, ys, gs), len(xs)),
        },
        r,
    )
    for name, cs in ties.items():
        res[f"{name} new"] = per_feature(lambda cs=cs: cs.eyes.intervals(cs.x, cs.y, cs.g),
                                         cs.x.size, r)  # fmt: skip
    for name, cs in legacy_ties.items():
        lo = LegacyEyePair.of(cs.eyes)
        res[f"{name} old"] = per_feature(lambda cs=cs, lo=lo: lo.intervals(cs.x, cs.y, cs.g),
                                         cs.x.size, 1)  # fmt: skip
    # bitmaps: expanding precomputed intervals against writing the same bytes once
    nb = min(n, args.bitmap_n)
    LA, RA = (v[:nb] for v in eyes.intervals(x[:nb], y[:nb], g[:nb])[:2])

    def zeros_fill():
        out = np.zeros((nb, eyes.m), bool)
        out.fill(True)
        return out

    res["zeros+fill"] = best_of(zeros_fill, r) / nb
    res["expand new"] = best_of(lambda: intervals_to_bitmap(LA, RA, eyes.m), r) / nb
    res["expand old"] = best_of(lambda: legacy_intervals_to_bitmap(LA, RA, eyes.m), r) / nb
    res["packed new"] = best_of(lambda: bits.packed_bitmaps(LA, RA, eyes.m, eyes.m), r) / nb
    res["bitmaps new"] = best_of(lambda: eyes.bitmaps(x[:nb], y[:nb], g[:nb]), r) / nb
    res["bitmaps old"] = best_of(lambda: old.bitmaps(x[:nb], y[:nb], g[:nb]), r) / nb
    return res


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=1_000_000)
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--rounds", type=int, default=3, help="whole measurements, each printed")
    ap.add_argument("--loop-n", type=int, default=20_000, help="features for the Python loop")
    ap.add_argument("--ties-n", type=int, default=100_000, help="features per tie class")
    ap.add_argument("--legacy-ties-n", type=int, default=300, help="tie features, old code")
    ap.add_argument("--bitmap-n", type=int, default=200_000, help="rows for the bitmaps")
    args = ap.parse_args()

    paper = stability_cases.make("paper", args.n, seed=1)
    names = {"ground": "resting on y = 0", "vertical": "touching an eye's vertical line"}
    ties = {names[k]: stability_cases.make(k, args.ties_n, seed=2) for k in names}
    legacy_ties = {names[k]: stability_cases.make(k, args.legacy_ties_n, seed=2) for k in names}
    eyes = paper.eyes
    print(f"N = {paper.x.size:,} paper-regime features, m = {eyes.m}, numpy on one core; "
          f"{args.rounds} rounds, best of {args.repeats} each (shared machine: noisy)")  # fmt: skip
    for k in range(args.rounds):
        t = one_round(args, paper, ties, legacy_ties)
        p = t["intervals new"]
        print(f"\n--- round {k + 1}: ns per feature (both eyes) and ratios in this round")
        po = t["intervals old"]
        print(f"intervals new {1e9 * p:7.1f} ns ({1e-6 / p:5.1f} M/s)  old "
              f"{1e9 * po:7.1f} ns  new is {po / p:.2f}x old")  # fmt: skip
        loop = t["python loop"]
        print(f"pure-Python loop {1e9 * loop:7.0f} ns: intervals new {loop / p:5.1f}x the loop "
              f"(target >= 30x), old {loop / t['intervals old']:5.1f}x")  # fmt: skip
        print(f"exact fallback on paper data costs {100 * (p / t['fast alone new'] - 1):+.1f} % "
              f"(target < 10 %)")  # fmt: skip
        for name in names.values():
            new, old = t[f"{name} new"], t[f"{name} old"]
            print(f"{name:32s} new {1e9 * new:8.0f} ns = {new / p:6.1f}x paper (target <= 50x)"
                  f"   old {1e9 * old:10.0f} ns = {old / t['intervals old']:7.0f}x paper old"
                  f"   speed-up {old / new:6.0f}x")  # fmt: skip
        z = t["zeros+fill"]
        print(f"expand to bool bits: new {1e9 * t['expand new']:6.0f} ns/row = "
              f"{100 * z / t['expand new']:4.0f} % of np.zeros+fill ({1e9 * z:.0f} ns/row, target "
              f">= 50 %); old {100 * z / t['expand old']:4.0f} %")  # fmt: skip
        print(f"packed bits (no byte per bit): {1e9 * t['packed new']:6.0f} ns/row = "
              f"{100 * z / t['packed new']:4.0f} % of the bool zeros+fill time")  # fmt: skip
        bn, bo = t["bitmaps new"], t["bitmaps old"]
        print(f"bitmaps (both eyes): new {1e-6 / bn:5.2f} M/s ({2 * eyes.m / bn / 1e9:.2f} "
              f"Gbit/s), old {1e-6 / bo:5.2f} M/s: new is {bo / bn:.2f}x old")  # fmt: skip

    sub = slice(0, min(args.loop_n, paper.x.size))
    xs, ys, gs = paper.x[sub].tolist(), paper.y[sub].tolist(), paper.g[sub].tolist()
    same = np.array(python_loop(eyes, xs, ys, gs)).T
    core = np.array(eyes.intervals(paper.x[sub], paper.y[sub], paper.g[sub]))
    print(
        f"\nloop agrees with the core on {int((same == core).all(axis=0).sum()):,} of {len(xs):,}"
    )
    old = np.array(LegacyEyePair.of(eyes).intervals(paper.x, paper.y, paper.g))
    new = np.array(eyes.intervals(paper.x, paper.y, paper.g))
    print(f"new and old cores agree on {int((old == new).all(axis=0).sum()):,} of {paper.x.size:,}")


if __name__ == "__main__":
    main()
