"""Inference speed per estimator: batched samples/s and single-sample latency.

Targets (issue 4): compact >= 10^6 samples/s batched and <= 1 ms for one sample.
Baseline measured in the same run: extracting the lit intervals from the bitmaps alone
(the floor every estimator pays), reported as a ratio.

    .venv/bin/python scripts/bench_estimators.py [--n 1000000] [--estimators compact,...]
"""

from __future__ import annotations

import argparse
import statistics
import time


def _best(fn, repeat: int) -> float:
    times = []
    for _ in range(repeat):
        t = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t)
    return min(times)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=1_000_000)
    ap.add_argument("--estimators", default="analytic,bayes,compact,paper")
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()

    import torch

    from eyeviz import dataset, estimators
    from eyeviz.estimators.base import bitmaps_to_intervals

    torch.set_num_threads(2)
    ds = dataset.generate(args.n, seed=2024)
    a, b = ds.omega_a, ds.omega_b
    base = _best(lambda: bitmaps_to_intervals(a, b), args.repeat)
    print(f"data: {args.n} rows of 2 x {a.shape[1]} bits; torch threads 2")
    print(f"baseline (interval extraction only): {args.n / base:,.0f} samples/s")
    print(
        f"{'estimator':10s} {'batched samples/s':>18s} {'x baseline time':>16s} "
        f"{'single (median)':>16s}  targets"
    )
    for name in args.estimators.split(","):
        try:
            est = estimators.load(name)
        except ValueError as exc:
            print(f"{name:10s} skipped: {exc}")
            continue
        n = args.n if name != "paper" else min(args.n, 20_000)
        t = _best(lambda e=est, k=n: e.predict(a[:k], b[:k]), args.repeat)
        rate = n / t
        lat = []
        for i in range(300):
            t0 = time.perf_counter()
            est.predict(a[i], b[i])
            lat.append(time.perf_counter() - t0)
        single = statistics.median(lat[20:])
        note = ""
        if name == "compact":
            ok = rate >= 1e6 and single <= 1e-3
            note = f"{'MET' if ok else 'MISSED'} (>= 1e6/s, <= 1 ms)"
        print(
            f"{name:10s} {rate:18,.0f} {t / (base * n / args.n):16.2f} "
            f"{single * 1e6:13.0f} us  {note}"
        )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
