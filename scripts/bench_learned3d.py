#!/usr/bin/env python
"""Benchmark of the learned 3D estimator's inference (issue 23: learned >= 10^5 rows/s).

Every figure is measured in this run, on rows generated here at the shipped weights'
design (nside 180, Algorithm 1 single pass, a seed none of its data sets used), best of
``--repeat``:

1. ``predict`` from the CSR lit sets (validation, summaries, network), rows/s, and its
   ratio to the 10^5 rows/s target: with the default ``threads`` (the two eyes'
   summaries side by side on two cores) and with one thread;
2. its parts: the run finder alone (the one pass over the indices, both eyes), the
   summaries (both eyes, the run finder and the indices' checks included), the features
   and the network, rows/s;
3. the baseline: one numpy pass that reads every lit index once (``indices.sum()``),
   rows/s: a ceiling for any estimator that looks at every lit facet, and the ratio of
   ``predict`` to it.

The 1-minute load average is printed with the figures (the cores may be shared).

    .venv/bin/python scripts/bench_learned3d.py [-n 20000] [--repeat 3]
"""

from __future__ import annotations

import argparse
import time


def best(f, repeat: int) -> float:
    t = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        f()
        t.append(time.perf_counter() - t0)
    return min(t)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[1])
    ap.add_argument("-n", type=int, default=20_000)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--seed", type=int, default=9_023_777)
    args = ap.parse_args(argv)

    import os

    from eyeviz.dataset.algorithm1_3d import generate3d
    from eyeviz.estimators import learned3d
    from eyeviz.estimators.healpix_summaries import _runs, eye_summaries
    from eyeviz.estimators.learned3d_features import features

    est = learned3d.load()
    d = est.domain
    ds = generate3d(args.n, d, seed=args.seed)
    n = len(ds)
    a = (ds.indptr_a, ds.indices_a)
    b = (ds.indptr_b, ds.indices_b)
    est.predict(a, b)  # warm the per-nside tables
    load = os.getloadavg()[0]

    t_pred = best(lambda: est.predict(a, b), args.repeat)
    threads = est.threads
    est.threads = 1
    t_pred1 = best(lambda: est.predict(a, b), args.repeat)
    est.threads = threads
    t_runs = best(lambda: (_runs(*a), _runs(*b)), args.repeat)

    def summaries():
        return (eye_summaries(d.nside, *a, name="lit_a"), eye_summaries(d.nside, *b, name="lit_b"))

    t_sum = best(summaries, args.repeat)
    sa, sb = summaries()
    t_feat = best(lambda: features(sa, sb, d.h, d.nside, d.r_min, d.r_max), args.repeat)
    x = features(sa, sb, d.h, d.nside, d.r_min, d.r_max)[0]
    t_net = best(lambda: est.network(x), args.repeat)
    t_base = best(lambda: (ds.indices_a.sum(), ds.indices_b.sum()), args.repeat)
    nnz = (ds.indptr_a[-1] + ds.indptr_b[-1]) / n
    print(f"{n} rows at nside {d.nside}, {nnz:.0f} lit indices per row (both eyes), "
          f"best of {args.repeat}, 1-min load average {load:.2f}")  # fmt: skip
    for k, t in ((threads, t_pred), (1, t_pred1)):
        print(f"predict (CSR), threads {k}: {n / t:10,.0f} rows/s  ({n / t / 1e5:.2f}x target)")
    print(f"  run finder (both eyes): {n / t_runs:12,.0f} rows/s")
    print(f"  summaries (both eyes):  {n / t_sum:12,.0f} rows/s")
    print(f"  features:               {n / t_feat:12,.0f} rows/s")
    print(f"  network ({est.n_weights} weights): {n / t_net:12,.0f} rows/s")
    print(f"baseline: read each index once: {n / t_base:12,.0f} rows/s "
          f"(predict = {t_base / t_pred:.3f}x of it)")  # fmt: skip
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
