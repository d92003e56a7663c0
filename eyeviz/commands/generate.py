"""``eyeviz generate``: write a training data set of Algorithm 1 (CSV or NPZ).

Planar eyes (default, ``--h --l --m``), HEALPix eyes (``--nside``) or a measured pair
(``--eye FILE [--units mm]``): the last two write the sparse data set
(:mod:`eyeviz.dataset.sparse3d`); a measured pair is embedded in it, and its ranges
default to the animal's scale (:func:`eyeviz.core.domain.measured_ranges`). The options
make the domain; the rows are written by the data set format of its kind
(:func:`eyeviz.dataset.kinds.write`)."""

from __future__ import annotations

import argparse
import os
import sys
import time
import warnings

NAME = "generate"
HELP = "generate a training data set with the paper's Algorithm 1 (CSV or NPZ)"
#: What the command writes, checked before any work (eyeviz.files.outputs).
OUTPUTS = {"output": "file"}
_PROGRESS_MIN = 200_000  # elements; below this a run takes well under a second


# long: one argparse option after another: the command's interface, no logic
def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "-n", type=int, required=True, metavar="N", help="number of elements (rows)"
    )
    parser.add_argument(
        "-o",
        "--output",
        required=True,
        metavar="OUT",
        help="output file: .csv (the paper's format) or .npz (bit-packed)",
    )
    parser.add_argument(
        "--mode",
        choices=("single", "multi"),
        default="single",
        help="single pass (Algorithm 1 as written) or multi-pass: segments "
        "of r with counts proportional to r, uniform over the BFV "
        "(default: single)",
    )
    parser.add_argument(
        "--seed",
        type=int,
        default=None,
        help="random seed, >= 0 (default: a fresh one, printed and kept in an NPZ's "
        "metadata; never a seed the shipped models were fitted on)",
    )
    from eyeviz.core.domain import DEFAULTS

    for flag, typ, what, table in (
        ("h", float, "origin to eye centre distance", 3),
        ("l", float, "eye radius", 3),
        ("m", int, "ommatidia per eye, even", 3),
        ("r_min", _length, "minimum distance of a feature centre", 4),
        ("r_max", _length, "maximum distance of a feature centre", 4),
        ("g_max", _length, "maximum feature radius", 4),
    ):
        parser.add_argument(
            f"--{flag.replace('_', '-')}",
            type=typ,
            default=None,  # filled by _fill_defaults: --eye has ranges of its own
            help=f"{what} (default: {DEFAULTS[flag]:g}, Table {table}"
            + (
                "; with --eye: at the animal's scale, in mm, or in baselines b (the "
                "distance between the eyes' lens centroids) as e.g. 12b)"
                if table == 4
                else ")"
            ),
        )
    parser.add_argument(
        "--nside",
        type=int,
        default=None,
        metavar="N",
        help="spherical (3D) eyes with HEALPix facets: nside, even (12 nside^2 facets per "
        "eye; 180 matches m = 720); writes the sparse 3D data set (.npz only)",
    )
    parser.add_argument(
        "--eye",
        default=None,
        metavar="FILE",
        help="a measured eye pair (.eye): balls in its binocular field, the pair embedded "
        "in the sparse data set (.npz only)",
    )
    parser.add_argument(
        "--units",
        choices=("mm", "m", "um"),
        default="mm",
        help="with --eye: the eye file's length unit (default mm, as .eye files)",
    )
    parser.add_argument(
        "--el-max",
        type=float,
        default=None,
        help="with --nside: largest |elevation| of a feature centre, in radians, in "
        "(0, pi/2) (default: pi/6); with --eye: in (0, pi/2] (default pi/2)",
    )
    parser.add_argument(
        "--segments",
        type=int,
        default=None,
        help="multi mode: number of r segments (default: segments of length 5, as the paper)",
    )
    parser.add_argument(
        "--field",
        choices=("wedge", "both-eyes"),
        default=None,
        help="with --nside: the binocular field a ball lies in: 'wedge' (default; the "
        "paper's wedge rotated about the baseline, outside both tangent cones) or "
        "'both-eyes' (in front, touching neither eye, >= 2 facets lit in each); with "
        "--eye the field is always 'both-eyes'",
    )
    parser.add_argument(
        "--unique-bitmaps",
        action="store_true",
        help="keep one element per distinct (Omega_A, Omega_B) pair, as the "
        "authors' published data set",
    )
    parser.add_argument(
        "--responses",
        choices=("flat", "gaussian", "cell"),
        default=None,
        help="store each lit facet's graded response beside the lit sets; with --eye "
        "flat (the covered share of the acceptance cone) or gaussian (FWHM = the acceptance "
        "angle), with --nside cell (the covered share of the HEALPix cell; docs/responses.md)",
    )
    parser.add_argument("--quiet", action="store_true", help="no progress bar")


def _length(text: str):
    """A range's value: a number (float), or with a unit (``30mm``, ``12b``) a
    :class:`eyeviz.core.animal_scale.Length`, which only ``--eye`` takes."""
    try:
        return float(text)
    except ValueError:
        from eyeviz.core.animal_scale import parse_length

        try:
            return parse_length(text, "the value")
        except ValueError as exc:  # argparse turns this into a one-line usage error
            raise argparse.ArgumentTypeError(str(exc)) from None


def _seed(args: argparse.Namespace) -> bool:
    """Set ``args.seed`` to a fresh seed when none was given; whether it was drawn."""
    if args.seed is not None:
        return False
    from eyeviz.commands._seeds import fresh_seed

    args.seed = fresh_seed()
    return True


def _say_seed(args: argparse.Namespace, drawn: bool, domain: dict, kind: str = "planar") -> None:
    """The drawn seed on stdout, even with --quiet (a CSV has nowhere to keep it); on
    stderr a warning when the given seed draws a set a shipped model was fitted on."""
    if drawn:
        print(
            f"generate: seed {args.seed} (drawn afresh; --seed {args.seed} repeats this run)",
            flush=True,
        )
        return
    from eyeviz.commands._seeds import same_sets

    for what in same_sets(args.seed, domain, args.mode, kind):
        print(
            f"generate: warning: seed {args.seed} with these parameters draws {what}; "
            "it is not a held-out test set for that model",
            file=sys.stderr,
        )


def _fill_defaults(args: argparse.Namespace) -> None:
    """The planar and HEALPix runs' defaults (Tables 3-4) for the options not given."""
    from eyeviz.core.domain import DEFAULTS

    for k in ("h", "l", "m", "r_min", "r_max", "g_max"):
        if getattr(args, k) is None:
            setattr(args, k, DEFAULTS[k])


def _refuse_ignored(args: argparse.Namespace) -> None:
    """An option the run would ignore is refused (issue 36): ``--segments`` cuts r only
    in multi mode; ``--m`` (even the default 720) is not the HEALPix eyes'."""
    from eyeviz import EyevizError
    from eyeviz.core.animal_scale import Length

    if args.eye is None:
        for k in ("r_min", "r_max", "g_max"):
            if isinstance(getattr(args, k), Length):
                flag = "--" + k.replace("_", "-")
                raise EyevizError(
                    f"{flag} {getattr(args, k)}: lengths in baselines or with a unit are "
                    "for --eye (measured eyes); model eyes take plain numbers"
                )
    if args.segments is not None and args.mode != "multi":
        raise EyevizError(
            f"--segments {args.segments} is for --mode multi; a single pass has no segments"
        )
    if args.m is not None and args.nside is not None:
        raise EyevizError("--m is the planar eye's; with --nside the equator has 4*nside facets")
    if args.field is not None and args.nside is None and args.eye is None:
        raise EyevizError(
            f"--field {args.field} needs --nside or --eye (the planar field is the paper's wedge)"
        )
    if args.responses in ("flat", "gaussian") and args.eye is None:
        raise EyevizError(
            f"--responses {args.responses} needs --eye (flat and gaussian responses are the "
            "measured eyes' acceptance cones)"
        )
    if args.responses == "cell" and args.nside is None:
        raise EyevizError(
            "--responses cell needs --nside (the share of each HEALPix cell; measured eyes "
            "answer flat or gaussian)"
        )


def run(args: argparse.Namespace) -> int:
    _refuse_ignored(args)
    drawn = _seed(args)
    if args.eye is not None:
        return _run_eye(args, drawn)
    _fill_defaults(args)
    if args.nside is not None or args.el_max is not None:
        return _run3d(args, drawn)
    from eyeviz import EyevizError, dataset
    from eyeviz.core.domain import Domain
    from eyeviz.core.geometry import EyePair
    from eyeviz.dataset import io as dataset_io

    try:
        eyes = EyePair(args.h, args.l, args.m)
    except ValueError as exc:
        raise EyevizError(str(exc)) from None
    dataset_io.format_of(args.output)
    kw = dict(
        eyes=eyes,
        r_min=args.r_min,
        r_max=args.r_max,
        g_max=args.g_max,
        mode=args.mode,
        seed=args.seed,
        unique_bitmaps=args.unique_bitmaps,
        segments=args.segments,
    )
    dataset.check_n(args.n)
    dataset.make_params(**kw)
    from eyeviz.files import limits

    fmt = dataset_io.format_of(args.output)
    limits.check_free_space(args.output, limits.estimated_output_bytes(args.n, args.m, fmt))
    domain = {"h": eyes.h, "l": eyes.l, "m": eyes.m}
    domain.update(r_min=args.r_min, r_max=args.r_max, g_max=args.g_max)
    _say_seed(args, drawn, domain)
    t0 = time.perf_counter()
    dom = Domain(eyes.h, eyes.l, eyes.m, args.r_min, args.r_max, args.g_max)
    _write(args, args.n, dom, _PROGRESS_MIN, unique_bitmaps=args.unique_bitmaps)
    if not args.quiet:
        size = os.path.getsize(args.output) / 1e6
        print(
            f"wrote {args.n:,} elements ({args.mode} pass, seed {args.seed}) to "
            f"{args.output} ({size:.1f} MB) in {time.perf_counter() - t0:.2f} s"
        )
    return 0


_PROGRESS_MIN_3D = 2_000  # rows; a 3D row (thousands of lit facets) costs far more


def _progress(args: argparse.Namespace, n: int, least: int):
    """A tqdm bar on stderr for ``n`` rows, or None when quiet or under ``least`` rows."""
    if args.quiet or n < least:
        return None
    from tqdm import tqdm

    return tqdm(
        total=n,
        unit="rows",
        unit_scale=True,
        file=sys.stderr,
        desc=f"generate {args.output}",
        leave=False,
        mininterval=0.5,
    )


def _run3d(args: argparse.Namespace, drawn: bool = False) -> int:
    """``--nside``: Algorithm 1 in 3D, written as the sparse 3D data set."""
    from eyeviz import EyevizError
    from eyeviz.core.domain import DEFAULTS, DEFAULTS3D, Domain3D
    from eyeviz.dataset import algorithm1_3d, sparse3d
    from eyeviz.files import limits

    if args.nside is None:
        raise EyevizError("--el-max needs --nside (the planar model has no elevation)")
    if args.m != DEFAULTS["m"]:
        raise EyevizError("--m is the planar eye's; with --nside the equator has 4*nside facets")
    if args.unique_bitmaps:
        raise EyevizError("--unique-bitmaps is for the planar data set only, not with --nside")
    sparse3d.check_output_path(args.output)
    el_max = DEFAULTS3D["el_max"] if args.el_max is None else args.el_max
    domain = Domain3D(args.h, args.l, args.nside, args.r_min, args.r_max, args.g_max, el_max)
    n = algorithm1_3d.check_n(args.n)
    algorithm1_3d.make_params3d(domain, args.mode, args.seed, args.segments, args.field)
    limits.check_free_space(args.output, sparse3d.estimated_bytes3d(n, domain))
    d3 = {"h": domain.h, "l": domain.l, "nside": domain.nside, "el_max": domain.el_max}
    d3.update(r_min=domain.r_min, r_max=domain.r_max, g_max=domain.g_max)
    _say_seed(args, drawn, d3, "spherical")
    t0 = time.perf_counter()
    _write_sparse(args, n, domain)
    if not args.quiet:
        size = os.path.getsize(args.output) / 1e6
        field = "" if args.field in (None, "wedge") else f", field {args.field}"
        print(
            f"wrote {n:,} 3D elements (nside {domain.nside}{field}, {args.mode} pass, seed "
            f"{args.seed}) to {args.output} ({size:.1f} MB) in {time.perf_counter() - t0:.2f} s"
        )
    return 0


def _write(args: argparse.Namespace, n: int, domain, least: int, **own) -> None:
    """Algorithm 1's ``n`` rows of ``domain`` to ``args.output`` through the data set
    format of the domain's kind (:func:`eyeviz.dataset.kinds.write`; ``own``: that
    format's own options), with a progress bar past ``least`` rows."""
    from eyeviz.dataset import kinds

    bar = _progress(args, n, least)
    try:
        kinds.write(
            args.output,
            n,
            domain,
            mode=args.mode,
            seed=args.seed,
            segments=args.segments,
            progress=bar.update if bar else None,
            **own,
        )
    finally:
        if bar is not None:
            bar.close()


def _write_sparse(args: argparse.Namespace, n: int, domain) -> None:
    """The sparse 3D data set of ``domain`` (HEALPix or measured eyes) to ``args.output``,
    with a progress bar past _PROGRESS_MIN_3D rows."""
    _write(args, n, domain, _PROGRESS_MIN_3D, field=args.field, responses=args.responses)


def _run_eye(args: argparse.Namespace, drawn: bool) -> int:
    """``--eye FILE``: Algorithm 1 on a measured pair, written as the sparse data set with
    the pair embedded."""
    from eyeviz import EyevizError
    from eyeviz.core.domain import Domain3D
    from eyeviz.dataset import algorithm1_3d, sparse3d
    from eyeviz.files import limits
    from eyeviz.files.eye_io import eye_path, load_eyes

    for flag in ("nside", "h", "l", "m"):
        if getattr(args, flag) is not None:
            raise EyevizError(f"--{flag} describes model eyes; with --eye the file gives the eyes")
    if args.unique_bitmaps:
        raise EyevizError("--unique-bitmaps is for the planar data set only, not with --eye")
    sparse3d.check_output_path(args.output)
    n = algorithm1_3d.check_n(args.n)
    eye = eye_path(args.eye)  # a file, or a shipped eye's name
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        pair = load_eyes(eye, units=args.units)
    for w in caught:  # e.g. a size that looks like the wrong unit: one line, no source
        print(f"generate: warning: {w.message}", file=sys.stderr)
    from eyeviz.core.animal_scale import prior_ranges

    ranges = prior_ranges(
        pair, **{k: getattr(args, k) for k in ("r_min", "r_max", "g_max", "el_max")}
    )
    domain = Domain3D.for_eyes(pair, **ranges)
    algorithm1_3d.make_params3d(domain, args.mode, args.seed, args.segments, args.field)
    limits.check_free_space(args.output, sparse3d.estimated_bytes3d(n, domain))
    if drawn:
        _say_seed(args, drawn, {}, "measured")
    t0 = time.perf_counter()
    _write_sparse(args, n, domain)
    if not args.quiet:
        size = os.path.getsize(args.output) / 1e6
        na, nb = domain.facet_counts
        b = 2 * domain.h
        print(
            f"wrote {n:,} elements of measured eyes {pair.name} ({na} + {nb} facets; r in "
            f"[{domain.r_min:.4g}, {domain.r_max:.4g}] mm = [{domain.r_min / b:.3g}, "
            f"{domain.r_max / b:.3g}] b, g <= {domain.g_max:.4g} mm; {args.mode} "
            f"pass, seed {args.seed}) to {args.output} ({size:.1f} MB) in "
            f"{time.perf_counter() - t0:.2f} s"
        )
    return 0
