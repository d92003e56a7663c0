"""Train the learned 3D estimator and write it into the shipped assets (or ``-o DIR``).

    .venv/bin/python scripts/train_learned3d.py --seed 20261125 [-o DIR] [-n 500000]

The training set is Algorithm 1 in 3D (single pass, default design: Domain3D) drawn
with ``--seed``, the validation set with ``--seed + 1``; both are recorded in
learned3d.json. Prints the metadata's timings and validation metrics.
"""

from __future__ import annotations

import argparse
import json
import shlex
import sys
from pathlib import Path


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seed", type=int, required=True)
    ap.add_argument("-o", "--out", default=None, help="default: eyeviz/assets/models/learned3d")
    ap.add_argument("-n", type=int, default=500_000)
    ap.add_argument("--n-val", type=int, default=50_000)
    ap.add_argument("--hidden", type=int, default=128)
    ap.add_argument("--epochs", type=int, default=40)
    ap.add_argument("--threads", type=int, default=1)
    args = ap.parse_args(argv)

    from eyeviz.estimators.learned3d import default_dir
    from eyeviz.estimators.learned3d_training import train

    out = Path(args.out) if args.out else default_dir()
    command = "scripts/train_learned3d.py " + " ".join(
        shlex.quote(a) for a in (sys.argv[1:] if argv is None else argv)
    )

    def progress(name: str, ep: int, total: int, val: float) -> None:
        print(f"{name}: epoch {ep}/{total} validation loss {val:.5f}", file=sys.stderr)

    meta = train(
        out,
        n_train=args.n,
        n_val=args.n_val,
        seed=args.seed,
        epochs=args.epochs,
        hidden=args.hidden,
        threads=args.threads,
        command=command,
        progress=progress,
    )
    keys = ("data_seconds", "fit_seconds", "train_seconds", "val_metrics")
    print(json.dumps({k: meta[k] for k in keys}, indent=2))
    print(f"wrote {out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
