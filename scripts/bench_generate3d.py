#!/usr/bin/env python
"""Benchmark of the 3D data set generator (issue 21 item 5), every figure measured in this run.

1. Time to generate and write 10^5 elements at nside 180 (the paper's m = 720, default
   ranges, el_max = pi/6) as the sparse 3D NPZ, on one core (target <= 60 s), next to the
   planar generator's time for 10^5 rows at m = 720 (NPZ) measured in the same run, and
   the ratio.
2. Memory flat in n: the peak RSS of runs with n = 10^4 and 10^5 (and 10^6 with
   ``--big``), each in its own process, and the ratios to the smallest.

Every run is a separate child process pinned to one CPU (``os.sched_setaffinity``), so
its peak RSS (``ru_maxrss``) is its own; the output goes to a temporary folder that is
removed at the end (10^5 rows at nside 180 are about 1.3 GB on disk, twice that while
being assembled).

    .venv/bin/python scripts/bench_generate3d.py            # 10^4 and 10^5
    .venv/bin/python scripts/bench_generate3d.py --big      # and 10^6 (about 13 GB)
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

CHILD = r"""
import json, os, resource, sys, time
cpu = sorted(os.sched_getaffinity(0))[-1]
os.sched_setaffinity(0, {cpu})
kind, n, out = sys.argv[1], int(sys.argv[2]), sys.argv[3]
import numpy  # noqa: F401  (imports are not timed)
from eyeviz import dataset
from eyeviz.core.domain import Domain3D
from eyeviz.dataset import sparse3d
t0 = time.perf_counter()
c0 = time.process_time()
if kind == "3d":
    sparse3d.write3d(out, n, Domain3D(), seed=1)
else:
    dataset.write(out, n, seed=1)
wall, cpu_s = time.perf_counter() - t0, time.process_time() - c0
rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
read = rss_read = None
if kind == "3d":  # read it back, every row and CRC checked, in bounded blocks
    t0 = time.perf_counter()
    rows = sum(len(b) for b in sparse3d.Sparse3DReader(out))
    assert rows == n
    read = time.perf_counter() - t0
    rss_read = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
print(json.dumps({"wall": wall, "cpu": cpu_s, "rss": rss, "bytes": os.path.getsize(out),
                  "read": read, "rss_read": rss_read}))
"""


def run(kind: str, n: int, folder: Path) -> dict:
    out = folder / f"{kind}_{n}.npz"
    env = {**os.environ, "PYTHONPATH": str(ROOT), "OMP_NUM_THREADS": "1"}
    res = subprocess.run(
        [sys.executable, "-c", CHILD, kind, str(n), str(out)],
        env=env,
        capture_output=True,
        text=True,
    )
    if res.returncode:
        sys.exit(f"{kind} n={n} failed:\n{res.stderr}")
    out.unlink()
    return json.loads(res.stdout.strip().splitlines()[-1])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=100_000, help="rows of the timed run")
    ap.add_argument("--big", action="store_true", help="also n = 10^6 for the memory check")
    args = ap.parse_args()
    print(f"load average: {os.getloadavg()[0]:.2f} (2 cores shared: wall times vary)")
    folder = Path(tempfile.mkdtemp(prefix="bench3d_", dir=ROOT))
    try:
        flat = run("3d", max(1, args.n // 10), folder)
        main3d = run("3d", args.n, folder)
        planar = run("planar", args.n, folder)
        print(f"\n1. generating {args.n:,} rows (one core)")
        print(
            f"   3D, nside 180:     {main3d['wall']:7.2f} s wall, {main3d['cpu']:7.2f} s CPU, "
            f"{main3d['bytes'] / 1e6:8.1f} MB"
        )
        if args.n == 100_000:
            verdict = "met" if main3d["wall"] <= 60 else "NOT met"
            print(f"   target 10^5 rows <= 60 s: {verdict} on wall time; CPU time "
                  f"{main3d['cpu']:.1f} s (what one free core would take)")  # fmt: skip
        print(
            f"   planar, m = 720:   {planar['wall']:7.2f} s wall, {planar['cpu']:7.2f} s CPU, "
            f"{planar['bytes'] / 1e6:8.1f} MB"
        )
        print(f"   ratio 3D / planar: {main3d['wall'] / planar['wall']:.1f}x (wall)")
        print(f"   reading it back (every row and CRC checked): {main3d['read']:.2f} s")
        runs = [(max(1, args.n // 10), flat), (args.n, main3d)]
        if args.big:
            runs.append((args.n * 10, run("3d", args.n * 10, folder)))
        print("\n2. peak RSS of the 3D generator (each run its own process), then reading")
        base, base_read = runs[0][1]["rss"], runs[0][1]["rss_read"]
        for n, r in runs:
            print(
                f"   n = {n:>9,}: writing {r['rss'] / 2**20:6.1f} MiB ({r['rss'] / base:.2f}x), "
                f"reading {r['rss_read'] / 2**20:6.1f} MiB ({r['rss_read'] / base_read:.2f}x); "
                f"file {r['bytes'] / 1e6:.0f} MB, {r['wall']:.1f} s"
            )
    finally:
        shutil.rmtree(folder, ignore_errors=True)


if __name__ == "__main__":
    main()
