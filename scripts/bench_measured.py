"""Benchmark: lit sets of a measured eye pair (the honeybee) with the axis index against a
brute-force numpy pass over every facet, measured in the same run.

Balls about the bee's head at bee-scale distances: centre directions uniform on the
sphere, distances log-uniform in [5, 100] mm, angular radii log-uniform in [0.5, 10] deg.
Ours: ``MeasuredEyePair.lit_csr`` (index, certified float64 decision, exact fallback).
Baselines: the same exact decision on every facet (``index=False``), and a plain float64
pass over every facet (the textbook cone distance, not exact). One-ball calls (what a drag
frame does per ball): ``lit`` in a loop. Targets (issue 30, item 4): <= 50 us per ball
(both eyes) in 1000-ball calls, and >= 10x the brute-force pass.

    .venv/bin/python scripts/bench_measured.py [-n 1000] [--one 200] [--eye AM_60185-real.eye]
"""

from __future__ import annotations

import argparse
import math
import os
import time

import numpy as np

from eyeviz.core import measured_fast
from eyeviz.files.eye_io import load_eyes, shipped_eye


def bee_balls(n: int, rng: np.random.Generator):
    d = rng.normal(size=(n, 3))
    d /= np.linalg.norm(d, axis=1)[:, None]
    r = np.exp(rng.uniform(math.log(5.0), math.log(100.0), n))
    g = r * np.sin(np.radians(np.exp(rng.uniform(math.log(0.5), math.log(10.0), n))))
    return (*(d * r[:, None]).T, g)


def best_of(fun, repeat: int = 3) -> tuple[float, object]:
    """Best wall time of ``repeat`` runs (and the result); CPU times in ``CPU[-1]``."""
    best, cpu, res = math.inf, math.inf, None
    for _ in range(repeat):
        t, c = time.perf_counter(), time.process_time()
        res = fun()
        best = min(best, time.perf_counter() - t)
        cpu = min(cpu, time.process_time() - c)
    CPU.append(cpu)
    return best, res


#: CPU time of each best_of call: on a shared machine wall time counts the waits for a core
CPU: list[float] = []


def float_pass(pair, x, y, z, g, block: int = 64) -> list[list[np.ndarray]]:
    """Every facet of both eyes in float64 (atan2 angle, the cone distance): the plain
    numpy brute force, in blocks of balls."""
    out = []
    for eye in "AB":
        pos, ax, acc = pair.facets(eye)
        unit = ax / np.linalg.norm(ax, axis=1)[:, None]
        half = acc / 2
        rows = []
        for k in range(0, x.size, block):
            c = np.stack([x[k : k + block], y[k : k + block], z[k : k + block]], axis=1)
            v = c[:, None, :] - pos[None, :, :]
            vn = np.sqrt((v * v).sum(axis=2))
            s = np.einsum("bij,ij->bi", v, unit)
            th = np.arctan2(np.sqrt(np.maximum(vn * vn - s * s, 0)), s) - half
            dist = np.where(th <= 0, 0.0, np.where(th < np.pi / 2, vn * np.sin(th), vn))
            lit = dist <= g[k : k + block, None]
            rows.extend(np.flatnonzero(r) for r in lit)
        out.append(rows)
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("-n", type=int, default=1000, help="balls per batch call")
    ap.add_argument("--one", type=int, default=200, help="one-ball calls to time")
    ap.add_argument("--eye", default="AM_60185-real.eye", help="a shipped eye file")
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args()
    rng = np.random.default_rng(args.seed)
    t = time.perf_counter()
    pair = load_eyes(shipped_eye(args.eye))
    x, y, z, g = bee_balls(args.n, rng)
    t_load = time.perf_counter() - t
    t = time.perf_counter()
    pair.lit(0.0, 10.0, 0.0, 1.0)  # builds the tables and the index (cached on the pair)
    t_build = time.perf_counter() - t
    n_a, n_b = pair.facet_counts
    print(f"{args.eye}: {n_a} + {n_b} facets; load {t_load:.2f} s, index {t_build * 1e3:.0f} ms")

    before = dict(measured_fast.FALLBACK_COUNTS)
    t_ours, (csr_a, csr_b) = best_of(lambda: pair.lit_csr(x, y, z, g))
    c_ours = CPU[-1]
    balls = pair._flat_balls(x, y, z, g)[1]
    t_brute, brute = best_of(
        lambda: (pair._lit_eye("A", balls, index=False), pair._lit_eye("B", balls, index=False)),
        1,
    )
    c_brute = CPU[-1]
    t_float, flt = best_of(lambda: float_pass(pair, x, y, z, g), 1)
    c_float = CPU[-1]
    same = all(
        np.array_equal(a[0], b[0]) and np.array_equal(a[1], b[1])
        for a, b in zip((csr_a, csr_b), brute, strict=True)
    )
    differ = sum(
        not np.array_equal(rows[k], csr[1][csr[0][k] : csr[0][k + 1]])
        for rows, csr in zip(flt, (csr_a, csr_b), strict=True)
        for k in range(args.n)
    )
    lit = (csr_a[1].size + csr_b[1].size) / args.n
    exact = measured_fast.FALLBACK_COUNTS["exact"] - before.get("exact", 0)
    fast = measured_fast.FALLBACK_COUNTS["fast"] - before.get("fast", 0)
    us = 1e6 / args.n
    print(f"{args.n} balls, {lit:.1f} facets lit per ball (both eyes)")
    print(f"  ours (index + exact)      {t_ours * us:9.1f} us/ball   (target <= 50)"
          f"   CPU {c_ours * us:.1f} us/ball")  # fmt: skip
    rb, rf = t_brute / t_ours, t_float / t_ours
    print(f"  brute force, exact        {t_brute * us:9.1f} us/ball   ratio {rb:6.1f}x"
          f"   (target >= 10x; same sets: {same}; CPU ratio {c_brute / c_ours:.1f}x)")  # fmt: skip
    print(f"  brute force, plain float  {t_float * us:9.1f} us/ball   ratio {rf:6.1f}x"
          f"   (CPU ratio {c_float / c_ours:.1f}x; differs from exact on {differ} of"
          f" {2 * args.n} sets)")  # fmt: skip
    print(f"  pairs decided: {fast} fast, {exact} exact (all runs)")

    times, cpus = [], []
    for k in range(min(args.one, args.n)):
        t, c = time.perf_counter(), time.process_time()
        pair.lit(float(x[k]), float(y[k]), float(z[k]), float(g[k]))
        times.append(time.perf_counter() - t)
        cpus.append(time.process_time() - c)
    times_us = np.array(times) * 1e6
    print(
        f"  one-ball lit(): p50 {np.median(times_us):.0f} us, mean {times_us.mean():.0f} us,"
        f" p90 {np.percentile(times_us, 90):.0f} us ({len(times)} calls);"
        f" CPU mean {np.mean(cpus) * 1e6:.0f} us"
    )
    print(f"  (load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores)")


if __name__ == "__main__":
    main()
