"""Whole-process time of `eyeviz snapshot` on the default scene (target <= 3 s).

Runs `eyeviz snapshot assets/scenes/default.toml -o OUT.{png,svg,pdf}` as a fresh process
several times and prints the median wall time and CPU time (user + sys of the child) per
format, next to baselines measured in the same run: a bare Python start, `eyeviz --help`
and importing matplotlib's Figure + Agg canvas. On a shared machine wall time stretches
with the load; the CPU time and the ratio to the matplotlib baseline do not.

    .venv/bin/python scripts/bench_snapshot.py [--repeat N] [--scene SCENE]
"""

from __future__ import annotations

import argparse
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
TARGET_S = 3.0


def timed(cmd: list[str]) -> tuple[float, float]:
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    subprocess.run(
        cmd,
        check=True,
        cwd=ROOT,
        stdout=subprocess.DEVNULL,
        env={**os.environ, "MPLBACKEND": "Agg"},
    )
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return wall, cpu


def median_of(cmd: list[str], repeat: int) -> tuple[float, float]:
    runs = [timed(cmd) for _ in range(repeat)]
    return statistics.median(r[0] for r in runs), statistics.median(r[1] for r in runs)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--scene", default=str(ROOT / "assets" / "scenes" / "default.toml"))
    args = ap.parse_args()
    py = sys.executable
    eyeviz = [py, "-m", "eyeviz"]
    print(
        f"load average: {os.getloadavg()[0]:.2f} on {os.cpu_count()} CPUs; "
        f"median of {args.repeat} runs each\n"
    )
    base = {
        "python -c pass": [py, "-c", "pass"],
        "eyeviz --help": [*eyeviz, "--help"],
        "import matplotlib Figure+Agg": [
            py,
            "-c",
            "import matplotlib.figure, matplotlib.backends.backend_agg",
        ],
    }
    rows = []
    for name, cmd in base.items():
        rows.append((name, *median_of(cmd, args.repeat)))
    mpl_wall = rows[-1][1]
    worst = 0.0
    with tempfile.TemporaryDirectory() as tmp:
        for fmt in ("png", "svg", "pdf"):
            cmd = [*eyeviz, "snapshot", args.scene, "-o", str(Path(tmp) / f"s.{fmt}")]
            wall, cpu = median_of(cmd, args.repeat)
            worst = max(worst, wall)
            rows.append((f"eyeviz snapshot -> .{fmt}", wall, cpu))
    print(f"{'command':34s} {'wall s':>8s} {'cpu s':>8s} {'wall / mpl import':>18s}")
    for name, wall, cpu in rows:
        print(f"{name:34s} {wall:8.2f} {cpu:8.2f} {wall / mpl_wall:18.2f}")
    verdict = "PASS" if worst <= TARGET_S else "FAIL"
    print(f"\nslowest snapshot: {worst:.2f} s wall (target <= {TARGET_S:.0f} s): {verdict}")
    return 0 if worst <= TARGET_S else 1


if __name__ == "__main__":
    sys.exit(main())
