"""``eyeviz report atlas -o DIR [--eye FILE ...]``: what measured eyes can know about distance.

For each eye pair (by default the shipped honeybee AM_60185 and bumblebees BT_77967 and
BT_77973; ``--eye`` names others, files or shipped names), under the prior at the
animal's scale (:mod:`eyeviz.core.animal_scale`; ``--r-min``, ``--r-max``, ``--g-max`` in
mm or baselines, ``--el-max``, ``--mode``):

- the binocular field on a map: small balls (``--ball-deg``, 0.5 degrees) on a
  ``--field-step`` grid of directions at the prior's r_min and r_max; which directions
  both eyes see (>= 2 facets each, no lens in the ball: ``in_bfv``) and with how many
  facets (:mod:`eyeviz.reports.atlas_measure`);
- a test set of ``--rows`` balls drawn from the prior (seed ``--seed``) and the
  estimators of ``--estimators`` on it (the limit on at most ``--limit-rows`` evenly
  spaced rows): DD (mean |r^ - r| / r), azimuth and elevation errors, per distance bin in
  mm and in baselines b, each with its standard error;
- the rule of thumb dZ ~ Z^2 dphi / b (a relative error Z dphi / b, dphi the lit facets'
  mean interommatidial angle) beside the measured DD: their ratio per bin and the
  exponent of DD against Z (the rule says 1);
- the run time of every step.

Output (written into a staging folder, moved in whole): ``atlas.md``, ``atlas_summary.csv``,
``atlas_bins.csv``, ``atlas_field.csv``, ``atlas_times.csv`` and the figures
``atlas_field``, ``atlas_distance``, ``atlas_rule``, ``atlas_scaling``, ``atlas_angles``,
each as PNG and SVG. Defaults (300 rows, 40 limit rows, 1-degree grid) keep the whole
atlas of the three shipped pairs to a few minutes on one core.
"""

from __future__ import annotations

import argparse
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from eyeviz import EyevizError
from eyeviz.reports.common import add_formats_option, parse_formats

HELP = "the atlas of measured eyes: binocular field, distance limit, rule of thumb"
SHIPPED = ("AM_60185-real.eye", "BT_77967-real.eye", "BT_77973-real.eye")
#: The test seed (no shipped model was fitted on measured eyes; fixed so reruns agree).
SEED = 3303
MAX_ROWS = 100_000
MAX_EYES = 8
MIN_STEP, MAX_STEP = 0.25, 10.0
DEFAULT_ESTIMATORS = "analytic3d,limit3d"


@dataclass
class PairAtlas:
    """Everything the atlas measured on one pair."""

    label: str
    facets: tuple[int, int]
    prior: dict[str, float]
    grid_step: float
    ball_deg: float = 0.5
    fields: list[dict[str, Any]] = field(default_factory=list)  # per distance
    scores: list[Any] = field(default_factory=list)  # BallScores
    bins: dict[str, list[dict[str, float]]] = field(default_factory=dict)
    overall: dict[str, dict[str, float]] = field(default_factory=dict)
    times: dict[str, float] = field(default_factory=dict)
    rows: int = 0


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("-o", "--output", type=Path, required=True, metavar="DIR")
    parser.add_argument(
        "--eye",
        action="append",
        default=None,
        metavar="FILE",
        help="an eye pair file (.eye, .gltf, .glb) or a shipped eye's name; repeat for "
        f"more (at most {MAX_EYES}; default: the shipped {', '.join(SHIPPED)})",
    )
    parser.add_argument(
        "--units",
        choices=("mm", "m", "um"),
        default=None,
        help="the eye files' length unit (default: the format's)",
    )
    parser.add_argument("--rows", type=int, default=300, help="test balls per pair (default 300)")
    parser.add_argument(
        "--limit-rows", type=int, default=40, help="rows the limit is run on (default 40)"
    )
    parser.add_argument("--bins", type=int, default=5, help="distance bins (default 5)")
    parser.add_argument(
        "--seed", type=int, default=SEED, help=f"the test sets' seed (default {SEED})"
    )
    parser.add_argument(
        "--estimators",
        default=DEFAULT_ESTIMATORS,
        help=f"estimators of measured eyes (default {DEFAULT_ESTIMATORS})",
    )
    parser.add_argument(
        "--field-step",
        type=float,
        default=1.0,
        help="the field map's grid step, degrees (default 1)",
    )
    parser.add_argument(
        "--ball-deg",
        type=float,
        default=0.5,
        help="the field map's balls' angular radius, degrees (default 0.5)",
    )
    for flag in ("r-min", "r-max", "g-max"):
        parser.add_argument(
            f"--{flag}",
            default=None,
            help=f"the prior's {flag.replace('-', '_')}: mm, or baselines "
            "as 12b (default: the pair's, docs/atlas.md)",
        )
    parser.add_argument(
        "--el-max",
        type=float,
        default=None,
        help="the prior's elevation bound, radians (default pi/2)",
    )
    parser.add_argument(
        "--mode",
        choices=("single", "multi"),
        default="single",
        help="the prior's pass (default single)",
    )
    add_formats_option(parser, ("png", "svg"))


def _check(args: argparse.Namespace) -> list[str]:
    """The estimator names, after refusing bad options in one line (and the options
    parsed in place: the formats, the prior's lengths)."""
    from eyeviz.core.animal_scale import parse_length
    from eyeviz.core.validation import check_int

    for flag, hi in (("rows", MAX_ROWS), ("limit_rows", MAX_ROWS), ("bins", 20), ("seed", 2**31)):
        lo = 0 if flag == "seed" else 1
        check_int("--" + flag.replace("_", "-"), getattr(args, flag), ge=lo, le=hi)
    if not MIN_STEP <= args.field_step <= MAX_STEP:
        raise EyevizError(
            f"--field-step must be in [{MIN_STEP:g}, {MAX_STEP:g}] degrees, got {args.field_step!r}"
        )
    args.formats = parse_formats(args.formats)
    for k in ("r_min", "r_max", "g_max"):
        if getattr(args, k) is not None:
            setattr(args, k, parse_length(getattr(args, k), "--" + k.replace("_", "-")))
    if not (0.01 <= args.ball_deg <= 10):
        raise EyevizError(f"--ball-deg must be in [0.01, 10] degrees, got {args.ball_deg!r}")
    eyes = args.eye or list(SHIPPED)
    if len(eyes) > MAX_EYES:
        raise EyevizError(f"at most {MAX_EYES} --eye files, got {len(eyes)}")
    names = [s for s in str(args.estimators).replace(",", " ").split() if s]
    from eyeviz.estimators import registry

    have = registry.available("spherical")
    bad = [s for s in names if s not in have]
    if bad or not names:
        raise EyevizError(
            f"unknown estimator(s) {', '.join(bad) or '(none given)'}; estimators of measured "
            f"eyes are among: {', '.join(have)}"
        )
    return list(dict.fromkeys(names))


def _load(spec: str, units: str | None):
    from eyeviz.files.eye_io import eye_path, load_eyes

    path = eye_path(spec)  # a file, or a shipped name (an error lists them)
    return load_eyes(path, units=units) if units else load_eyes(path)


def measure_pair(pair, args: argparse.Namespace, names: list[str]) -> PairAtlas:
    """The atlas of one pair (see the module docstring)."""
    from eyeviz.core.animal_scale import describe_prior, prior_ranges
    from eyeviz.core.domain import domain_for
    from eyeviz.dataset import kinds
    from eyeviz.reports import atlas_measure as am

    t0 = time.perf_counter()
    ranges = prior_ranges(
        pair, **{k: getattr(args, k) for k in ("r_min", "r_max", "g_max", "el_max")}
    )
    domain = domain_for(pair, **ranges)
    prior = describe_prior(domain)
    out = PairAtlas(str(pair.name), domain.facet_counts, prior, args.field_step, args.ball_deg)
    lon, lat = am.grid(args.field_step)
    for r in (domain.r_min, domain.r_max):
        na, nb, both = am.field_counts(pair, domain.origin, r, lon, lat, args.ball_deg)
        ext = am.field_extent(both, na, nb, lon, lat, args.field_step)
        out.fields.append(
            {
                "r_mm": r,
                "r_b": r / prior["b_mm"],
                "na": na,
                "nb": nb,
                "both": both,
                "lon": lon,
                "lat": lat,
                **ext,
            }
        )
    out.times["field map"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    ds = kinds.sample(args.rows, domain, mode=args.mode, seed=args.seed)
    out.rows = len(ds)
    out.times["test set"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    lit_a, lit_b = (ds.indptr_a, ds.indices_a), (ds.indptr_b, ds.indices_b)
    rule = ds.r * am.local_spacing(pair, lit_a, lit_b) / prior["b_mm"]
    out.times["rule of thumb"] = time.perf_counter() - t0
    out.scores = am.score(ds, names, args.limit_rows)
    edges = np.linspace(domain.r_min, domain.r_max, args.bins + 1)
    for s in out.scores:
        out.times[s.name] = s.seconds
        if not s.ok:
            continue
        out.bins[s.name] = am.binned(s, ds.r, rule, edges, prior["b_mm"])
        ov: dict[str, float] = {"rows": float(s.rows.size), "flagged": float(s.flagged)}
        for key, v in (
            ("dd", 100 * s.ape),
            ("az", s.az_deg),
            ("el", s.el_deg),
            ("rule", 100 * rule[s.rows]),
        ):
            ov[key], ov[key + "_se"] = am.mean_se(v)
        mids = [b["r_mid_mm"] for b in out.bins[s.name]]
        ov["exponent"] = am.slope(np.array(mids), np.array([b["dd"] for b in out.bins[s.name]]))
        ov["us_per_row"] = s.seconds / max(1, s.rows.size) * 1e6
        out.overall[s.name] = ov
    return out


def run(args: argparse.Namespace) -> int:
    from eyeviz.reports import atlas_figures, atlas_tables

    t_all = time.perf_counter()
    names = _check(args)
    pairs = [_load(spec, args.units) for spec in (args.eye or SHIPPED)]
    atlases = []
    for pair in pairs:
        a = measure_pair(pair, args, names)
        atlases.append(a)
        print(f"atlas: {a.label}: {np.nansum(list(a.times.values())):.1f} s", flush=True)
    t0 = time.perf_counter()
    figs = atlas_figures.write_all(atlases, args.output, args.formats)
    fig_s = time.perf_counter() - t0
    total = time.perf_counter() - t_all
    written = atlas_tables.write_all(atlases, args, args.output, figs, fig_s, total)
    print(
        f"atlas: wrote {len(written) + len(args.formats) * len(figs)} files to {args.output} "
        f"in {total:.1f} s"
    )
    return 0


__all__ = ["HELP", "PairAtlas", "add_arguments", "measure_pair", "run"]
