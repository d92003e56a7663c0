"""``eyeviz report dataset DATA [DATA ...] -o DIR``: how the elements are distributed.

For each data set, side by side: the histogram of r (the paper's Figures 8, 9) and the
centres (x, y) in the BFV (Figures 10, 11). Writes ``dataset.png``, ``dataset.md`` and
``dataset.csv`` (one row of summary figures per data set) into DIR, each atomically.

The summary's ``area_density_ratio`` is the number of centres per unit BFV area in the
outer half of the r range divided by that in the inner half: about 1 for centres uniform
over the area (multi-pass), (r_in + r_mid) / (r_mid + r_max) < 1 for a flat histogram
of r (a single pass), where r_in .. r_max is the range split at r_mid.
"""

from __future__ import annotations

import argparse
import csv
import io
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

HELP = "distribution of a data set: r histogram and centres in the BFV (Figures 8-11)"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "data",
        nargs="+",
        type=Path,
        metavar="DATA",
        help="data set files (.csv or .npz), shown side by side",
    )
    parser.add_argument("-o", "--output", required=True, type=Path, help="output directory")
    parser.add_argument(
        "--labels", nargs="+", default=None, help="one title per data set (default: the file names)"
    )
    parser.add_argument("--bins", type=int, default=40, help="histogram bins (default 40)")
    parser.add_argument(
        "--max-points",
        type=int,
        default=20000,
        help="centres drawn per scatter plot (default 20000)",
    )


@dataclass
class Summary:
    label: str
    path: str
    n: int
    m: int
    mode: str
    r_min: float
    r_max: float
    r_mean: float
    g_min: float
    g_max: float
    phi_min_deg: float
    phi_max_deg: float
    distinct_pairs: int
    area_density_ratio: float

    FIELDS = (
        "label",
        "path",
        "n",
        "m",
        "mode",
        "r_min",
        "r_max",
        "r_mean",
        "g_min",
        "g_max",
        "phi_min_deg",
        "phi_max_deg",
        "distinct_pairs",
        "area_density_ratio",
    )


def summarise(ds, label: str, path: str) -> Summary:
    r = ds.r
    lo, hi = float(r.min()), float(r.max())
    mid = 0.5 * (lo + hi)
    inner = np.count_nonzero(r < mid)
    outer = r.size - inner
    a_in, a_out = mid**2 - lo**2, hi**2 - mid**2  # annulus areas, up to the BFV angle
    ratio = (outer / a_out) / (inner / a_in) if inner and a_in > 0 and a_out > 0 else math.nan
    keys = np.concatenate([np.packbits(ds.omega_a, 1), np.packbits(ds.omega_b, 1)], 1)
    distinct = len(np.unique(keys.view(np.dtype((np.void, keys.shape[1]))).ravel()))
    g = ds.g[np.isfinite(ds.g)]
    return Summary(
        label,
        path,
        len(ds),
        ds.m,
        str(ds.params.get("mode", "unknown")),
        lo,
        hi,
        float(r.mean()),
        float(g.min()) if g.size else math.nan,
        float(g.max()) if g.size else math.nan,
        math.degrees(float(ds.phi.min())),
        math.degrees(float(ds.phi.max())),
        distinct,
        float(ratio),
    )


def _plot(datasets, summaries, bins: int, max_points: int, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    k = len(datasets)
    fig, axes = plt.subplots(
        2, k, figsize=(4.6 * k, 8.4), squeeze=False, gridspec_kw={"height_ratios": [1, 1.25]}
    )
    r_lo = min(s.r_min for s in summaries)
    r_hi = max(s.r_max for s in summaries)
    edges = np.linspace(r_lo, r_hi, bins + 1)
    hmax = max(np.histogram(ds.r, bins=edges)[0].max() for ds in datasets)
    for j, (ds, s) in enumerate(zip(datasets, summaries, strict=True)):
        ax = axes[0, j]
        counts = np.histogram(ds.r, bins=edges)[0]
        ax.bar(
            edges[:-1],
            counts,
            width=np.diff(edges),
            align="edge",
            color="#4c72b0",
            edgecolor="white",
            linewidth=0.4,
        )
        mids = 0.5 * (edges[:-1] + edges[1:])
        flat = np.full(bins, len(ds) / bins)
        lin = len(ds) * mids / mids.sum()
        ax.plot(mids, flat, "--", color="#dd8452", lw=1.4, label="flat in r (one pass)")
        ax.plot(mids, lin, ":", color="#55a868", lw=1.8, label="uniform over area")
        ax.set_ylim(0, hmax * 1.18)
        ax.set_xlabel("distance r of the centre")
        ax.set_ylabel("elements per bin" if j == 0 else "")
        ax.set_title(f"{s.label}\nn = {s.n:,}, mode: {s.mode}", fontsize=10)
        ax.legend(fontsize=8, loc="upper left", frameon=False)
        ax.grid(axis="y", alpha=0.3)

        ax = axes[1, j]
        step = max(1, math.ceil(len(ds) / max_points))
        x, y = ds.x[::step], ds.y[::step]
        ax.scatter(x, y, s=0.6, alpha=0.45, color="#4c72b0", linewidths=0, rasterized=True)
        psi = ds.eyes.psi
        reach = r_hi * 1.05
        for ang in (psi, math.pi - psi):
            ax.plot([0, reach * math.cos(ang)], [0, reach * math.sin(ang)], color="0.35", lw=0.9)
        for rr in (r_lo, r_hi):
            t = np.linspace(psi, math.pi - psi, 200)
            ax.plot(rr * np.cos(t), rr * np.sin(t), color="0.6", lw=0.6, ls="--")
        ax.plot([-ds.eyes.h, ds.eyes.h], [0, 0], "o", color="#c44e52", ms=3)
        ax.set_aspect("equal")
        ax.set_xlim(-reach * math.cos(psi) * 1.02, reach * math.cos(psi) * 1.02)
        ax.set_ylim(-0.03 * reach, reach * 1.02)
        ax.set_xlabel("x")
        ax.set_ylabel("y" if j == 0 else "")
        shown = f"every {step}th of " if step > 1 else ""
        ax.set_title(
            f"centres in the BFV ({shown}{s.n:,})\n"
            f"outer/inner density per area: {s.area_density_ratio:.2f}",
            fontsize=9,
        )
    fig.suptitle("Data set distribution (paper Figures 8-11)", fontsize=12)
    fig.tight_layout()
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=110)
    plt.close(fig)
    _write_atomic(path, buf.getvalue())


def _write_atomic(path: Path, data: bytes) -> None:
    from eyeviz.dataset.io import atomic_output

    with atomic_output(path) as tmp:
        tmp.write_bytes(data)


def _markdown(summaries: list[Summary]) -> str:
    lines = [
        "# Data set distribution",
        "",
        "![r histograms and centres](dataset.png)",
        "",
        "| data set | n | m | mode | r range | mean r | g range | phi range (deg) "
        "| distinct bitmap pairs | outer/inner density per area |",
        "|---|---:|---:|---|---|---:|---|---|---:|---:|",
    ]
    for s in summaries:
        lines.append(
            f"| {s.label} | {s.n:,} | {s.m} | {s.mode} | {s.r_min:.1f} - {s.r_max:.1f} "
            f"| {s.r_mean:.1f} | {s.g_min:.2f} - {s.g_max:.2f} "
            f"| {s.phi_min_deg:.1f} - {s.phi_max_deg:.1f} | {s.distinct_pairs:,} "
            f"| {s.area_density_ratio:.2f} |"
        )
    lines += [
        "",
        "The last column is the number of centres per unit BFV area in the outer half of "
        "the r range over that in the inner half: about 1 when centres are uniform over the "
        "area (multi-pass, Figure 11), below 1 for a flat histogram of r (one pass, "
        "Figures 8, 10: the density falls as 1/r).",
        "",
    ]
    return "\n".join(lines)


def run(args: argparse.Namespace) -> int:
    from eyeviz import EyevizError
    from eyeviz.dataset import load

    if args.bins < 1:
        raise EyevizError(f"--bins must be >= 1, got {args.bins}")
    if args.max_points < 1:
        raise EyevizError(f"--max-points must be >= 1, got {args.max_points}")
    labels = args.labels or [p.name for p in args.data]
    if len(labels) != len(args.data):
        raise EyevizError(
            f"--labels needs one label per data set ({len(args.data)}), got {len(labels)}"
        )
    datasets = [load(p) for p in args.data]
    for p, ds in zip(args.data, datasets, strict=True):
        if len(ds) == 0:
            raise EyevizError(f"{p}: the data set is empty")
    summaries = [
        summarise(ds, lab, str(p)) for ds, lab, p in zip(datasets, labels, args.data, strict=True)
    ]
    out = args.output
    out.mkdir(parents=True, exist_ok=True)
    _plot(datasets, summaries, args.bins, args.max_points, out / "dataset.png")
    _write_atomic(out / "dataset.md", _markdown(summaries).encode())
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(Summary.FIELDS)
    for s in summaries:
        w.writerow([getattr(s, f) for f in Summary.FIELDS])
    _write_atomic(out / "dataset.csv", buf.getvalue().encode())
    print(f"wrote {out / 'dataset.png'}, {out / 'dataset.md'}, {out / 'dataset.csv'}")
    return 0
