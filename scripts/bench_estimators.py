"""Inference speed per estimator: batched samples/s and single-sample latency.

Targets (issue 4): compact >= 10^6 samples/s batched and <= 1 ms for one sample.
Baseline measured in the same run: extracting the lit intervals from the bitmaps alone
(the floor every estimator pays), reported as a ratio.

`limit` (issue 10: >= 5,000 distinct keys/s batched on one core, one key <= 2 ms) is
measured apart, because it caches per key: distinct keys on a fresh estimator (empty
cache), one new key per call, and the same rows again (all from the cache), beside the
bayes table lookup on the same rows in the same run.

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
    ap.add_argument("--estimators", default="analytic,bayes,compact,paper,limit")
    ap.add_argument("--limit-rows", type=int, default=20_000)
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
        if name == "limit":
            _bench_limit(a, b, args.limit_rows, args.repeat)
            continue
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


def _bench_limit(a, b, rows: int, repeat: int) -> None:
    """Distinct keys/s and one-key latency of `limit`, beside the bayes table lookup."""
    import numpy as np

    from eyeviz import estimators
    from eyeviz.estimators.base import bitmaps_to_intervals

    a, b = a[:rows], b[:rows]
    LA, RA, LB, RB, _ = bitmaps_to_intervals(a, b)
    distinct = len(np.unique(np.stack([LA, RA, LB, RB], 1), axis=0))
    times = []
    for _ in range(repeat):  # a fresh estimator each time: nothing cached
        est = estimators.load("limit")
        t0 = time.perf_counter()
        est.predict(a, b)
        times.append(time.perf_counter() - t0)
    t_cold = min(times)
    t_warm = _best(lambda: est.predict(a, b), repeat)  # every key cached now
    try:
        bay = estimators.load("bayes")
        t_bay = _best(lambda: bay.predict(a, b), repeat)
    except ValueError:
        t_bay = float("nan")
    fresh = estimators.load("limit")
    lat_new, lat_hit = [], []
    for i in range(300):  # the first call per row is a new key, the second a cache hit
        t0 = time.perf_counter()
        fresh.predict(a[i], b[i])
        lat_new.append(time.perf_counter() - t0)
        t0 = time.perf_counter()
        fresh.predict(a[i], b[i])
        lat_hit.append(time.perf_counter() - t0)
    new = statistics.median(lat_new[20:])
    hit = statistics.median(lat_hit[20:])
    lat_bay = []
    if t_bay == t_bay:
        for i in range(300):
            t0 = time.perf_counter()
            bay.predict(a[i], b[i])
            lat_bay.append(time.perf_counter() - t0)
    keys_s = distinct / t_cold
    ok = keys_s >= 5000 and new <= 2e-3
    print(f"limit: {rows} rows, {distinct} distinct keys, one process")
    print(f"  limit, empty cache : {keys_s:12,.0f} distinct keys/s ({rows / t_cold:,.0f} rows/s)")
    print(f"  limit, all cached  : {rows / t_warm:12,.0f} rows/s")
    print(f"  bayes table lookup : {rows / t_bay:12,.0f} rows/s (same rows)")
    print(
        f"  limit / bayes time, empty cache: {t_cold / t_bay:.1f}x; cached: {t_warm / t_bay:.1f}x"
    )
    bay_lat = f"{statistics.median(lat_bay[20:]) * 1e6:.0f} us" if lat_bay else "n/a"
    print(f"  one key: new {new * 1e3:.2f} ms, cached {hit * 1e6:.0f} us, bayes {bay_lat}")
    print(f"  targets (>= 5,000 keys/s, one key <= 2 ms): {'MET' if ok else 'MISSED'}")


if __name__ == "__main__":
    raise SystemExit(main())
