"""``eyeviz train NAME``: fit an estimator that learns (one sub-command per registry entry).

Every learning estimator has one shape, ``fit(data, out_dir, **options) -> path``
(:mod:`eyeviz.estimators.registry`); its options come from its registry entry. Without
``-o`` the output goes to the user models directory (``$EYEVIZ_HOME/models``, else
``~/.local/share/eyeviz/models``; printed); the shipped assets are written only with
``--into-assets``. Weights and metadata are staged in a temporary directory and moved in
as a whole at the end: Ctrl-C leaves the previous model intact.
Nothing heavy is imported until ``run``.
"""

from __future__ import annotations

import argparse
import shlex
import sys

NAME = "train"
HELP = "train an estimator that learns (compact networks, bayes table, the paper's networks)"
#: What the command writes, checked before any work (eyeviz.files.outputs).
OUTPUTS = {"out": "path"}
#: The training data an estimator of each kind (its registry entry's ``kind``) reads.
DATA = {
    "planar": ".csv or .npz from `eyeviz generate`",
    "spherical": "a sparse 3D .npz from `eyeviz generate --nside`",
}


def add_arguments(parser: argparse.ArgumentParser) -> None:
    from eyeviz.estimators import registry

    sub = parser.add_subparsers(dest="what", metavar="ESTIMATOR", required=True)
    for e in registry.entries(None):  # planar and spherical (learned3d)
        if not e.learns:
            continue
        p = sub.add_parser(e.name, help=e.help, description=e.help)
        if e.fit_takes_data:
            p.add_argument(
                "data",
                nargs="?",
                default=None,
                help=f"training data ({DATA[e.kind]}); default: generate",
            )
        out = p.add_mutually_exclusive_group()
        out.add_argument(
            "-o",
            "--out",
            default=None,
            help="output directory (default: the user models directory, printed)"
            + ("; a .npz file name is accepted" if e.name == "bayes" else ""),
        )
        out.add_argument(
            "--into-assets",
            action="store_true",
            help="write into the shipped assets (eyeviz/assets/models) instead",
        )
        registry.add_options(p, e.fit_options)
        g = p.add_argument_group("data parameters (defaults: Tables 3 and 4)")
        registry.add_options(g, registry.DOMAIN_OPTIONS)


def _command() -> str:
    return "eyeviz " + " ".join(shlex.quote(a) for a in sys.argv[1:])


def run(args: argparse.Namespace) -> int:
    from pathlib import Path

    from eyeviz import EyevizError
    from eyeviz.estimators import fit_checks, registry, store

    e = registry.get(args.what)
    options = registry.options_from_args(e.fit_options, args)
    options["domain"] = registry.domain_from_args(args)
    options["command"] = _command()
    if "seed" in {o.dest for o in e.fit_options} and options.get("seed") is None:
        from eyeviz.commands._seeds import fresh_seed

        # a fresh seed, not the one the shipped model was fitted on; kept in the model's
        # metadata and in its recorded command, so the run can be repeated
        options["seed"] = fresh_seed()
        options["command"] += f" --seed {options['seed']}"
        print(
            f"{e.name}: seed {options['seed']} (drawn afresh; --seed {options['seed']} "
            "repeats this run)",
            file=sys.stderr,
        )
    out_arg = args.out
    if e.name == "bayes" and out_arg is not None and out_arg.endswith(".npz"):
        options["filename"] = Path(out_arg).name
        out_arg = str(Path(out_arg).parent)
    out_dir = store.resolve_out_dir(out_arg, args.into_assets, e.weights_subdir)
    data = getattr(args, "data", None)
    if data is not None and not Path(data).is_file():
        raise EyevizError(f"data file {data} not found")
    # before the fit's import (torch, seconds): a bad number is refused at once
    fit_checks.check(e.name, options, data is not None)
    print(f"{e.name}: training into {out_dir}", file=sys.stderr)
    bar = _progress(e.name, options)
    try:
        path = e.fit_estimator(data, out_dir, **options)
    finally:
        if bar is not None:
            bar.close()
    flag = "" if args.into_assets else f" --weights {path}"
    print(f"{e.name}: wrote {path}; use it with `eyeviz predict -e {e.name}{flag} DATA -o OUT`")
    return 0


def _progress(name: str, options: dict):
    """A tqdm bar wired to the estimator's ``progress`` callback (paper draws its own)."""
    from tqdm import tqdm

    if name == "compact":
        epochs = options.get("epochs", 12)
        bar = tqdm(total=2 * epochs, desc="compact", unit="epoch", file=sys.stderr, delay=1.0)

        def progress(label, ep, total, val):
            bar.set_postfix_str(f"{label} epoch {ep} val rel. error {100 * val:.4g} %")
            bar.update(1)

        options["progress"] = progress
        return bar
    if name == "bayes":
        bar = tqdm(desc="bayes sample", unit="el", unit_scale=True, file=sys.stderr, delay=1.0)

        def progress_b(done, total):
            bar.total = total
            bar.update(done - bar.n)

        options["progress"] = progress_b
        return bar
    return None
