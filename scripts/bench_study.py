"""Benchmark of the eye-design study (issue 11 targets), ratios within one run.

(a) One design point of 10^5 test elements on one core (in this process, no dask): the
    paper's design (h=40, l=20, m=720) and the slowest design of the default grid, found
    by timing every default design at a small n first. Target: <= 60 s.
(b) A 12-point study on a LocalCluster with 1 worker process, then with 2, in the same
    run: wall times (cluster start included) and the ratio. Target: >= 1.7x.

    PYTHONPATH=$PWD python scripts/bench_study.py [--n-point 100000] [--n-study 50000]

Timings depend on the machine's load: say how loaded it was with the figures.
"""

from __future__ import annotations

import argparse
import os
import tempfile
import time
from pathlib import Path

TARGET_POINT_S = 60.0
TARGET_SPEEDUP = 1.7


def bench_point(n: int, n_rank: int) -> None:
    from eyeviz.study import DesignPoint, design_grid, evaluate

    print(f"(a) one design point, n = {n}, one core (this process)")
    t0 = time.perf_counter()
    ranked = []
    for p in design_grid(n=n_rank):
        t = time.perf_counter()
        evaluate(p)
        ranked.append((time.perf_counter() - t, p))
    ranked.sort(key=lambda x: x[0], reverse=True)
    print(
        f"    ranking the {len(ranked)} default designs at n = {n_rank}: "
        f"{time.perf_counter() - t0:.1f} s; slowest three: "
        + "; ".join(f"h={p.h:g} l={p.l:g} m={p.m} {s:.2f} s" for s, p in ranked[:3])
    )
    paper = DesignPoint(h=40, l=20, m=720, n=n)
    cases = [("paper design h=40 l=20 m=720", paper)]
    for _, p in ranked[:2]:
        cases.append((f"slow default design h={p.h:g} l={p.l:g} m={p.m}", p))
    for name, p in cases:
        p = DesignPoint(p.h, p.l, p.m, p.r_min, p.r_max, p.g_max, p.prior, n, p.seed)
        t = time.perf_counter()
        rows = evaluate(p)
        s = time.perf_counter() - t
        ok = "meets" if s <= TARGET_POINT_S else "MISSES"
        print(
            f"    {name}: {s:.1f} s ({s / TARGET_POINT_S:.2f} of the {TARGET_POINT_S:g} s "
            f"target: {ok}); DD MAPE {rows[0]['dd_mape']:.2f} %, AD MAPE "
            f"{rows[0]['ad_mape']:.3f} %"
        )


def bench_study(n: int) -> None:
    from eyeviz.study import design_grid, read_rows, run_study

    points = design_grid("20,40,80", "10", "180,360,720,1440", n=n)
    assert len(points) == 12
    print(f"(b) a 12-point study (h 20,40,80; l 10; m 180..1440; n = {n}), LocalCluster")
    walls: dict[int, float] = {}
    busy: dict[int, float] = {}
    with tempfile.TemporaryDirectory() as d:
        for w in (1, 2):
            path = Path(d) / f"w{w}.csv"
            t = time.perf_counter()
            s = run_study(path, points, workers=w, progress=False)
            walls[w] = time.perf_counter() - t
            assert s.computed == 12, s
            rows, _ = read_rows(path)
            alls = sorted((r for r in rows if r["bin"] == "all"), key=lambda r: r["seconds"])
            per = [r["seconds"] for r in alls]
            top = alls[-1]
            busy[w] = sum(per) / walls[w]
            print(
                f"    {w} worker(s): {walls[w]:.1f} s wall (cluster start included); "
                f"points took {min(per):.1f}-{max(per):.1f} s each (slowest h={top['h']:g} "
                f"m={top['m']}), {sum(per):.1f} s in all"
            )
    ratio = walls[1] / walls[2]
    ok = "meets" if ratio >= TARGET_SPEEDUP else "MISSES"
    print(f"    speed-up 2 vs 1 workers: {ratio:.2f}x (target >= {TARGET_SPEEDUP}x: {ok})")
    print(
        f"    workers kept busy (sum of point times / wall): {busy[1]:.2f} with 1 worker, "
        f"{busy[2]:.2f} with 2 (2.0 = both busy all the time; a loaded machine slows each "
        "point down instead)"
    )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n-point", type=int, default=100_000, help="(a) test elements")
    ap.add_argument("--n-rank", type=int, default=10_000, help="(a) n for ranking designs")
    ap.add_argument("--n-study", type=int, default=50_000, help="(b) test elements/point")
    ap.add_argument("--skip-point", action="store_true", help="leave (a) out")
    ap.add_argument("--skip-study", action="store_true", help="leave (b) out")
    args = ap.parse_args()
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    print(f"cores: {os.cpu_count()}, load average (1 min) at start: {load:.2f}")
    if not args.skip_point:
        bench_point(args.n_point, args.n_rank)
    if not args.skip_study:
        bench_study(args.n_study)
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    print(f"load average (1 min) at end: {load:.2f}")


if __name__ == "__main__":
    main()
