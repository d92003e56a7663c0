"""``eyeviz train compact|bayes|paper``: fit the estimators that learn.

- ``compact``: generates its own data (single pass, Tables 3-4), trains the two compact
  networks with early stopping and writes ``compact_{dd,ad}.pt`` + ``compact.json``.
- ``bayes``: builds the posterior table of the information limit (``bayes.npz``).
- ``paper``: the paper's AD/DD networks (Appendix A/B) on a data file or on freshly
  generated data, for a wall-clock budget (:func:`eyeviz.estimators.paper.train`).

Weights are written atomically (temporary file + rename) after every improving epoch.
Nothing heavy is imported until ``run``.
"""

from __future__ import annotations

import argparse
import shlex
import sys

NAME = "train"
HELP = "train an estimator (compact networks, bayes table, or the paper's networks)"


def _positive_int(text: str) -> int:
    try:
        v = int(float(text))
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a positive integer, got {text!r}") from None
    if v < 1 or v != float(text):
        raise argparse.ArgumentTypeError(f"expected a positive integer, got {text!r}")
    return v


def _domain_args(p: argparse.ArgumentParser) -> None:
    g = p.add_argument_group("data parameters (defaults: Tables 3 and 4)")
    g.add_argument("--h", type=float, default=40.0)
    g.add_argument("--l", type=float, default=20.0)
    g.add_argument("--m", type=int, default=720)
    g.add_argument("--r-min", type=float, default=1000.0)
    g.add_argument("--r-max", type=float, default=5000.0)
    g.add_argument("--g-max", type=float, default=500.0)


def add_arguments(parser: argparse.ArgumentParser) -> None:
    sub = parser.add_subparsers(dest="what", metavar="ESTIMATOR", required=True)

    c = sub.add_parser("compact", help="the compact networks (a few minutes on 2 CPU cores)")
    c.add_argument("-o", "--out", default=None, help="output directory (default assets/models)")
    c.add_argument(
        "-n",
        "--n-train",
        type=_positive_int,
        default=1_000_000,
        help="training elements (default 10^6)",
    )
    c.add_argument("--n-val", type=_positive_int, default=100_000)
    c.add_argument("--epochs", type=_positive_int, default=12)
    c.add_argument("--hidden", type=_positive_int, default=32, help="DD hidden width")
    c.add_argument("--hidden-ad", type=_positive_int, default=8, help="AD hidden width")
    c.add_argument("--patience", type=_positive_int, default=3)
    c.add_argument("--seed", type=int, default=0)
    c.add_argument("--threads", type=_positive_int, default=2)
    _domain_args(c)

    b = sub.add_parser("bayes", help="the posterior table of the information limit")
    b.add_argument(
        "-o", "--out", default=None, help="output .npz (default assets/models/bayes.npz)"
    )
    b.add_argument(
        "-n",
        type=_positive_int,
        default=30_000_000,
        help="sample size (default 3*10^7; ~4 GB of memory while building)",
    )
    b.add_argument("--seed", type=int, default=12345)
    _domain_args(b)

    p = sub.add_parser("paper", help="the paper's AD and DD networks, for a time budget")
    p.add_argument(
        "data",
        nargs="?",
        default=None,
        help="training data (.csv or .npz from `eyeviz generate`); default: generate --n elements",
    )
    p.add_argument(
        "-n",
        type=_positive_int,
        default=100_000,
        help="elements to generate when no data file is given",
    )
    p.add_argument("--mode", choices=("single", "multi"), default="single")
    p.add_argument("--budget", type=float, default=600.0, help="seconds per network")
    p.add_argument("--device", default="cpu")
    p.add_argument("--nets", default="ad,dd", help="comma-separated subset of ad,dd")
    p.add_argument("--seed", type=int, default=0, help="data, split and init seed")
    p.add_argument(
        "--ad-lr",
        type=float,
        default=None,
        help="AD learning rate (default 0.003 as Appendix A; Table 5 says 0.004)",
    )
    p.add_argument(
        "--dd-momentum",
        type=float,
        default=None,
        help="DD Nesterov momentum (default 0 = Keras default = plain SGD)",
    )
    p.add_argument("--tag", default="", help="suffix of the output files (ad<TAG>.pt)")
    p.add_argument("--threads", type=_positive_int, default=None, help="torch CPU threads")
    p.add_argument(
        "-o",
        "--out",
        default=None,
        help="output directory (default assets/models/paper/ or the user cache)",
    )
    _domain_args(p)


def _domain(args):
    from eyeviz.estimators.base import Domain

    return Domain(args.h, args.l, args.m, args.r_min, args.r_max, args.g_max)


def _command() -> str:
    return "eyeviz " + " ".join(shlex.quote(a) for a in sys.argv[1:])


def run(args: argparse.Namespace) -> int:
    return {"compact": _compact, "bayes": _bayes, "paper": _paper}[args.what](args)


def _compact(args) -> int:
    from tqdm import tqdm

    from eyeviz.estimators import compact

    bar = tqdm(total=2 * args.epochs, desc="compact", unit="epoch", file=sys.stderr)

    def progress(label, ep, total, val):
        bar.set_postfix_str(f"{label} epoch {ep} val rel. error {100 * val:.4g} %")
        bar.update(1)

    try:
        meta = compact.train(
            args.out,
            args.n_train,
            args.n_val,
            args.seed,
            args.epochs,
            args.hidden,
            args.hidden_ad,
            patience=args.patience,
            domain=_domain(args),
            threads=args.threads,
            command=_command(),
            progress=progress,
        )
    finally:
        bar.close()
    v = meta["val_metrics"]
    print(
        f"compact: {meta['n_weights']} weights, {meta['train_seconds']} s; validation "
        f"DD MAPE {v['dd']['mape']:.3f} % R^2 {v['dd']['r2']:.4f}, "
        f"AD MAPE {v['ad']['mape']:.4f} %"
    )
    return 0


def _bayes(args) -> int:
    from tqdm import tqdm

    from eyeviz.estimators import bayes

    out = args.out or str(bayes.default_path())
    if not out.endswith(".npz"):
        raise ValueError(f"bayes output must end in .npz, got {out!r}")
    with tqdm(
        total=args.n, desc="bayes sample", unit="el", unit_scale=True, file=sys.stderr
    ) as bar:

        def progress(done, total):
            bar.update(done - bar.n)

        table = bayes.build_table(args.n, _domain(args), args.seed, progress)
    table["meta"]["command"] = _command()
    bayes.save_table(table, out)
    print(f"bayes: {table['meta']['keys']} keys from {args.n} elements -> {out}")
    return 0


def _paper(args) -> int:
    from eyeviz import dataset
    from eyeviz.estimators import paper

    if args.threads is not None:
        paper.torch.set_num_threads(args.threads)
    nets = tuple(s.strip() for s in args.nets.split(",") if s.strip())
    dom = _domain(args)
    if args.data:
        data = dataset.load(args.data, dom.eyes)
        params = {"file": args.data}
    else:
        data = dataset.generate(
            args.n, dom.eyes, dom.r_min, dom.r_max, dom.g_max, args.mode, args.seed
        )
        params = {**dom.to_dict(), "n": args.n, "mode": args.mode, "seed": args.seed}
    res = paper.train(
        data,
        args.budget,
        args.device,
        args.out,
        args.seed,
        nets=nets,
        ad_lr=args.ad_lr,
        dd_momentum=args.dd_momentum,
        tag=args.tag,
        data_params=params,
        command=_command(),
    )
    for meta in res.values():
        h = meta.get("heldout", {})
        print(
            f"{meta.get('label', '')}: held-out MAPE {h.get('mape', float('nan')):.3f} %, "
            f"MAE {h.get('mae', float('nan')):.4g}, R^2 {h.get('r2', float('nan')):.4f} "
            f"-> {meta.get('weights_file', '?')}"
        )
    return 0
