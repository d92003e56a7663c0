#!/usr/bin/env python
"""Benchmark of the data set generator (issue 3), every figure measured in this run.

1. Whole-process time of ``eyeviz generate -n 100000 -o X.csv`` (the paper's data set,
   about 150 MB) against a one-element-at-a-time pure-Python generator of the same
   Algorithm 1 that writes the same CSV layout with the ``csv`` module (the way the
   authors' web app works), both as separate processes; the ratio is printed.
2. Rows per second of ``eyeviz generate -n 10000000 -o X.npz`` and its peak memory,
   next to the peak memory of a run 10x smaller (bounded memory: the two should match).

    .venv/bin/python scripts/bench_dataset.py                 # full run
    .venv/bin/python scripts/bench_dataset.py --n-npz 1000000 # smaller NPZ run

Wall times depend on what else the machine runs: the load average is printed, and CPU
times (user + sys) are shown next to wall times.
"""

from __future__ import annotations

import argparse
import csv
import math
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


# --- the baseline: Algorithm 1, one element at a time, csv module --------------------


def baseline_generate(
    n: int,
    out: str,
    seed: int = 0,
    h: float = 40.0,
    l: float = 20.0,
    m: int = 720,
    r_min: float = 1000.0,
    r_max: float = 5000.0,
    g_max: float = 500.0,
) -> None:
    """Algorithm 1 as printed, in pure Python: numpy's uniform per draw, math per element,
    bitmaps built bit by bit (steps 17-28), rejection as eyeviz does, csv.writer rows."""
    import numpy as np

    rng = np.random.default_rng(seed)
    gamma = 2 * math.pi / m
    psi = math.asin(l / h)
    k = m / (2 * math.pi)
    half = m // 2

    def interval(cx: float, x: float, y: float, g: float) -> tuple[int, int]:
        dx = x - cx
        r_e = math.hypot(dx, y)
        phi_e = math.atan2(y, dx) % (2 * math.pi)
        a = math.asin(min(g / r_e, 1.0))
        return math.floor(k * (phi_e - a)), math.floor(k * (phi_e + a))

    w = math.sqrt((h - l) * (h + l))
    with open(out, "w", newline="") as f:
        writer = csv.writer(f, lineterminator="\n")
        for _ in range(n):
            while True:
                r = rng.uniform(r_min, r_max)  # step 7
                g_min = r * math.sin(gamma / 2)  # step 8
                if g_min > g_max:  # step 9
                    continue
                g = rng.uniform(g_min, g_max)  # step 10
                if g > r:  # step 11
                    continue
                a = math.asin(g / r)
                lo, hi = psi + a, math.pi - psi - a
                if lo > hi:
                    continue
                phi = rng.uniform(lo, hi)  # step 12
                x, y = r * math.cos(phi), r * math.sin(phi)
                if w * y - l * abs(x) - g * h < 0:  # Prop. 4
                    continue
                lb, rb = interval(h, x, y, g)  # steps 13-14
                la, ra = interval(-h, x, y, g)  # steps 15-16
                if ra <= la or rb <= lb:  # Def. 1
                    continue
                break
            omega_a, omega_b = [0] * half, [0] * half
            for j in range(half):  # steps 17-28
                omega_b[j] = 1 if lb <= j <= rb else 0
                omega_a[j] = 1 if la <= j <= ra else 0
            writer.writerow(omega_a + omega_b + [r, phi, g])


# --- measuring ------------------------------------------------------------------------


def timed(cmd: list[str]) -> dict:
    """Wall time, CPU time (user + sys) and peak RSS of one child process."""
    t = time.perf_counter()
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    _, status, ru = os.wait4(proc.pid, 0)
    wall = time.perf_counter() - t
    err = proc.stderr.read().decode() if proc.stderr else ""
    proc.returncode = os.waitstatus_to_exitcode(status)
    if proc.returncode != 0:
        raise SystemExit(f"command failed ({proc.returncode}): {' '.join(cmd)}\n{err}")
    return {"wall": wall, "cpu": ru.ru_utime + ru.ru_stime, "rss_mb": ru.ru_maxrss / 1024}


def eyeviz_cmd() -> list[str]:
    exe = Path(sys.executable).parent / "eyeviz"
    return [str(exe)] if exe.exists() else [sys.executable, "-m", "eyeviz"]


def appendix_columns(path: Path) -> tuple[int, int]:
    """Rows and columns as the paper's Appendix A/B loader sees them (first 1000 rows)."""
    rows = 0
    with open(path) as f:
        for row in csv.reader(f, delimiter=","):
            cols = len(row)
            float(row[720]), float(row[721])
            rows += 1
            if rows == 1000:
                break
    return rows, cols


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--n-csv", type=int, default=100_000)
    ap.add_argument("--n-npz", type=int, default=10_000_000)
    ap.add_argument("--repeat", type=int, default=5, help="eyeviz CSV runs (best and median)")
    ap.add_argument("--skip-baseline", action="store_true")
    ap.add_argument("--dir", type=Path, default=None, help="scratch directory (default: temp)")
    ap.add_argument("--baseline-worker", nargs=2, metavar=("N", "OUT"), help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.baseline_worker:
        baseline_generate(int(args.baseline_worker[0]), args.baseline_worker[1])
        return 0

    scratch = Path(tempfile.mkdtemp(prefix="eyeviz-bench-", dir=args.dir))
    try:
        print(f"load average before: {os.getloadavg()[0]:.2f} on {os.cpu_count()} CPUs")
        ev = eyeviz_cmd()
        csv_out = scratch / "paper.csv"
        runs = [
            timed([*ev, "generate", "-n", str(args.n_csv), "-o", str(csv_out), "--quiet"])
            for _ in range(args.repeat)
        ]
        size_mb = csv_out.stat().st_size / 1e6
        best = min(r["wall"] for r in runs)
        med = statistics.median(r["wall"] for r in runs)
        cpu = min(r["cpu"] for r in runs)
        print(
            f"\neyeviz generate -n {args.n_csv} -o X.csv ({size_mb:.1f} MB), whole process, "
            f"{args.repeat} runs:"
        )
        print(
            f"  wall best {best:.3f} s, median {med:.3f} s; CPU best {cpu:.3f} s; "
            f"peak RSS {max(r['rss_mb'] for r in runs):.0f} MB"
        )
        print(f"  Appendix A/B loader: {appendix_columns(csv_out)[1]} columns per row")
        results = {"csv_wall_best": best, "csv_wall_median": med, "csv_cpu": cpu}
        if not args.skip_baseline:
            base_out = scratch / "baseline.csv"
            b = timed(
                [sys.executable, __file__, "--baseline-worker", str(args.n_csv), str(base_out)]
            )
            print(
                f"\none-element-at-a-time Python + csv module, same rows and layout "
                f"({base_out.stat().st_size / 1e6:.1f} MB, "
                f"{appendix_columns(base_out)[1]} columns):"
            )
            print(f"  wall {b['wall']:.2f} s; CPU {b['cpu']:.2f} s")
            print(
                f"  ratio (baseline / eyeviz): wall {b['wall'] / med:.1f}x (median), "
                f"{b['wall'] / best:.1f}x (best); CPU {b['cpu'] / cpu:.1f}x"
            )
            results["baseline_wall"] = b["wall"]
            base_out.unlink()
        csv_out.unlink()

        npz_out = scratch / "big.npz"
        small_n = max(1, args.n_npz // 10)
        small = timed([*ev, "generate", "-n", str(small_n), "-o", str(npz_out), "--quiet"])
        big = timed([*ev, "generate", "-n", str(args.n_npz), "-o", str(npz_out), "--quiet"])
        size_mb = npz_out.stat().st_size / 1e6
        print(f"\neyeviz generate -n {args.n_npz:,} -o X.npz ({size_mb:.0f} MB):")
        print(
            f"  wall {big['wall']:.2f} s = {args.n_npz / big['wall'] / 1e6:.2f} M rows/s; "
            f"CPU {big['cpu']:.2f} s = {args.n_npz / big['cpu'] / 1e6:.2f} M rows/s"
        )
        print(
            f"  peak RSS {big['rss_mb']:.0f} MB (vs {small['rss_mb']:.0f} MB for "
            f"{small_n:,} rows: memory does not grow with n)"
        )
        print(f"\nload average after: {os.getloadavg()[0]:.2f}")
    finally:
        shutil.rmtree(scratch, ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
