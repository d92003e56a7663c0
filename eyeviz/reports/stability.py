"""``eyeviz report stability -o DIR``: the geometry's error against run time.

For every case class of :mod:`eyeviz.reference.stability_cases`, three implementations of Eq. 11
and 22-25 are compared with the mpmath reference (:mod:`eyeviz.reference.digits80`, 80 digits):
(a) the paper's formulas taken literally in float64, (b) the same in float32, (c) the
eyeviz core. A feature counts as a difference when either eye's bitmap differs. The core
as it was before issue 14 (:mod:`eyeviz.reference.legacy_fastpath`) is timed in the same
run, so its cost and the speed-up stand beside the new figures.
"""

from __future__ import annotations

import argparse
import csv
import io
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from eyeviz.core.validation import check_int
from eyeviz.files.atomic import atomic_output

HELP = "numerical stability of the geometry against an 80-digit reference"

METHODS = ("paper float64", "paper float32", "eyeviz core")
OLD = "eyeviz core, before issue 14"
TIMED = (*METHODS, OLD, "reference (mpmath)")
#: Most features per case class (-n): each needs an 80-digit mpmath reference.
MAX_N = 100_000
#: Most balls per case class of the spherical eyes (--n3d): their reference visits every facet.
MAX_N3D = 10_000


@dataclass
class Row:
    case: str
    description: str
    n: int
    m: int
    diffs: dict[str, int]
    seconds_per_feature: dict[str, float]
    exact_fallbacks: int
    exact_ties: int = 0  # decided by the vectorised expansion predicates
    exact_mpmath: int = 0  # decided by mpmath


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("-o", "--output", required=True, type=Path, help="output directory")
    parser.add_argument("-n", type=int, default=2000, help="features per case class (default 2000)")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument(
        "--n3d",
        type=int,
        default=12,
        help="balls per case class of the spherical eyes (default 12; 0 leaves them out: "
        "their reference visits every facet, about 0.3-1.5 s a ball)",
    )


def _timed(fn, repeats: int = 3) -> tuple[object, float]:
    best, out = float("inf"), None
    for _ in range(repeats):
        t = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t)
    return out, best


def measure_case(cs) -> Row:
    """Differences from the reference and time per feature of each method on one class."""
    from eyeviz.core import geometry
    from eyeviz.reference.digits80 import reference_intervals
    from eyeviz.reference.legacy_fastpath import LegacyEyePair
    from eyeviz.reference.paper_formulas import paper_intervals

    e, x, y, g = cs.eyes, cs.x, cs.y, cs.g
    ref, t_ref = _timed(lambda: np.array(reference_intervals(e, x, y, g)), 1)
    runs = {
        "paper float64": lambda: paper_intervals(e.h, e.m, x, y, g, np.float64),
        "paper float32": lambda: paper_intervals(e.h, e.m, x, y, g, np.float32),
        "eyeviz core": lambda: e.intervals(x, y, g),
    }
    diffs, times = {}, {"reference (mpmath)": t_ref / x.size}
    for method, fn in runs.items():
        out, t = _timed(fn)
        diffs[method] = int((np.array(out) != ref).any(axis=0).sum())
        times[method] = t / x.size
    old = LegacyEyePair.of(e)
    out, t = _timed(lambda: old.intervals(x, y, g), 1)  # slow on ties: once
    if (np.array(out) != ref).any():
        raise AssertionError(f"the legacy core differs from the reference on {cs.name}")
    times[OLD] = t / x.size
    geometry.FALLBACK_COUNTS.clear()
    e.intervals(x, y, g)
    c = geometry.FALLBACK_COUNTS
    return Row(
        cs.name, cs.description, int(x.size), e.m, diffs, times, c["exact"], c["ties"], c["mpmath"]
    )


def measure(n: int = 2000, seed: int = 0, progress=None) -> list[Row]:
    """Run every case class; returns one :class:`Row` per class."""
    from eyeviz.reference import stability_cases

    rows = []
    for i, name in enumerate(stability_cases.CLASSES):
        rows.append(measure_case(stability_cases.make(name, n, seed + i)))
        if progress:
            progress(name)
    return rows


def _markdown(rows: list[Row]) -> str:
    out = io.StringIO()
    out.write("# Numerical stability of the geometry\n\n")
    out.write(
        "Features whose bitmaps (either eye) differ from an 80-digit mpmath reference, and the\n"
        "time per feature. (a) and (b) are the paper's Eq. 11 and 22-25 taken literally\n"
        "(arccos form, valid for 0 <= phi <= pi only, so features below the x-axis come out\n"
        "mirrored); (c) is eyeviz's core: float64 with an exact fallback on the elements near a\n"
        "boundary ('exact' column: how many of them per class; 'ties' of those were decided\n"
        "vectorised with floating-point expansions, 'mpmath' one at a time). The core as it\n"
        "was before issue 14 is timed in the same run: its cost per feature, and the new\n"
        "core's speed-up over it, stand in the last columns.\n\n"
    )
    out.write("| case | n | m | " + " | ".join(f"{m} diffs" for m in METHODS))
    out.write(" | exact | ties | mpmath | " + " | ".join(f"{m} µs" for m in TIMED))
    out.write(" | speed-up vs before | core / paper regime |\n")
    out.write("|" + "---|" * (3 + len(METHODS) + 3 + len(TIMED) + 2) + "\n")
    paper = rows[0].seconds_per_feature["eyeviz core"] if rows else 1.0
    for r in rows:
        t = r.seconds_per_feature
        cells = [r.case, str(r.n), str(r.m)]
        cells += [f"{r.diffs[m]} ({100 * r.diffs[m] / r.n:.1f} %)" for m in METHODS]
        cells += [str(r.exact_fallbacks), str(r.exact_ties), str(r.exact_mpmath)]
        cells += [f"{1e6 * t[m]:.3g}" for m in TIMED]
        cells += [f"{t[OLD] / t['eyeviz core']:.3g}x", f"{t['eyeviz core'] / paper:.3g}x"]
        out.write("| " + " | ".join(cells) + " |\n")
    out.write("\nCase classes:\n\n")
    for r in rows:
        out.write(f"- **{r.case}**: {r.description}\n")
    return out.getvalue()


def _plot(rows: list[Row], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    colors = {
        "paper float64": "#E69F00",
        "paper float32": "#CC79A7",
        "eyeviz core": "#0072B2",
        OLD: "#56B4E9",
    }
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4.2), constrained_layout=True)
    y = np.arange(len(rows))
    h = 0.27
    for j, m in enumerate(METHODS):
        frac = [100 * r.diffs[m] / r.n for r in rows]
        ax1.barh(y + (j - 1) * h, frac, h, label=m, color=colors[m])
        for yi, f in zip(y, frac, strict=True):
            if f == 0:
                ax1.text(0.3, yi + (j - 1) * h, "0", va="center", fontsize=7, color=colors[m])
    ax1.set_yticks(y, [r.case for r in rows])
    ax1.invert_yaxis()
    ax1.set_xlabel("features with a wrong bitmap (%)")
    ax1.set_title("error against the 80-digit reference")
    ax1.legend(loc="lower right", fontsize=8)
    for m in TIMED:
        t = [1e9 * r.seconds_per_feature[m] for r in rows]
        err = [max(100 * r.diffs.get(m, 0) / r.n, 0.01) for r in rows]
        ax2.scatter(t, err, label=m, color=colors.get(m, "#555555"), s=30)
    ax2.set_xscale("log")
    ax2.set_yscale("log")
    ax2.set_xlabel("run time per feature (ns, log)")
    ax2.set_ylabel("wrong bitmaps (%, 0 drawn at 0.01)")
    ax2.set_title("error against run time (one point per case class)")
    ax2.legend(fontsize=8)
    ax2.grid(True, which="both", alpha=0.3)
    fig.savefig(path, dpi=130)
    plt.close(fig)


def _write_atomic(path: Path, writer) -> None:
    with atomic_output(path) as tmp:
        writer(tmp)


def write(rows: list[Row], outdir: Path) -> None:
    outdir.mkdir(parents=True, exist_ok=True)
    _write_atomic(outdir / "stability.md", lambda p: p.write_text(_markdown(rows)))

    def csv_writer(p: Path) -> None:
        with open(p, "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(
                ["case", "n", "m", *(f"diffs {m}" for m in METHODS), "exact fallbacks"]
                + ["exact ties", "exact mpmath"]
                + [f"s/feature {m}" for m in TIMED]
                + ["speed-up vs before"]
            )
            for r in rows:
                t = r.seconds_per_feature
                w.writerow(
                    [r.case, r.n, r.m, *(r.diffs[m] for m in METHODS), r.exact_fallbacks]
                    + [r.exact_ties, r.exact_mpmath]
                    + [t[m] for m in TIMED]
                    + [t[OLD] / t["eyeviz core"]]
                )

    _write_atomic(outdir / "stability.csv", csv_writer)
    _write_atomic(outdir / "stability.png", lambda p: _plot(rows, p))


def run(args: argparse.Namespace) -> int:
    check_int("-n", args.n, ge=1, le=MAX_N)
    check_int("--n3d", args.n3d, ge=0, le=MAX_N3D)
    from tqdm import tqdm

    from eyeviz.reference import stability_cases

    with tqdm(total=len(stability_cases.CLASSES), desc="stability", unit="class") as bar:
        rows = measure(args.n, args.seed, progress=lambda _name: bar.update())
    write(rows, args.output)
    core_diffs = sum(r.diffs["eyeviz core"] for r in rows)
    print(
        f"wrote {args.output / 'stability.md'} (.csv, .png); eyeviz core differences: {core_diffs}"
    )
    if args.n3d:
        from eyeviz.reference import stability_cases3d
        from eyeviz.reports.stability3d import measure3d, write3d

        classes = len(stability_cases3d.CLASSES)
        with tqdm(total=classes, desc="stability 3D", unit="class") as bar:
            rows3 = measure3d(args.n3d, args.seed, progress=lambda _name: bar.update())
        write3d(rows3, args.output)
        diffs3 = sum(r.diffs["eyeviz core"] for r in rows3)
        print(
            f"wrote {args.output / 'stability3d.md'} (.csv, .png); eyeviz core differences "
            f"(spherical eyes): {diffs3}"
        )
        core_diffs += diffs3
    return 0 if core_diffs == 0 else 1
