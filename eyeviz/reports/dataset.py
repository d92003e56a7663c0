"""``eyeviz report dataset DATA [DATA ...] -o DIR``: how the elements are distributed.

For each data set, side by side: the histogram of r (the paper's Figures 8, 9) and the
centres (x, y) in the BFV (Figures 10, 11). Writes the figure as ``dataset.png`` (300
dpi), ``dataset.svg`` and ``dataset.pdf`` (vectors, the scatter rasterised), and
``dataset.md`` and ``dataset.csv`` (one row of summary figures per data set) into DIR,
each atomically.
Each file is streamed block by block (:func:`eyeviz.dataset.reader.iter_blocks`), so a
10^7-row data set needs one block of memory plus 8 bytes per distinct bitmap pair (the
pairs are counted by 64-bit hash: a collision among 10^7 pairs has odds about 3e-6).

The summary's ``area_density_ratio`` is the number of centres per unit BFV area in the
outer half of the r range divided by that in the inner half: about 1 for centres uniform
over the area (multi-pass), (r_in + r_mid) / (r_mid + r_max) < 1 for a flat histogram
of r (a single pass), where r_in .. r_max is the range split at r_mid.

The generation mode is the one an NPZ records (``mode_source`` "recorded"); a CSV records
none, so it is inferred from that ratio (``mode_source`` "inferred"): "single" when it is
near the flat-histogram value, "multi" when near 1, else "unknown" (too few rows, or a
distribution that is neither, such as ``--unique-bitmaps``).
"""

from __future__ import annotations

import argparse
import csv
import io
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

#: Centres drawn per scatter plot, at most (each is kept in memory until the plot).
MAX_POINTS = 10**6
#: The figure's raster resolution (print quality) and its formats.
DPI = 300
FORMATS = ("png", "svg", "pdf")
#: Fewer rows than this: the mode is not inferred (the ratio's noise is too large).
MIN_ROWS_TO_INFER = 1000

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
    mode_source: str  # "recorded" (the file's metadata), "inferred" (from r) or "unknown"
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
        "mode_source",
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


_HASH_MUL = np.uint64(0x9E3779B97F4A7C15)


def _row_hashes(omega_a: np.ndarray, omega_b: np.ndarray) -> np.ndarray:
    """A 64-bit hash of each row's bitmap pair (packed bits, 8 bytes at a time), for
    counting distinct pairs in bounded memory (8 bytes per distinct pair, not m/4)."""
    keys = np.concatenate([np.packbits(omega_a, 1), np.packbits(omega_b, 1)], 1)
    pad = (-keys.shape[1]) % 8
    if pad:
        keys = np.pad(keys, ((0, 0), (0, pad)))
    words = np.ascontiguousarray(keys).view(np.uint64)
    h = np.full(len(words), np.uint64(len(keys[0])), np.uint64)
    with np.errstate(over="ignore"):
        for j in range(words.shape[1]):
            h = (h ^ words[:, j]) * _HASH_MUL
            h ^= h >> np.uint64(29)
    return h


@dataclass
class _Scan:
    """What one streamed pass over a data set gathers (no rows kept)."""

    n: int = 0
    r_lo: float = math.inf
    r_hi: float = -math.inf
    r_sum: float = 0.0
    g_lo: float = math.inf
    g_hi: float = -math.inf
    phi_lo: float = math.inf
    phi_hi: float = -math.inf
    hashes: np.ndarray = field(default_factory=lambda: np.empty(0, np.uint64))

    def add(self, b) -> None:
        self.n += len(b.r)
        self.r_lo = min(self.r_lo, float(b.r.min()))
        self.r_hi = max(self.r_hi, float(b.r.max()))
        self.r_sum += float(b.r.sum())
        g = b.g[np.isfinite(b.g)]
        if g.size:
            self.g_lo, self.g_hi = min(self.g_lo, float(g.min())), max(self.g_hi, float(g.max()))
        self.phi_lo = min(self.phi_lo, float(b.phi.min()))
        self.phi_hi = max(self.phi_hi, float(b.phi.max()))
        self.hashes = np.unique(np.concatenate([self.hashes, _row_hashes(b.omega_a, b.omega_b)]))


def _reader(path: Path):
    from eyeviz.dataset.reader import iter_blocks

    return iter_blocks(path)


def summarise(path: Path, label: str) -> Summary:
    """Summary figures of the data set at ``path``, streamed block by block
    (:func:`eyeviz.dataset.reader.iter_blocks`): memory is one block plus 8 bytes per
    distinct bitmap pair, whatever the file's size. Reads the file twice (the inner/outer
    split needs the r range first)."""
    from eyeviz import EyevizError

    reader = _reader(path)
    scan = _Scan()
    for b in reader:
        scan.add(b)
    if scan.n == 0:
        raise EyevizError(f"{path}: the data set is empty")
    lo, hi = scan.r_lo, scan.r_hi
    mid = 0.5 * (lo + hi)
    inner = sum(int(np.count_nonzero(b.r < mid)) for b in _reader(path))
    outer = scan.n - inner
    a_in, a_out = mid**2 - lo**2, hi**2 - mid**2  # annulus areas, up to the BFV angle
    ratio = (outer / a_out) / (inner / a_in) if inner and a_in > 0 and a_out > 0 else math.nan
    has_g = scan.g_lo <= scan.g_hi
    recorded = reader.params.get("mode")
    if recorded in ("single", "multi"):
        mode, source = str(recorded), "recorded"
    else:
        mode = infer_mode(float(ratio), lo, hi, scan.n)
        source = "unknown" if mode == "unknown" else "inferred"
    return Summary(
        label,
        str(path),
        scan.n,
        reader.eyes.m,
        mode,
        source,
        lo,
        hi,
        scan.r_sum / scan.n,
        scan.g_lo if has_g else math.nan,
        scan.g_hi if has_g else math.nan,
        math.degrees(scan.phi_lo),
        math.degrees(scan.phi_hi),
        int(scan.hashes.size),
        float(ratio),
    )


def infer_mode(ratio: float, r_lo: float, r_hi: float, n: int) -> str:
    """ "single", "multi" or "unknown" from the outer/inner density ratio per area: a
    single pass (r flat) gives (r_lo + r_mid) / (r_mid + r_hi), a multi-pass set (uniform
    over the area) 1. The nearer one (in log ratio) when within 30 % of the distance
    between the two; "unknown" otherwise or for fewer than :data:`MIN_ROWS_TO_INFER` rows."""
    mid = 0.5 * (r_lo + r_hi)
    flat = (r_lo + mid) / (mid + r_hi) if mid + r_hi > 0 else math.nan
    if n < MIN_ROWS_TO_INFER or not (ratio > 0 and math.isfinite(ratio)) or not flat > 0:
        return "unknown"
    gap = abs(math.log(flat))
    if gap < 0.1:  # a range too narrow to tell the two apart
        return "unknown"
    d_single, d_multi = abs(math.log(ratio / flat)), abs(math.log(ratio))
    if min(d_single, d_multi) > 0.3 * gap:
        return "unknown"
    return "single" if d_single < d_multi else "multi"


def _histogram_and_sample(path: Path, edges: np.ndarray, step: int):
    """(counts per bin, x, y of every ``step``-th row, the eye pair), streamed."""
    reader = _reader(path)
    counts = np.zeros(len(edges) - 1, np.int64)
    xs, ys = [], []
    for b in reader:
        counts += np.histogram(b.r, bins=edges)[0]
        first = (-b.start) % step
        r, phi = b.r[first::step], b.phi[first::step]
        xs.append(r * np.cos(phi))
        ys.append(r * np.sin(phi))
    return counts, np.concatenate(xs), np.concatenate(ys), reader.eyes


# long: a figure's layout, panel after panel: matplotlib calls, not logic
def _plot(paths, summaries, bins: int, max_points: int, path: Path) -> list[Path]:
    """The figure at ``path`` (.png, 300 dpi) and beside it as .svg and .pdf; the paths."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    k = len(paths)
    r_lo = min(s.r_min for s in summaries)
    r_hi = max(s.r_max for s in summaries)
    edges = np.linspace(r_lo, r_hi, bins + 1)
    if not np.all(np.diff(edges) > 0):  # every r equal: one bin around it
        edges = np.array([r_lo - 0.5, r_hi + 0.5]) if r_lo == r_hi else np.unique(edges)
        bins = len(edges) - 1
    drawn = [
        _histogram_and_sample(p, edges, max(1, math.ceil(s.n / max_points)))
        for p, s in zip(paths, summaries, strict=True)
    ]
    hmax = max(int(c.max()) for c, *_ in drawn)
    fig, axes = plt.subplots(
        2, k, figsize=(4.6 * k, 8.4), squeeze=False, gridspec_kw={"height_ratios": [1, 1.25]}
    )
    for j, ((counts, x, y, eyes), s) in enumerate(zip(drawn, summaries, strict=True)):
        ax = axes[0, j]
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
        flat = np.full(bins, s.n / bins)
        lin = s.n * mids / mids.sum()
        ax.plot(mids, flat, "--", color="#dd8452", lw=1.4, label="flat in r (one pass)")
        ax.plot(mids, lin, ":", color="#55a868", lw=1.8, label="uniform over area")
        ax.set_ylim(0, max(hmax, 1) * 1.18)
        ax.set_xlabel("distance r of the centre")
        ax.set_ylabel("elements per bin" if j == 0 else "")
        how = "" if s.mode_source != "inferred" else " (inferred from r)"
        ax.set_title(f"{s.label}\nn = {s.n:,}, mode: {s.mode}{how}", fontsize=10)
        ax.legend(fontsize=8, loc="upper left", frameon=False)
        ax.grid(axis="y", alpha=0.3)

        ax = axes[1, j]
        step = max(1, math.ceil(s.n / max_points))
        ax.scatter(x, y, s=0.6, alpha=0.45, color="#4c72b0", linewidths=0, rasterized=True)
        psi = eyes.psi
        reach = max(r_hi, 1e-9) * 1.05
        for ang in (psi, math.pi - psi):
            ax.plot([0, reach * math.cos(ang)], [0, reach * math.sin(ang)], color="0.35", lw=0.9)
        for rr in (r_lo, r_hi):
            t = np.linspace(psi, math.pi - psi, 200)
            ax.plot(rr * np.cos(t), rr * np.sin(t), color="0.6", lw=0.6, ls="--")
        ax.plot([-eyes.h, eyes.h], [0, 0], "o", color="#c44e52", ms=3)
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
    from eyeviz.reports.common import save_formats

    written = save_formats(fig, path.with_suffix(""), FORMATS, dpi=DPI)
    plt.close(fig)
    return written


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
        "Also as vectors: [dataset.svg](dataset.svg), [dataset.pdf](dataset.pdf).",
        "",
        "| data set | n | m | mode | r range | mean r | g range | phi range (deg) "
        "| distinct bitmap pairs | outer/inner density per area |",
        "|---|---:|---:|---|---|---:|---|---|---:|---:|",
    ]
    for s in summaries:
        lines.append(
            f"| {s.label} | {s.n:,} | {s.m} | {_mode_cell(s)} | {s.r_min:.1f} - {s.r_max:.1f} "
            f"| {s.r_mean:.1f} | {s.g_min:.2f} - {s.g_max:.2f} "
            f"| {s.phi_min_deg:.1f} - {s.phi_max_deg:.1f} | {s.distinct_pairs:,} "
            f"| {s.area_density_ratio:.2f} |"
        )
    lines += [
        "",
        "The mode is the one an NPZ records; a CSV records none, so it is inferred from the "
        "last column (marked *inferred*), or left unknown when that is neither value.",
        "",
        "The last column is the number of centres per unit BFV area in the outer half of "
        "the r range over that in the inner half: about 1 when centres are uniform over the "
        "area (multi-pass, Figure 11), below 1 for a flat histogram of r (one pass, "
        "Figures 8, 10: the density falls as 1/r).",
        "",
    ]
    return "\n".join(lines)


def _mode_cell(s: Summary) -> str:
    return f"{s.mode} (*inferred*)" if s.mode_source == "inferred" else s.mode


def run(args: argparse.Namespace) -> int:
    from eyeviz import EyevizError
    from eyeviz.core.bounds import check_bins
    from eyeviz.core.validation import check_int

    bins = check_bins(args.bins)
    max_points = check_int("--max-points", args.max_points, ge=1, le=MAX_POINTS)
    labels = args.labels or [p.name for p in args.data]
    if len(labels) != len(args.data):
        raise EyevizError(
            f"--labels needs one label per data set ({len(args.data)}), got {len(labels)}"
        )
    summaries = [summarise(p, lab) for p, lab in zip(args.data, labels, strict=True)]
    out = args.output
    out.mkdir(parents=True, exist_ok=True)
    figures = _plot(args.data, summaries, bins, max_points, out / "dataset.png")
    _write_atomic(out / "dataset.md", _markdown(summaries).encode())
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(Summary.FIELDS)
    for s in summaries:
        w.writerow([getattr(s, f) for f in Summary.FIELDS])
    _write_atomic(out / "dataset.csv", buf.getvalue().encode())
    print("wrote " + ", ".join(str(p) for p in [*figures, out / "dataset.md", out / "dataset.csv"]))
    return 0
