"""``eyeviz report estimators -o DIR``: error against run time for every estimator.

On fresh test sets generated with the paper's parameters (Tables 3 and 4; single- and
multi-pass, seeds unlike any training seed), each estimator is scored on azimuth (AD, phi)
and distance (DD, r): MAPE (Eq. 34), MAE (Eq. 33) and R^2. R^2 is the standard one
(1 - SS_res/SS_tot with SS_tot the spread of the TRUE values, as scikit-learn's
``r2_score``), not Eq. 35-36's spread of the predictions (docs/conventions.md).
Beside the metrics: training time (from the estimator's metadata), inference time per
sample when batched and for one sample alone, and the number of learned weights. The
paper's Table 5 is quoted as a reference row; the bayes estimator is the information
limit (the best error any estimator can reach from the bitmaps).

Estimators that cannot be loaded (the paper nets without weights, say) are listed with
the reason, never crashed on. Output: ``estimators.md``, ``estimators.csv``,
``estimators.png`` (error against inference time, log axes).

With ``--data FILE`` (a sparse data set of HEALPix or measured eyes), ``--nside N`` (a
fresh HEALPix test set) or ``--eye FILE`` (a fresh test set of a measured pair) the report
is that of the eyes that see lit sets instead: on that data set (or a fresh one of
``--n-test`` rows drawn from the 3D Algorithm 1 with ``--seed``), every estimator that
answers for those eyes (registry kind "spherical": analytic3d, limit3d, learned3d, ...)
is scored on distance (DD: MAPE of r, Eq. 34), azimuth (AD: MAPE of the azimuth) and
elevation (MAPE of the elevation, and its mean absolute error in degrees: the elevation
crosses 0, where a relative error blows up, so the MAE is the figure to read), with the
rows it flagged (answered by a fallback). Run time: microseconds per row when batched,
milliseconds for one row alone. The limit costs milliseconds per row, so it is measured
on at most ``--limit-rows`` evenly spaced rows; every estimator is also scored on those
same rows (the "subset" columns), which is the like-for-like comparison. Output:
``estimators3d.md``, ``estimators3d.csv``, ``estimators3d.png`` (error against run time,
log axes).

One report for every eye model: the measuring (:mod:`~eyeviz.reports.estimators_measure`:
one :class:`~eyeviz.reports.estimators_measure.Result` for the planar eyes' two
coordinates and the lit sets' three with their flagged rows), the tables
(:mod:`~eyeviz.reports.estimators_table`) and the figures
(:mod:`~eyeviz.reports.estimators_plot`) each hold both sides; :func:`write` picks the
files' names and writers by the side of the data contract (:data:`WRITERS`).
"""

from __future__ import annotations

import argparse
from collections.abc import Callable
from pathlib import Path

from eyeviz.core.validation import check_int
from eyeviz.files import limits
from eyeviz.reports.common import (
    accuracy_metrics,
    parse_names,
    save_figure,
    try_load,
    write_atomic,
)
from eyeviz.reports.estimators_measure import (
    PAPER_TABLE5,
    TARGETS,
    TEST_SEED,
    TEST_SETS,
    Result,
    _fmt_weights,
    _limit,
    _time_batched,
    _time_single,
    make_test_sets,
    measure,
    measure_lit,
    measure_one,
)
from eyeviz.reports.estimators_plot import _COLORS, plot, plot_lit
from eyeviz.reports.estimators_table import (
    CSV_FIELDS,
    _descriptions,
    _fmt,
    _fmt_time,
    to_csv,
    to_csv_lit,
    to_markdown,
    to_markdown_lit,
)

# The measuring, the tables and the figure live in estimators_measure, estimators_table and
# estimators_plot, the helpers shared with the trajectories report in common; their names
# stay importable from here (the tests use several of them).
__all__ = [
    "CSV_FIELDS",
    "HELP",
    "WRITERS",
    "PAPER_TABLE5",
    "TARGETS",
    "TEST_SEED",
    "TEST_SETS",
    "Result",
    "_COLORS",
    "_descriptions",
    "_fmt",
    "_fmt_time",
    "_fmt_weights",
    "_limit",
    "_time_batched",
    "_time_single",
    "accuracy_metrics",
    "add_arguments",
    "make_test_sets",
    "measure",
    "measure_lit",
    "measure_one",
    "parse_names",
    "plot",
    "plot_lit",
    "run",
    "save_figure",
    "to_csv",
    "to_csv_lit",
    "to_markdown",
    "to_markdown_lit",
    "try_load",
    "write",
    "write_atomic",
]

HELP = "estimators' AD/DD error, training and inference time (error against run time)"


def _markdown_planar(results: list[Result], what: tuple[int, int], png: str) -> str:
    n_test, seed = what
    return to_markdown(results, n_test, seed, png)


#: Per side of the data contract, the planar eyes' bitmaps ("planar") or the lit sets of
#: every other model ("lit": spherical, measured, a new one): the files' stem, the figure,
#: the CSV, and the Markdown given the results, the test sets' description (planar:
#: (n_test, seed); lit sets: the data set's sentence) and the figure's file name.
WRITERS: dict[str, tuple[str, Callable, Callable, Callable]] = {
    "planar": ("estimators", plot, to_csv, _markdown_planar),
    "lit": ("estimators3d", plot_lit, to_csv_lit, to_markdown_lit),
}


def write(results: list[Result], outdir: Path, side: str, what) -> list[Path]:
    """The report's Markdown, CSV and figure for one side of the data (:data:`WRITERS`)."""
    import matplotlib.pyplot as plt

    stem, figure, table, markdown = WRITERS[side]
    outdir.mkdir(parents=True, exist_ok=True)
    png = outdir / f"{stem}.png"
    fig = figure(results)
    save_figure(fig, png)
    plt.close(fig)
    write_atomic(outdir / f"{stem}.csv", table(results))
    write_atomic(outdir / f"{stem}.md", markdown(results, what, png.name))
    return [outdir / f"{stem}.md", outdir / f"{stem}.csv", png]


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("-o", "--output", required=True, type=Path, help="output directory")
    parser.add_argument(
        "--n-test",
        type=int,
        default=20000,
        help="elements per test set (default 20000, the paper's test sample)",
    )
    parser.add_argument(
        "--estimators", default=None, help="comma-separated names (default: all available)"
    )
    parser.add_argument(
        "--seed",
        type=int,
        default=TEST_SEED,
        help=f"test-set seed; multi-pass uses seed+1 (default {TEST_SEED})",
    )
    parser.add_argument(
        "--data",
        type=Path,
        default=None,
        help="spherical eyes: score the 3D estimators on this sparse 3D data set "
        "(eyeviz generate --nside)",
    )
    parser.add_argument(
        "--nside",
        type=int,
        default=None,
        help="spherical eyes: score the 3D estimators on a fresh 3D test set of --n-test "
        "rows at this nside (the paper's h, l, ranges; seed --seed)",
    )
    parser.add_argument(
        "--eye",
        type=Path,
        default=None,
        metavar="FILE",
        help="measured eyes: score the estimators that answer for them on a fresh test "
        "set of --n-test rows of this eye file (.eye, millimetres; ranges at the "
        "animal's scale; seed --seed)",
    )
    parser.add_argument(
        "--limit-rows",
        type=int,
        default=1000,
        help="spherical eyes: the limit (ms per row) on at most this many evenly spaced "
        "rows, where every estimator is also scored (default 1000)",
    )


# long: the report's one sequence (read or generate, predict each estimator, write), each step
# with its own one-line error
def run_lit(args: argparse.Namespace) -> int:
    """The report of the eyes that see lit sets (``--data``, ``--nside`` or ``--eye``)."""
    from eyeviz import EyevizError
    from eyeviz.estimators import registry
    from eyeviz.reports.errors import with_error

    given = [f for f in ("data", "nside", "eye") if getattr(args, f, None) is not None]
    if len(given) > 1:
        both = "both " if len(given) == 2 else "all of "
        raise EyevizError(
            f"give one of --data, --nside, --eye, not {both}--{' and --'.join(given)}"
        )
    check_int("--limit-rows", args.limit_rows, ge=1, le=limits.MAX_ROWS)
    if args.data is not None:
        from eyeviz.dataset.kinds import data_format, kind_of

        fmt = data_format(kind_of(args.data))
        if fmt.domain_flags:  # a file that needs --h --l --m: not a data set of lit sets
            raise EyevizError(
                f"--data {args.data} is {fmt.what}; --data takes a data set that carries "
                "its eyes (eyeviz generate --nside or --eye); the planar estimators are "
                "scored on fresh test sets (no --data)"
            )
        ds = fmt.call("loader", args.data)
        if len(ds) == 0:  # "metrics need at least one value" named no file (issue 36)
            raise EyevizError(f"data set {args.data} has no rows: there is nothing to measure")
        d = ds.domain
        eyes = (
            f"nside = {d.nside}"
            if d.kind == "spherical"
            else f"a measured pair of {d.facet_counts[0]} + {d.facet_counts[1]} facets "
            f"(fingerprint {str(d.eyes.fingerprint)[:12]}), r in [{d.r_min:.4g}, "
            f"{d.r_max:.4g}], g <= {d.g_max:.4g}, about the lens centroids' midpoint"
        )
        what = (
            f"Data set `{Path(args.data).name}`: {len(ds)} rows, h = {d.h:g}, "
            f"l = {d.l:g}, {eyes}, params {ds.params}."
        )
    elif getattr(args, "eye", None) is not None:
        from eyeviz.core.domain import domain_for
        from eyeviz.dataset import kinds
        from eyeviz.files.eye_io import eye_path, load_eyes

        check_int("--n-test", args.n_test, ge=10, le=limits.MAX_ROWS)
        args.eye = eye_path(args.eye)  # a file, or a shipped eye's name
        pair = load_eyes(args.eye)
        ds = kinds.sample(args.n_test, domain_for(pair), "single", args.seed)
        d = ds.domain
        what = (
            f"A fresh test set: {len(ds)} rows of Algorithm 1 (single pass, seed {args.seed}) "
            f"on the measured eyes `{args.eye.name}` ({d.facet_counts[0]} + "
            f"{d.facet_counts[1]} facets), r in [{d.r_min:.4g}, {d.r_max:.4g}] mm, g <= "
            f"{d.g_max:.4g} mm, about the lens centroids' midpoint."
        )
    else:
        from eyeviz.core.domain import domain_for
        from eyeviz.core.geometry3d import EyePair3D
        from eyeviz.dataset import kinds

        check_int("--n-test", args.n_test, ge=10, le=limits.MAX_ROWS)
        ds = kinds.sample(args.n_test, domain_for(EyePair3D(nside=args.nside)), "single", args.seed)
        what = (
            f"A fresh test set: {len(ds)} rows of the 3D Algorithm 1 (single pass, seed "
            f"{args.seed}), the paper's design at nside = {args.nside}."
        )
    avail = registry.available("spherical")
    if args.estimators is None:
        names = registry.available_for(ds.domain.kind)
    else:
        names = [s for s in str(args.estimators).replace(",", " ").split() if s]
        bad = [s for s in names if s not in avail]
        if bad or not names:
            raise EyevizError(
                f"unknown 3D estimator(s) {', '.join(bad) or '(none given)'}; available: "
                f"{', '.join(avail)}"
            )
    results = measure_lit(ds, names, args.limit_rows)
    paths = write(results, args.output, "lit", what)
    for r in results:
        if r.ok:
            m, e = r.metrics["subset"], r.errors["subset"]
            dd, ad, el = (with_error(m[k], e[k]) for k in ("dd", "ad", "el_mae_deg"))
            print(
                f"{r.name:11s} DD MAPE {dd} %  AD MAPE {ad} %  el MAE {el} deg  "
                f"{r.batched_us:.3g} µs/row (subset of "
                f"{len(range(0, len(ds), max(1, -(-len(ds) // args.limit_rows))))} rows)"
            )
        else:
            print(f"{r.name:11s} unavailable: {r.status}")
    print("wrote " + ", ".join(str(p) for p in paths))
    return 0


def run(args: argparse.Namespace) -> int:
    from tqdm import tqdm

    if any(getattr(args, f, None) is not None for f in ("data", "nside", "eye")):
        return run_lit(args)
    check_int("--n-test", args.n_test, ge=10, le=limits.MAX_ROWS)
    names = parse_names(args.estimators)
    bar = tqdm(total=len(names), desc="estimators", unit="est", leave=False)

    def progress(name):
        bar.set_postfix_str(name)
        bar.update(1)

    results = measure(names, args.n_test, args.seed, progress)
    bar.close()
    paths = write(results, args.output, "planar", (args.n_test, args.seed))
    for r in results:
        if r.ok:
            e = r.metrics["single"]
            print(
                f"{r.name:9s} AD MAPE {e['ad']['mape']:.3f} %  DD MAPE {e['dd']['mape']:.3f} %  "
                f"R^2 {e['dd']['r2']:.4f}  {r.batched_us:.3g} µs/sample  "
                f"{r.single_ms:.3g} ms single"
            )
        else:
            print(f"{r.name:9s} unavailable: {r.status}")
    print("wrote " + ", ".join(str(p) for p in paths))
    return 0
