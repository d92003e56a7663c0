"""Snapshot time against the number of features (issue 25: the label placement was cubic).

For n = 100, 300, 1000, 3000 and 10^4 random features (the default layers and the
labels: eyes, BFV, discs, bitmap strips with their interval labels, the readout table,
the names), times ``eyeviz.render.mpl.export.export`` to a PNG in this process (imports
warmed up first, median of --repeat runs) and prints the time, the time per feature, the
ratio of the per-feature time to the 100-feature case (flat when linear) and the PNG's
size (fixed once the table and the lanes are full). The interval-label placement alone
(``layout.interval_lanes``) is timed too, next to the previous all-pairs placement on the
sizes where that finishes (it took 78 s for 1000 labels).

    .venv/bin/python scripts/bench_snapshot_scale.py [--repeat N] [--sizes 100,300,...]
"""

from __future__ import annotations

import argparse
import os
import statistics
import struct
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
os.environ.setdefault("MPLBACKEND", "Agg")

from eyeviz.model.scene import Eyes, Feature, Scene, View  # noqa: E402
from eyeviz.render.mpl.export import export  # noqa: E402
from eyeviz.render.mpl.layout import interval_lanes, label_width  # noqa: E402

LAYERS = ["eyes", "bfv", "features", "bitmaps", "readout", "labels"]


def scene(n: int, seed: int = 0, layers: list[str] | None = None) -> Scene:
    rng = np.random.default_rng(seed)
    feats = [
        Feature(
            f"feature {i}",
            float(rng.uniform(-3000, 3000)),
            float(rng.uniform(600, 5000)),
            float(rng.uniform(20, 200)),
            "#D55E00",
        )
        for i in range(n)
    ]
    return Scene(
        Eyes(), feats, list(layers or LAYERS), [], View((0.0, 2500.0), 8000.0), f"{n} features"
    )


def old_lanes(L, R, m: int, strip_in: float) -> int:
    """The previous placement: each label scans every earlier one per lane (cubic)."""
    idx_per_in = m / strip_in
    placed: list[tuple[float, float, int]] = []
    for i in sorted(range(len(L)), key=lambda j: int(L[j])):
        lo, hi = int(L[i]), int(R[i])
        text = "whole eye" if hi - lo >= m - 1 else f"[{lo}, {hi % m}]"
        wid = label_width(text, 6.0) * idx_per_in
        centre = min(max(((lo + hi + 1) / 2) % m, wid / 2), m - wid / 2)
        lane = 0
        while any(abs(centre - c) < (wid + w) / 2 and ln == lane for c, w, ln in placed):
            lane += 1
        placed.append((centre, wid, lane))
    return 1 + max(ln for *_, ln in placed)


def median_time(fn, repeat: int) -> float:
    runs = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        runs.append(time.perf_counter() - t0)
    return statistics.median(runs)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--sizes", default="100,300,1000,3000,10000")
    ap.add_argument("--old-max", type=int, default=300, help="largest n for the old placement")
    ap.add_argument(
        "--layers",
        default=",".join(LAYERS),
        help="layers shown (default: %(default)s; the teaching layers tangents and sectors "
        "draw lines per feature)",
    )
    args = ap.parse_args()
    sizes = [int(s) for s in args.sizes.split(",")]
    layers = [s.strip() for s in args.layers.split(",") if s.strip()]
    print(
        f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} CPUs; median of "
        f"{args.repeat}; layers {', '.join(layers)}"
    )
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "s.png"
        export(scene(3), out)  # warm up: imports, fonts
        rows = []
        for n in sizes:
            sc = scene(n, layers=layers)
            t = median_time(lambda sc=sc: export(sc, out), args.repeat)
            w, h = struct.unpack(">II", out.read_bytes()[16:24])
            rng = np.random.default_rng(n)
            L = rng.integers(0, 360, n)
            R = L + rng.integers(0, 240, n)
            t_lanes = median_time(lambda L=L, R=R: interval_lanes(L, R, 720, 3.0), args.repeat)
            t_old = (
                median_time(lambda L=L, R=R: old_lanes(L, R, 720, 3.0), 1)
                if n <= args.old_max
                else None
            )
            rows.append((n, t, w, h, t_lanes, t_old))
    base = rows[0][1] / rows[0][0]
    ratio = f"per-feature / n={rows[0][0]}"
    print(
        f"\n{'features':>9s} {'snapshot s':>11s} {'ms/feature':>11s} {ratio:>22s}"
        f" {'x time':>8s} {'PNG px':>12s} {'lanes ms':>9s} {'old lanes ms':>13s}"
    )
    for n, t, w, h, tl, to in rows:
        old = f"{to * 1e3:13.1f}" if to is not None else f"{'(skipped)':>13s}"
        print(
            f"{n:9d} {t:11.2f} {t / n * 1e3:11.3f} {t / n / base:22.3f} {t / rows[0][1]:8.2f}"
            f" {f'{w}x{h}':>12s} {tl * 1e3:9.2f} {old}"
        )
    print(
        "\nlinear: ms/feature stays flat or falls (fixed costs are spread thinner); the PNG "
        "size stops growing once the table and the label lanes are full."
    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
