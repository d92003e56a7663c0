"""``eyeviz report renderers -o DIR``: how well the field's renderers sample a facet.

Every renderer in the field estimates a facet's graded response by casting rays. This
report sets four samplers (:mod:`eyeviz.reference.samplers`: a true 2-D Gaussian,
CompoundRay's shader, InvertPy's 7 rays, a uniform cone) against the exact responses
(:mod:`eyeviz.core.responses_caps`) over a population of lit balls
(:mod:`eyeviz.reports.renderers_measure`): each one's bias, its RMS error against rays
per facet, and the rays it needs for 1 % error (issue 34.4; docs/renderers.md).

Writes ``renderers.md``, ``renderers.csv`` (one row per sampler), ``curves.csv`` (the
RMS error at each N) and the figure ``renderers.png`` (also ``.svg`` and ``.pdf``) into
DIR (atomically, through ``eyeviz report``).
"""

from __future__ import annotations

import argparse
import csv
import io
import math
from pathlib import Path

from eyeviz.core.validation import check_int

HELP = "sampled against exact graded responses: renderers' bias and rays for 1 %% error"

#: Most balls in the population (--balls) and in the Monte-Carlo check (--mc-balls).
MAX_BALLS = 10**6
MAX_MC_BALLS = 10**5
MAX_MC_RAYS = 10**5


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("-o", "--output", required=True, type=Path, help="output directory")
    parser.add_argument(
        "--balls", type=int, default=4000, help="balls in the population (default 4000)"
    )
    parser.add_argument(
        "--acceptance",
        type=float,
        default=2.6,
        help="the facet's acceptance angle (FWHM), degrees (default 2.6)",
    )
    parser.add_argument(
        "--mc-balls",
        type=int,
        default=300,
        help="balls of the Monte-Carlo check with real rays (default 300)",
    )
    parser.add_argument(
        "--mc-rays", type=int, default=64, help="rays a facet in the Monte-Carlo check (default 64)"
    )
    parser.add_argument("--seed", type=int, default=0)


def _check(args: argparse.Namespace) -> None:
    check_int("--balls", args.balls, ge=1, le=MAX_BALLS)
    check_int("--mc-balls", args.mc_balls, ge=0, le=MAX_MC_BALLS)
    check_int("--mc-rays", args.mc_rays, ge=1, le=MAX_MC_RAYS)
    if not (math.isfinite(args.acceptance) and 0 < args.acceptance < 180):
        raise ValueError(f"--acceptance must be in (0, 180) degrees, got {args.acceptance}")


def _n(x: float) -> str:
    return "never (bias > 1 %)" if not math.isfinite(x) else f"{x:,.0f}"


def _markdown(rows, dr_deg: float, n_balls: int, example: dict[str, float]) -> str:
    from eyeviz.reports.renderers_measure import RAYS, TARGET

    out = io.StringIO()
    out.write("# Renderers: sampled against exact responses\n\n")
    out.write("![error against rays, a ball against offset, ray distributions](renderers.png)\n\n")
    out.write(
        "Also as vectors: [renderers.svg](renderers.svg), [renderers.pdf](renderers.pdf).\n\n"
    )
    out.write(
        f"A facet of acceptance angle {dr_deg:g} degrees (FWHM); {n_balls:,} balls it lights "
        "(angular radius 0.05 to 10 times the cone's half-angle, centres uniform over the "
        "solid angle where the ball meets the cone). The exact responses are the core's "
        "(gaussian on the sphere, flat). Bias: the sampler's limit (infinitely many rays) "
        "less the exact response. RMS error with N rays: sqrt(mean of bias^2 + q (1 - q) / N) "
        "over the balls, q the limit; the Monte-Carlo column draws the real rays.\n\n"
    )
    out.write(
        "| sampler | target | rays within FWHM/2 | bias: mean | RMS | max | "
        f"example: limit / exact | rays for {TARGET:.0%} (RMS) | every ball within {TARGET:.0%} | "
        "Monte-Carlo: rays, measured / predicted RMS |\n"
    )
    out.write("|---|---|---|---|---|---|---|---|---|---|\n")
    for r in rows:
        out.write(
            f"| {r.label} | {r.target} | {r.within_half_fwhm:.1%} | {r.bias_mean:+.4f} | "
            f"{r.bias_rms:.4f} | {r.bias_max:.4f} | {r.example:.3f} / {r.example_exact:.3f} | "
            f"{_n(r.rays_for_target)} | {_n(r.rays_for_target_worst)} | "
            f"{r.mc_rays or '-'}: {r.mc_rms:.4f} / {r.mc_predicted:.4f} |\n"
        )
    out.write(
        f"\nExample: a {example['beta_deg']:g}-degree ball {example['delta_deg']:g} degrees off "
        f"the axis of a {example['dr_deg']:g}-degree facet (issue 34).\n\n"
    )
    shown = [n for n in RAYS if n in (1, 4, 16, 64, 256, 1024, 4096, 16384, 65536)]
    out.write(
        "RMS error against rays per facet:\n\n| sampler | " + " | ".join(map(str, shown)) + " |\n"
    )
    out.write("|---|" + "---|" * len(shown) + "\n")
    for r in rows:
        cells = [f"{r.rms[n]:.4f}" if n in r.rms else "-" for n in shown]
        if len(r.rms) == 1:
            cells = [f"{next(iter(r.rms.values())):.4f} (7 rays)"] + [""] * (len(shown) - 1)
        out.write(f"| {r.label} | " + " | ".join(cells) + " |\n")
    return out.getvalue()


def _csv(rows) -> tuple[str, str]:
    from eyeviz.reports.renderers_measure import RAYS

    a, b = io.StringIO(), io.StringIO()
    w = csv.writer(a, lineterminator="\n")
    w.writerow(
        [
            "sampler",
            "target",
            "within_half_fwhm",
            "bias_mean",
            "bias_rms",
            "bias_max",
            "example_limit",
            "example_exact",
            "rays_for_1pct",
            "rays_for_1pct_every_ball",
            "mc_rays",
            "mc_rms",
            "mc_predicted_rms",
        ]
    )
    for r in rows:
        w.writerow(
            [
                r.key,
                r.target,
                f"{r.within_half_fwhm:.6f}",
                f"{r.bias_mean:.6g}",
                f"{r.bias_rms:.6g}",
                f"{r.bias_max:.6g}",
                f"{r.example:.6f}",
                f"{r.example_exact:.6f}",
                r.rays_for_target,
                r.rays_for_target_worst,
                r.mc_rays,
                f"{r.mc_rms:.6g}",
                f"{r.mc_predicted:.6g}",
            ]
        )
    w2 = csv.writer(b, lineterminator="\n")
    w2.writerow(["sampler", "rays", "rms_error"])
    for r in rows:
        for n in RAYS:
            if n in r.rms:
                w2.writerow([r.key, n, f"{r.rms[n]:.6g}"])
        if 7 in r.rms and 7 not in RAYS:
            w2.writerow([r.key, 7, f"{r.rms[7]:.6g}"])
    return a.getvalue(), b.getvalue()


def measure(args: argparse.Namespace):
    """(rows, offset curves, radial CDFs, example) for the report's arguments."""
    from eyeviz.reports import renderers_measure as M

    dr = math.radians(args.acceptance)
    pop = M.population(args.balls, dr, args.seed)
    rows = []
    for i, key in enumerate(M.TARGETS):
        row = M.measure_row(key, pop)
        if args.mc_balls:
            M.monte_carlo(row, pop, args.mc_balls, args.mc_rays, args.seed + 1 + i)
        rows.append(row)
    ex = M.EXAMPLE
    curves = M.offset_curves(math.radians(ex["dr_deg"]), math.radians(ex["beta_deg"]))
    example = dict(ex)
    cr = next(r for r in rows if r.key == "compoundray")
    example["exact"], example["compoundray"] = cr.example_exact, cr.example
    return rows, curves, M.radial_cdf(dr), example


def run(args: argparse.Namespace) -> int:
    from eyeviz.reports.common import write_atomic
    from eyeviz.reports.renderers_plot import plot

    _check(args)
    rows, curves, cdf, example = measure(args)
    out: Path = args.output
    out.mkdir(parents=True, exist_ok=True)
    plot(rows, curves, cdf, math.radians(args.acceptance), example, out / "renderers.png")
    write_atomic(out / "renderers.md", _markdown(rows, args.acceptance, args.balls, example))
    table, curve_table = _csv(rows)
    write_atomic(out / "renderers.csv", table)
    write_atomic(out / "curves.csv", curve_table)
    for r in rows:
        print(
            f"{r.label:28s} bias RMS {r.bias_rms:.4f}, within FWHM/2 {r.within_half_fwhm:.1%}, "
            f"rays for 1 %: {_n(r.rays_for_target)}"
        )
    print(f"wrote {out / 'renderers.md'}")
    return 0
