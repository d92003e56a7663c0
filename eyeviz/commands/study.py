"""``eyeviz study -o STUDY.csv``: the eye-design study (issue 11) on Dask.

With ``--nside LIST`` the 3D design study of the spherical eyes instead (issue 23;
:mod:`eyeviz.study.point`): the same resumable runner, a table of its own. With
``--eye NAME`` the study over a shipped measured pair reshaped, fewer facets
(``--facets``) or a wider head (``--widen``) (:mod:`eyeviz.study.point_measured`).

For every design (h, l, m) of the grid with l < h, the information limit's DD and AD
error (MAPE, Eq. 34; R^2, Eq. 35) overall and per distance bin, one row per design and
bin in a CSV table appended as points finish; re-running skips finished points. dask is
imported only when the study runs (:mod:`eyeviz.study.runner`), not by ``--help``.
"""

from __future__ import annotations

import argparse
import sys

NAME = "study"
HELP = (
    "the eye-design study: the information limit's distance and azimuth error over a "
    "grid of (h, l, m), or with --nside the 3D study of the spherical eyes, on Dask (local "
    "processes or an existing cluster); resumable"
)
#: What the command writes, checked before any work (eyeviz.files.outputs).
OUTPUTS = {"output": "file"}


def _csv(values) -> str:
    return ",".join(f"{v:g}" for v in values)


# long: one argparse option after another: the command's interface, no logic
def add_arguments(parser: argparse.ArgumentParser) -> None:
    from eyeviz.core.domain import DEFAULTS
    from eyeviz.study.grid import DEFAULT_H, DEFAULT_L, DEFAULT_M

    parser.add_argument(
        "-o",
        "--output",
        metavar="STUDY.csv",
        required=True,
        help="study table (CSV); an existing one of this version is resumed",
    )
    parser.add_argument(
        "--h",
        default=_csv(DEFAULT_H),
        metavar="LIST",
        help=f"eye positions h (eyes 2h apart; Table 3); default {_csv(DEFAULT_H)}",
    )
    parser.add_argument(
        "--l",
        default=_csv(DEFAULT_L),
        metavar="LIST",
        help=f"eye radii l (designs need l < h); default {_csv(DEFAULT_L)}",
    )
    parser.add_argument(
        "--m",
        default=None,
        metavar="LIST",
        help=f"ommatidia m per eye (even, >= 4); default {_csv(DEFAULT_M)}",
    )
    parser.add_argument(
        "--nside",
        default=None,
        metavar="LIST",
        help="the 3D study instead: HEALPix nside of the spherical eyes (even, >= 2; "
        "docs/spherical.md), e.g. 16,32,64; a table of its own",
    )
    parser.add_argument(
        "--eye",
        default=None,
        metavar="NAME",
        help="the study over a measured pair instead: a shipped eye (e.g. AM_60185-real.eye) "
        "with fewer facets (--facets) or a wider head (--widen); a table of its own",
    )
    parser.add_argument(
        "--facets",
        default=None,
        metavar="LIST",
        help="with --eye: fractions of each eye's facets kept (in (0, 1]); default 1,0.5,0.25",
    )
    parser.add_argument(
        "--widen",
        default=None,
        metavar="LIST",
        help="with --eye: baseline factors (the eyes moved apart); default 1,2",
    )
    parser.add_argument(
        "--el-max",
        default=None,
        metavar="RAD",
        help="3D only: elevation band |el| <= this (radians); default pi/6",
    )
    parser.add_argument(
        "--estimator",
        default=None,
        metavar="NAME",
        help="3D only: the estimator of the spherical eyes measured (the registry's; "
        "limit3d is the accuracy limit); default analytic3d",
    )
    parser.add_argument(
        "--n",
        default=None,
        metavar="N",
        help="test elements per design point; default 100000 (3D: 20000)",
    )
    parser.add_argument(
        "--prior",
        default="single",
        choices=("single", "multi"),
        help="Algorithm 1 prior of the test sets; default single",
    )
    parser.add_argument(
        "--seed",
        default=None,
        metavar="S",
        help="random seed; default: a resumed table's, else drawn afresh (and printed)",
    )
    parser.add_argument(
        "--r-min",
        default=None,
        metavar="R",
        help=f"nearest object distance; default {DEFAULTS['r_min']:g} (--eye: the pair's)",
    )
    parser.add_argument(
        "--r-max",
        default=None,
        metavar="R",
        help=f"farthest object distance; default {DEFAULTS['r_max']:g} (--eye: the pair's)",
    )
    parser.add_argument(
        "--g-max",
        default=None,
        metavar="G",
        help=f"largest object size; default {DEFAULTS['g_max']:g} (--eye: the pair's)",
    )
    parser.add_argument(
        "--workers",
        default=None,
        metavar="N",
        help="local worker processes; default one per usable CPU (affinity, cgroup quota)",
    )
    parser.add_argument(
        "--scheduler",
        default=None,
        metavar="ADDR",
        help="address of an existing Dask scheduler (tcp://HOST:8786) instead of local processes",
    )
    parser.add_argument("--no-progress", action="store_true", help="no progress bar")


def _int(name: str, text) -> int:
    from eyeviz import EyevizError

    try:
        return int(str(text).strip())
    except ValueError:
        raise EyevizError(f"{name} must be an integer, got {text!r}") from None


def _float(name: str, text) -> float:
    from eyeviz.core.validation import check_real

    return check_real(name, text)


def _seed(args: argparse.Namespace) -> int:
    """``--seed`` as given; else the seed of the table being resumed (every row of a table
    carries its point's seed, the key a resume matches); else a fresh one, printed (issue
    25: a default of 0 gave every study the same test sets)."""
    from eyeviz import EyevizError

    if args.seed is not None:
        return _int("seed", args.seed)
    if args.eye is not None:
        from eyeviz.study.point_measured import StudyTableMeasured

        keys, at = StudyTableMeasured.open(args.output).keys, -2  # (..., n, seed, estimator)
    elif args.nside is not None:
        from eyeviz.study.table import StudyTable3D

        keys, at = StudyTable3D.open(args.output).keys, -2  # (..., n, seed, estimator)
    else:
        from eyeviz.study.kinds import open_table

        keys, at = open_table(args.output, []).keys, -1  # (..., n, seed); not a 3D table
    seeds = sorted({int(k[at]) for k in keys})
    if len(seeds) > 1:
        raise EyevizError(
            f"{args.output}: rows of seeds {', '.join(map(str, seeds[:5]))}: give --seed"
        )
    if seeds:
        print(f"study: seed {seeds[0]} (the table's; resuming)", flush=True)
        return seeds[0]
    from eyeviz.commands._seeds import fresh_seed

    seed = fresh_seed()
    print(f"study: seed {seed} (drawn afresh; --seed {seed} repeats this study)", flush=True)
    return seed


def _measured_points(args: argparse.Namespace, given: dict, seed: int) -> list:
    """``--eye``: the measured study's points (eyeviz.study.point_measured)."""
    from eyeviz import EyevizError
    from eyeviz.study.point_measured import measured_grid

    if args.nside is not None or args.m is not None:
        raise EyevizError("--eye is the measured study; --m and --nside are the model eyes'")
    common = {k: None if v is None else _float(k, v) for k, v in given.items()}
    if args.el_max is not None:
        common["el_max"] = _float("el_max", args.el_max)
    return measured_grid(
        args.eye,
        "1,0.5,0.25" if args.facets is None else args.facets,
        "1,2" if args.widen is None else args.widen,
        **common,
        prior=args.prior,
        n=_int("n", args.n if args.n is not None else 300),
        seed=seed,
        estimator=args.estimator or "analytic3d",
    )


# long: the command's one sequence (options checked, grid built, the study run, the table
# written), each step with its own one-line error
def run(args: argparse.Namespace) -> int:
    import logging

    from eyeviz import EyevizError
    from eyeviz.core.domain import DEFAULTS
    from eyeviz.study import design_grid, run_study
    from eyeviz.study.grid import DEFAULT_M
    from eyeviz.study.kinds import open_table

    given = {k: getattr(args, k) for k in ("r_min", "r_max", "g_max")}
    ranges = {k: _float(k, DEFAULTS[k] if v is None else v) for k, v in given.items()}
    r_min, r_max, g_max = ranges["r_min"], ranges["r_max"], ranges["g_max"]
    if args.eye is None and (args.facets is not None or args.widen is not None):
        raise EyevizError("--facets and --widen reshape a measured pair: they need --eye")
    seed = _seed(args)
    points: list = []
    if args.eye is not None:
        points = _measured_points(args, given, seed)
    elif args.nside is not None:
        from eyeviz.core.domain import DEFAULT_EL_MAX
        from eyeviz.study.grid import DEFAULT_N3D, design_grid3d
        from eyeviz.study.point import DEFAULT_ESTIMATOR

        if args.m is not None:
            raise EyevizError("--m is the planar study's, --nside the 3D study's: give one")
        points = design_grid3d(
            args.h,
            args.l,
            args.nside,
            r_min=r_min,
            r_max=r_max,
            g_max=g_max,
            el_max=DEFAULT_EL_MAX if args.el_max is None else _float("el_max", args.el_max),
            prior=args.prior,
            n=_int("n", args.n if args.n is not None else DEFAULT_N3D),
            seed=seed,
            estimator=args.estimator or DEFAULT_ESTIMATOR,
        )
    else:
        if args.el_max is not None or args.estimator is not None:
            raise EyevizError("--el-max and --estimator belong to the 3D study (--nside)")
        points = design_grid(
            args.h,
            args.l,
            args.m if args.m is not None else _csv(DEFAULT_M),
            r_min=r_min,
            r_max=r_max,
            g_max=g_max,
            prior=args.prior,
            n=_int("n", args.n if args.n is not None else 100_000),
            seed=seed,
        )
    workers = None if args.workers is None else _int("workers", args.workers)
    if workers is not None and args.scheduler is None:
        from eyeviz.study.cpus import workers_warning

        advice = workers_warning(workers)
        if advice:
            print(f"eyeviz: warning: {advice}", file=sys.stderr)
    logging.getLogger("distributed").setLevel(logging.ERROR)  # a killed worker: no log spam
    try:
        summary = run_study(
            args.output,
            points,
            workers=workers,
            scheduler=args.scheduler,
            progress=not args.no_progress,
        )
    except KeyboardInterrupt as exc:
        kept = "the finished points"
        try:
            kept = f"{len(open_table(args.output, points).keys)} finished point(s)"
        except Exception:  # noqa: BLE001 - the message only
            pass
        name = getattr(exc, "signame", "SIGINT")
        what = "interrupted" if name == "SIGINT" else f"terminated by {name}"
        print(
            f"eyeviz: {what}; {kept} kept in {args.output} (run the same command to resume)",
            file=sys.stderr,
        )
        return int(getattr(exc, "exit_code", 130))
    print(summary)
    return 0
