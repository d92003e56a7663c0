"""``eyeviz report trajectories -o DIR``: the experiments of Section 6 (Figures 14-17).

Circular features of radius g in {5, 50, 500} move along three kinds of trajectory
(:mod:`eyeviz.model.trajectories`): horizontal lines y = r and circles of radius r about the
origin for r = 1000, 2000, ..., 10000, and the central axis x = 0 from y = 1000 to 10000.
Section 6 places 1.5r/g, r/g and 4500/g features on them; those counts are used, clipped
to [--min-count, --max-count] (the paper's 3 features for g = 500 on the nearest line
give no stable mean; 3000 for g = 5 at r = 10000 add nothing but time). The vertical
axis is scored per 1000-long segment, so it gives a curve like the others.

Accuracy = 100 % - MAPE (Section 6) of the azimuth phi (AD) and the distance r (DD)
along each trajectory, per estimator, all estimators on the same axes. Points and levels
stated in the text of Section 6 for the paper's nets are drawn in grey for comparison.
The nets of the paper (and the compact ones) were trained on r in [1000, 5000]; the
shaded part of each plot lies outside that domain. ``limit`` (the information limit,
:mod:`eyeviz.estimators.limit`) is computed for Algorithm 1's single-pass prior over
r in [1000, 10000] (:data:`LIMIT_DOMAIN`), so it covers every trajectory; where a feature
is one the prior cannot draw (g = 5 beyond r = 1146: g < r sin(gamma/2)) its key has an
empty posterior, is answered by triangulation and counted in ``n_flagged``. The report
lists plainly where the limit itself is below a level the paper states.

Output: ``trajectories.md``, ``trajectories.csv`` and one PNG per trajectory kind.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from eyeviz import EyevizError
from eyeviz.core.validation import check_int
from eyeviz.reports.common import parse_names, save_figure, try_load, write_atomic
from eyeviz.reports.trajectories_measure import (
    DISTANCES,
    G_VALUES,
    KINDS,
    LIMIT_DOMAIN_KW,
    MAX_COUNT,
    PAPER_LEVELS,
    PAPER_TEXT,
    PAPER_TEXT_SUMMARY,
    TRAIN_R,
    Point,
    _accuracy,
    measure,
    trajectory_points,
)
from eyeviz.reports.trajectories_plot import plot
from eyeviz.reports.trajectories_table import _table, limit_below_paper, to_csv, to_markdown

# The measuring, the tables and the figures live in trajectories_measure, trajectories_table
# and trajectories_plot; their names stay importable from here (scripts/check_limit.py and
# the tests use several of them).
__all__ = [
    "DISTANCES",
    "G_VALUES",
    "HELP",
    "KINDS",
    "LIMIT_DOMAIN_KW",
    "MAX_COUNT",
    "PAPER_LEVELS",
    "PAPER_TEXT",
    "PAPER_TEXT_SUMMARY",
    "TRAIN_R",
    "Point",
    "_accuracy",
    "_table",
    "add_arguments",
    "limit_below_paper",
    "measure",
    "parse_names",
    "plot",
    "run",
    "save_figure",
    "to_csv",
    "to_markdown",
    "trajectory_points",
    "try_load",
    "write",
    "write_atomic",
]

HELP = "accuracy along the paper's test trajectories (Section 6, Figures 15-17)"


def write(points, missing, names, outdir: Path, lo: int, hi: int) -> list[Path]:
    import matplotlib.pyplot as plt

    outdir.mkdir(parents=True, exist_ok=True)
    shown = [n for n in names if n not in missing]
    pngs = {}
    paths = []
    for kind in KINDS:
        if not any(p.kind == kind for p in points) and shown:
            continue
        fig = plot(points, kind, shown)
        path = outdir / f"trajectories_{kind}.png"
        save_figure(fig, path)
        plt.close(fig)
        pngs[kind] = path.name
        paths.append(path)
    write_atomic(outdir / "trajectories.csv", to_csv(points))
    write_atomic(outdir / "trajectories.md", to_markdown(points, missing, names, lo, hi, pngs))
    return [outdir / "trajectories.md", outdir / "trajectories.csv", *paths]


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("-o", "--output", required=True, type=Path, help="output directory")
    parser.add_argument(
        "--estimators", default=None, help="comma-separated names (default: all available)"
    )
    parser.add_argument(
        "--min-count", type=int, default=30, help="fewest features per trajectory (default 30)"
    )
    parser.add_argument(
        "--max-count", type=int, default=2000, help="most features per trajectory (default 2000)"
    )


def run(args: argparse.Namespace) -> int:
    from tqdm import tqdm

    check_int("--min-count", args.min_count, ge=1, le=MAX_COUNT)
    check_int("--max-count", args.max_count, ge=1, le=MAX_COUNT)
    if args.max_count < args.min_count:
        raise EyevizError(
            f"--max-count must be >= --min-count, got {args.max_count} < {args.min_count}"
        )
    names = parse_names(args.estimators)
    bar = tqdm(total=len(KINDS) * len(G_VALUES), desc="trajectories", leave=False)

    def progress(what):
        bar.set_postfix_str(what)
        bar.update(1)

    points, missing = measure(names, args.min_count, args.max_count, progress=progress)
    bar.close()
    paths = write(points, missing, names, args.output, args.min_count, args.max_count)
    for name, why in missing.items():
        print(f"{name}: unavailable: {why}")
    print("wrote " + ", ".join(str(p) for p in paths))
    return 0
