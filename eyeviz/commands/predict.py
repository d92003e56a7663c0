"""``eyeviz predict --estimator NAME DATA.csv -o PRED.csv``: r_hat, phi_hat per row.

Reads a data set of DESIGN.md §3 (.csv or .npz), writes a CSV with a header line
``r_hat,phi_hat`` and one row per input row (``nan`` where a row is not a single
feature), atomically. Prints the metrics against the data's own r and phi.
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
from pathlib import Path

NAME = "predict"
HELP = "predict distance and azimuth for every row of a data set"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("data", help="data set (.csv or .npz, as `eyeviz generate` writes)")
    parser.add_argument(
        "-e",
        "--estimator",
        default="compact",
        help="analytic, bayes, compact or paper (default compact)",
    )
    parser.add_argument("-o", "--out", required=True, help="output CSV (r_hat,phi_hat)")
    parser.add_argument(
        "--weights", default=None, help="weights directory/file instead of the shipped ones"
    )


def run(args: argparse.Namespace) -> int:
    import numpy as np

    from eyeviz import EyevizError, dataset, estimators
    from eyeviz.estimators import metrics

    if args.estimator not in estimators.available():
        raise EyevizError(
            f"unknown estimator {args.estimator!r}; available: {', '.join(estimators.available())}"
        )
    out = Path(args.out)
    if not out.parent.is_dir():
        raise EyevizError(f"output directory {out.parent} does not exist")
    if not Path(args.data).is_file():
        raise EyevizError(f"data file {args.data} not found")
    kw = {} if args.weights is None else {"path": args.weights}
    est = estimators.load(args.estimator, **kw)
    ds = dataset.load(args.data, est.domain.eyes)
    pred = est.predict(ds.omega_a, ds.omega_b)
    table = np.column_stack([pred.r, pred.phi])
    fd, tmp = tempfile.mkstemp(prefix=out.name + ".", suffix=".tmp", dir=out.parent)
    os.close(fd)
    try:
        np.savetxt(tmp, table, fmt="%.17g", delimiter=",", header="r_hat,phi_hat", comments="")
        os.chmod(tmp, 0o644)
        os.replace(tmp, out)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
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
