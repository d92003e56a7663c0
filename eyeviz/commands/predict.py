"""``eyeviz predict --estimator NAME DATA.csv -o PRED.csv``: r_hat, phi_hat per row.

Reads a data set of DESIGN.md §3 (.csv or .npz), writes a CSV with a header line
``r_hat,phi_hat`` and one row per input row (``nan`` where a row is not a single
feature), atomically. Prints the metrics against the data's own r and phi.

The data set's eye design (h, l, m) must be the estimator's: an NPZ carries it, a CSV is
described by ``--h --l --m`` (default Tables 3-4). An estimator for any design (analytic,
limit) gets its domain from those flags (and ``--r-min --r-max --g-max``); the other
options come from the estimator's registry entry. ``-o`` may not be the input file
(compared by device and inode, so links count).
"""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

NAME = "predict"
HELP = "predict distance and azimuth for every row of a data set"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    from eyeviz.estimators import registry

    names = registry.available()
    parser.add_argument("data", help="data set (.csv or .npz, as `eyeviz generate` writes)")
    parser.add_argument(
        "-e",
        "--estimator",
        default="compact",
        help="; ".join(f"{e.name}: {e.help}" for e in registry.entries())
        + f" (one of {', '.join(names)}; default compact)",
    )
    parser.add_argument("-o", "--out", required=True, help="output CSV (r_hat,phi_hat)")
    parser.add_argument(
        "--weights", default=None, help="weights directory/file instead of the shipped ones"
    )
    g = parser.add_argument_group(
        "design (a CSV's eyes; the domain of an estimator for any design; default Tables 3-4)"
    )
    registry.add_options(g, registry.DOMAIN_OPTIONS)
    o = parser.add_argument_group("estimator options")
    for e in registry.entries():
        registry.add_options(o, e.load_options)


def same_file(a, b) -> bool:
    """Whether paths ``a`` and ``b`` are the same file (device and inode: links count)."""
    try:
        sa, sb = os.stat(a), os.stat(b)
    except OSError:
        return False
    return (sa.st_dev, sa.st_ino) == (sb.st_dev, sb.st_ino)


def _design_text(h: float, l: float, m: int) -> str:  # noqa: E741
    return f"h={h:g}, l={l:g}, m={m}"


def _read(args, registry):
    """(data set, its design) with the CSV design from the flags."""
    from eyeviz import EyevizError, dataset
    from eyeviz.core.domain import PAPER_DOMAIN
    from eyeviz.core.geometry import EyePair

    path = Path(args.data)
    from eyeviz.dataset.io import format_of

    if format_of(path) == "npz":
        ds = dataset.load(path)
        design = (float(ds.eyes.h), float(ds.eyes.l), int(ds.eyes.m))
        flags = {k: getattr(args, k, None) for k in ("h", "l", "m")}
        given = {k: v for k, v in flags.items() if v is not None}
        file_design = dict(zip(("h", "l", "m"), design, strict=True))
        bad = {k: v for k, v in given.items() if float(v) != float(file_design[k])}
        if bad:
            raise EyevizError(
                f"{path} has design {_design_text(*design)}, but "
                + ", ".join(f"--{k} {v:g}" for k, v in bad.items())
                + " was given"
            )
        return ds, design
    dom = registry.domain_from_args(args, PAPER_DOMAIN)
    ds = dataset.load(path, EyePair(dom.h, dom.l, dom.m))
    return ds, dom.design


def run(args: argparse.Namespace) -> int:
    import numpy as np

    from eyeviz import EyevizError
    from eyeviz.core.domain import Domain
    from eyeviz.estimators import metrics, registry
    from eyeviz.files.atomic import atomic_output

    entry = registry.get(args.estimator)
    out = Path(args.out)
    if not Path(args.data).is_file():
        raise EyevizError(f"data file {args.data} not found")
    if same_file(args.data, out):
        raise EyevizError(
            f"output {args.out} is the input data file {args.data}; choose another -o"
        )
    if not (out.parent if str(out.parent) else Path(".")).is_dir():
        raise EyevizError(f"output directory {out.parent} does not exist")
    ds, design = _read(args, registry)
    kw = registry.options_from_args(entry.load_options, args)
    if args.weights is not None:
        kw["path"] = args.weights
    if entry.any_design:
        h, l, m = design  # noqa: E741
        kw["domain"] = registry.domain_from_args(args, Domain(h, l, m))
    est = entry.load_estimator(**kw)
    if est.domain.design != design:
        raise EyevizError(
            f"data set {args.data} has design {_design_text(*design)}, but estimator "
            f"{entry.name!r} answers for {_design_text(*est.domain.design)}"
        )
    pred = est.predict(ds.omega_a, ds.omega_b)
    table = np.column_stack([pred.r, pred.phi])
    with atomic_output(out) as tmp:
        np.savetxt(tmp, table, fmt="%.17g", delimiter=",", header="r_hat,phi_hat", comments="")
    n = len(pred.r)
    valid = np.asarray(pred.valid)
    msg = f"{args.estimator}: {n} rows -> {out}"
    if (~valid).any():
        msg += f"; {int((~valid).sum())} not a single feature (nan)"
    outside = valid & ~np.asarray(pred.in_domain)
    if outside.any():
        msg += f"; {int(outside.sum())} outside the training domain"
    print(msg, file=sys.stderr)
    if valid.sum() >= 2:
        dd = metrics.summary(ds.r[valid], pred.r[valid])
        ad = metrics.summary(ds.phi[valid], pred.phi[valid])
        print(
            f"DD MAPE {dd['mape']:.3f} %  MAE {dd['mae']:.2f}  R^2 {dd['r2']:.4f} | "
            f"AD MAPE {ad['mape']:.4f} %  MAE {ad['mae']:.3g} rad  R^2 {ad['r2']:.6f}",
            file=sys.stderr,
        )
    return 0
