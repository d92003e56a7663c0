"""How the limit's DD moves with its accuracy setting (issue 38.2): limit3d's DD (mean
|dr| / r, %) over one fresh data set at nside 180 at several targets of the per-key
Monte-Carlo error, each against the tightest, on the same rows (paired: the differences
are far more precise than the DD itself). Prints a Markdown table and the keys/s of each.

    python scripts/check_limit3d_convergence.py [-n ROWS] [--seed SEED] [--nside NSIDE]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from eyeviz.core.domain3d import Domain3D
from eyeviz.dataset.algorithm1_3d import generate3d
from eyeviz.estimators.limit3d import Limit3DEstimator

TARGETS = (0.04, 0.02, 0.01, 0.005, 0.0025)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("-n", type=int, default=300)
    ap.add_argument("--seed", type=int, default=5550123)
    ap.add_argument("--nside", type=int, default=180)
    ap.add_argument("--max-batches", type=int, default=64)
    a = ap.parse_args()
    dom = Domain3D(nside=a.nside)
    ds = generate3d(a.n, dom, seed=a.seed)
    Limit3DEstimator(dom).predict_dataset(generate3d(4, dom, seed=1))  # warm
    rel = {}
    rows = []
    for t in TARGETS:
        est = Limit3DEstimator(dom, accuracy=t, max_batches=a.max_batches)
        t0 = time.perf_counter()
        p = est.predict_dataset(ds)
        dt = time.perf_counter() - t0
        rel[t] = np.abs(p.r - ds.r) / ds.r
        rows.append((t, dt, p))
    ref = rel[TARGETS[-1]]
    n = a.n
    print(f"limit3d DD at nside {a.nside}, {n} rows of seed {a.seed} (fresh), against target "
          f"{TARGETS[-1]} (max batches {a.max_batches})\n")  # fmt: skip
    print("| target | DD % | ± (rows) | DD - DD(tightest), points | ± (paired) | keys/s |"
          " median accepted | capped % | flagged % |")  # fmt: skip
    print("|---|---|---|---|---|---|---|---|---|")
    for t, dt, p in rows:
        d = rel[t] - ref
        print(
            f"| {t:g} | {100 * rel[t].mean():.3f} | {100 * rel[t].std() / np.sqrt(n):.3f} | "
            f"{100 * d.mean():+.4f} | {100 * d.std() / np.sqrt(n):.4f} | {n / dt:.1f} | "
            f"{np.median(p.n_accepted):.0f} | {100 * p.mc_capped.mean():.1f} | "
            f"{100 * p.flagged.mean():.1f} |"
        )


if __name__ == "__main__":
    main()
