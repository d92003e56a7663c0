"""``eyeviz report information -o DIR``: what graded responses are worth against bitmaps.

With photon noise (Poisson, N photons a facet at full coverage) the graded responses
bound how well a ball's distance can be known (a Cramer-Rao bound from the exact
responses' derivatives, :mod:`eyeviz.reports.information_measure`); the binary bitmaps'
best estimate sets the other side. At the paper's planar design, at a HEALPix pair
(nside 180) and at the honeybee: the photons a facet from which grades beat the bitmaps,
and by how much at N (issue 34.5; docs/renderers.md). Every figure has a bootstrap
standard error over the balls, the crossovers a 95 % bootstrap interval
(:func:`eyeviz.reports.information_measure.ball_bootstrap`).

Writes ``information.md``, ``information.csv`` (one row per model), ``balls.csv`` (per
ball: r, the bound at N = 1, the binary error) and the figure ``information.png`` (also
``.svg`` and ``.pdf``) into DIR (atomically, through ``eyeviz report``).
"""

from __future__ import annotations

import argparse
import csv
import io
import math
from pathlib import Path

import numpy as np

from eyeviz.core.validation import check_int
from eyeviz.reports.errors import N_BOOT

HELP = "graded responses under photon noise against the bitmaps: a Cramer-Rao bound on distance"

MAX_BALLS = 100_000
MAX_PHOTONS = 1e12
FORMATS = ("png", "svg", "pdf")
COLORS = ("#4c72b0", "#c44e52", "#55a868", "#8172b3")


def add_arguments(parser: argparse.ArgumentParser) -> None:
    from eyeviz.reports.information_measure import DEFAULT_PHOTONS

    parser.add_argument("-o", "--output", required=True, type=Path, help="output directory")
    parser.add_argument(
        "--photons",
        type=float,
        default=DEFAULT_PHOTONS,
        help=f"photons a facet catches at full coverage (default {DEFAULT_PHOTONS})",
    )
    parser.add_argument(
        "--planar-balls", type=int, default=400, help="features of the planar design (400)"
    )
    parser.add_argument(
        "--bee-balls", type=int, default=60, help="balls at the honeybee (default 60)"
    )
    parser.add_argument(
        "--healpix-balls",
        type=int,
        default=8,
        help="balls at the HEALPix pair (default 8, 0 leaves it out)",
    )
    parser.add_argument("--nside", type=int, default=180, help="the HEALPix pair's nside (180)")
    parser.add_argument(
        "--kind",
        choices=("gaussian", "flat"),
        default="gaussian",
        help="the honeybee's response kernel (default gaussian)",
    )
    parser.add_argument("--seed", type=int, default=0)


def _check(args: argparse.Namespace) -> None:
    check_int("--planar-balls", args.planar_balls, ge=0, le=MAX_BALLS)
    check_int("--bee-balls", args.bee_balls, ge=0, le=MAX_BALLS)
    check_int("--healpix-balls", args.healpix_balls, ge=0, le=MAX_BALLS)
    check_int("--nside", args.nside, ge=2, le=1024, even=True)
    if not (math.isfinite(args.photons) and 0 < args.photons <= MAX_PHOTONS):
        raise ValueError(f"--photons must be > 0 and <= 1e12, got {args.photons}")
    if args.planar_balls + args.bee_balls + args.healpix_balls == 0:
        raise ValueError("every model has 0 balls: nothing to measure")


def measure(args: argparse.Namespace) -> list:
    """One :class:`ModelResult` per model with balls."""
    from eyeviz.files.eye_io import load_eyes, shipped_eye
    from eyeviz.reports import information_measure as M

    out = []
    if args.planar_balls:
        out.append(M.measure_planar(args.planar_balls, args.seed))
    if args.healpix_balls:
        out.append(M.measure_healpix(args.nside, args.healpix_balls, args.seed + 1))
    if args.bee_balls:
        pair = load_eyes(shipped_eye("AM_60185-real.eye"))
        out.append(M.measure_measured("honeybee", pair, args.bee_balls, args.seed + 2, args.kind))
    return out


def _pct(value: float, se: float) -> str:
    """A relative error in percent with its standard error, to the precision it allows."""
    from eyeviz.reports.errors import with_error

    return with_error(100 * value, 100 * se) + " %"


def _interval(m, e, key: str) -> str:
    return f"{getattr(m, key):.3g} ({e.low[key]:.3g}-{e.high[key]:.3g})"


def _ratio(m, e, key: str, photons: float) -> str:
    """binary / graded at N = sqrt(N / N*), with the interval N*'s maps to (monotone)."""
    val, lo, hi = (math.sqrt(photons / x) for x in (getattr(m, key), e.high[key], e.low[key]))
    return f"{val:.3g}x ({lo:.3g}-{hi:.3g})"


def _markdown(results, photons: float, errors) -> str:
    o = io.StringIO()
    o.write("# What grades are worth: graded responses under photon noise against bitmaps\n\n")
    o.write("![relative error of distance against photons](information.png)\n\n")
    o.write(
        "Also as vectors: [information.svg](information.svg), "
        "[information.pdf](information.pdf).\n\n"
    )
    o.write(
        "Graded: the Cramer-Rao bound on the distance r of a ball from Poisson photon counts "
        "of every lit facet (mean N x the exact response), relative RMS over the balls; it "
        "falls as 1/sqrt(N). Binary: the relative RMS error of r of the best estimate the "
        "project has from the bitmaps, on the same balls. N*: the photons a facet (at full "
        "coverage) from which the graded bound is below the binary error (RMS; and in "
        "medians of |relative error|, the graded one at the bound's Gaussian median). "
        f"Errors: bootstrap standard errors over the balls ({N_BOOT:,} resamples of the "
        "balls both sides answer, seed 0); N* and the ratios with their 95 % bootstrap "
        "intervals.\n\n"
    )
    o.write(
        f"| model | kind | balls | binary estimate | binary RMS | binary median | graded RMS at "
        f"N = {photons:g} | graded median at N | binary / graded at N (RMS) | binary / graded at "
        "N (medians) | N* (RMS) | "
        "N* (medians) | finite-difference check (h vs h/2: median, max) | balls without a "
        "bound | not settled |\n"
    )
    o.write("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n")
    for m, e in zip(results, errors, strict=True):
        g = m.graded_rms(photons)
        o.write(
            f"| {m.description} | {m.kind} | {m.n_balls} | {m.binary_name} | "
            f"{_pct(m.binary_rms, e.se['binary_rms'])} | "
            f"{_pct(m.binary_median, e.se['binary_median'])} | "
            f"{_pct(g, e.graded_rms_se(photons))} | "
            f"{_pct(m.graded_median(photons), e.graded_median_se(photons))} | "
            f"{_ratio(m, e, 'crossover', photons)} | "
            f"{_ratio(m, e, 'crossover_median', photons)} | {_interval(m, e, 'crossover')} | "
            f"{_interval(m, e, 'crossover_median')} | "
            f"{m.fd_change:.1e}, {m.fd_change_max:.1e} | {m.dropped} | {m.unresolved} |\n"
        )
    notes = [n for m in results for n in m.notes]
    if notes:
        o.write("\n" + "\n".join(f"- {m.name}: {n}" for m in results for n in m.notes) + "\n")
    return o.getvalue()


def _csv(results, photons: float, errors) -> tuple[str, str]:
    a, b = io.StringIO(), io.StringIO()
    w = csv.writer(a, lineterminator="\n")
    w.writerow(
        ["model", "kind", "balls", "binary_estimate", "binary_rms", "binary_rms_se",
         "binary_median", "binary_median_se", "graded_rms_at_n", "graded_rms_at_n_se",
         "graded_median_at_n", "graded_median_at_n_se", "photons", "crossover_rms",
         "crossover_rms_se", "crossover_rms_low", "crossover_rms_high", "crossover_median",
         "crossover_median_se", "crossover_median_low", "crossover_median_high",
         "fd_change_median", "fd_change_max", "balls_without_bound", "balls_not_settled"]
    )  # fmt: skip
    for m, e in zip(results, errors, strict=True):
        w.writerow(
            [m.name, m.kind, m.n_balls, m.binary_name, f"{m.binary_rms:.6g}",
             f"{e.se['binary_rms']:.3g}", f"{m.binary_median:.6g}",
             f"{e.se['binary_median']:.3g}", f"{m.graded_rms(photons):.6g}",
             f"{e.graded_rms_se(photons):.3g}", f"{m.graded_median(photons):.6g}",
             f"{e.graded_median_se(photons):.3g}", photons, f"{m.crossover:.6g}",
             f"{e.se['crossover']:.3g}", f"{e.low['crossover']:.3g}",
             f"{e.high['crossover']:.3g}", f"{m.crossover_median:.6g}",
             f"{e.se['crossover_median']:.3g}", f"{e.low['crossover_median']:.3g}",
             f"{e.high['crossover_median']:.3g}", f"{m.fd_change:.3g}",
             f"{m.fd_change_max:.3g}", m.dropped, m.unresolved]
        )  # fmt: skip
    w2 = csv.writer(b, lineterminator="\n")
    w2.writerow(["model", "r", "crb_var_r_at_1_photon", "binary_relative_error"])
    for m in results:
        for r, c, e in zip(m.r, m.crb1, m.binary_rel, strict=True):
            w2.writerow([m.name, f"{r:.9g}", f"{c:.6g}", f"{e:.6g}"])
    return a.getvalue(), b.getvalue()


def _plot(results, photons: float, path: Path, errors) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from eyeviz.reports.common import save_formats

    fig, (ax, bx) = plt.subplots(1, 2, figsize=(12.5, 4.8), constrained_layout=True)
    ns = np.logspace(0, 6, 61)
    for m, e, c in zip(results, errors, COLORS, strict=False):
        ax.plot(ns, [m.graded_rms(n) for n in ns], color=c, lw=2, label=f"{m.name}: graded")
        ax.axhline(m.binary_rms, color=c, ls="--", lw=1.3, label=f"{m.name}: bitmaps")
        if 1 <= m.crossover <= 1e6:
            ax.plot([m.crossover], [m.binary_rms], "o", color=c, ms=7)
            right = m.crossover > 1e3  # the label to the left near the axis' end
            ax.annotate(f"N* = {_interval(m, e, 'crossover')}", (m.crossover, m.binary_rms),
                        textcoords="offset points", xytext=(-6 if right else 6, 6),
                        ha="right" if right else "left", fontsize=8, color=c)  # fmt: skip
        ok = m.ok
        scale = float(np.max(m.r))
        bx.scatter(m.r[ok] / scale, np.abs(m.binary_rel[ok]), s=9, color=c, marker="x",
                   alpha=0.6, linewidths=0.8, label=f"{m.name}: bitmaps |error|")  # fmt: skip
        bx.scatter(m.r[ok] / scale, np.sqrt(m.crb1[ok] / photons) / m.r[ok], s=9, color=c,
                   alpha=0.6, label=f"{m.name}: graded bound")  # fmt: skip
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("photons a facet at full coverage, N")
    ax.set_ylabel("relative RMS error of the distance r")
    ax.set_title("graded (Cramer-Rao) against bitmaps (best estimate)", fontsize=10)
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=7.5, frameon=False, loc="lower left")
    bx.set_yscale("log")
    bx.set_xlabel("r / largest r of the model's balls")
    bx.set_ylabel("relative error of r (per ball)")
    bx.set_title(f"per ball, graded at N = {photons:g}", fontsize=10)
    bx.grid(alpha=0.3, which="both")
    bx.legend(fontsize=7, frameon=False, loc="lower right", ncol=2)
    fig.suptitle("What grades are worth (issue 34.5)", fontsize=11)
    fig.canvas.draw()
    fig.set_layout_engine("none")
    save_formats(fig, path.with_suffix(""), FORMATS, dpi=170)
    plt.close(fig)


def run(args: argparse.Namespace) -> int:
    from eyeviz.reports.common import write_atomic

    _check(args)
    from eyeviz.reports.information_measure import ball_bootstrap

    results = measure(args)
    errors = [ball_bootstrap(m) for m in results]
    out: Path = args.output
    out.mkdir(parents=True, exist_ok=True)
    _plot(results, args.photons, out / "information.png", errors)
    write_atomic(out / "information.md", _markdown(results, args.photons, errors))
    table, balls = _csv(results, args.photons, errors)
    write_atomic(out / "information.csv", table)
    write_atomic(out / "balls.csv", balls)
    for m, e in zip(results, errors, strict=True):
        print(
            f"{m.name}: bitmaps {_pct(m.binary_rms, e.se['binary_rms'])} RMS, graded "
            f"{_pct(m.graded_rms(args.photons), e.graded_rms_se(args.photons))} at "
            f"N = {args.photons:g}; grades win from N* = {_interval(m, e, 'crossover')} photons"
        )
    print(f"wrote {out / 'information.md'}")
    return 0
