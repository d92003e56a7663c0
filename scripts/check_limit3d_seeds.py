"""The converged DD of the limit by merging seeds (issue 38.2): the default estimator's
draws for the same keys under K seeds (each seed exactly what ``predict`` at the default
accuracy uses), and the DD of the answers from the draws of the first k seeds merged, for
k = 1, 2, 4, ... K, on the same fresh rows. Merging k seeds multiplies each key's draws
by k, so the Monte-Carlo part of the DD falls as 1 / k: DD(k) = DD(inf) + delta / k, and
DD(inf) = 2 DD(K) - DD(K / 2). Paired differences with bootstrap standard errors over rows.

The answers are limit3d's own: the weighted medians of r (weights w / r) over the merged
draws (``Limit3DEstimator._posterior``, the draws ``predict`` uses; it is private, so this
check follows the estimator's code). k = 1 is checked against ``predict`` on the rows.

    python scripts/check_limit3d_seeds.py [-n ROWS] [--rows N] [--seed SEED] [-k K]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from eyeviz.core.domain import Domain3D
from eyeviz.dataset.algorithm1_3d import generate3d
from eyeviz.estimators.base import take_rows
from eyeviz.estimators.limit3d import Limit3DEstimator
from eyeviz.estimators.weighted import weighted_median
from eyeviz.files.atomic import atomic_output
from eyeviz.reports.errors import bootstrap_se


def _draws(est: Limit3DEstimator, la, lb, rows: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    sm = est._posterior(take_rows(*la, rows), take_rows(*lb, rows))
    return sm["r"], sm["w"]


def _answer(r: np.ndarray, w: np.ndarray) -> np.ndarray:
    with np.errstate(invalid="ignore", divide="ignore"):
        return weighted_median(r, w / r)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("-n", type=int, default=2400, help="rows generated (as the other check)")
    ap.add_argument("--rows", type=int, default=800, help="the first ROWS rows are used")
    ap.add_argument("--seed", type=int, default=20261204)
    ap.add_argument("--nside", type=int, default=180)
    ap.add_argument("-k", type=int, default=4, help="seeds merged (a power of 2)")
    ap.add_argument("--out", default="")
    a = ap.parse_args()
    dom = Domain3D(nside=a.nside)
    ds = generate3d(a.n, dom, seed=a.seed)
    la, lb = (ds.indptr_a, ds.indices_a), (ds.indptr_b, ds.indices_b)
    n = min(a.rows, a.n)
    ests = [Limit3DEstimator(dom, seed=s) for s in range(a.k)]
    ks = [k for k in (1, 2, 4, 8, 16, 32) if k <= a.k]
    ans = {k: np.empty(n) for k in ks}
    each = np.empty((a.k, n))
    t0 = time.perf_counter()
    for s0 in range(0, n, 8):
        rows = np.arange(s0, min(n, s0 + 8))
        rs, ws = zip(*(_draws(e, la, lb, rows) for e in ests), strict=True)
        for j in range(a.k):
            each[j, rows] = _answer(rs[j], ws[j])
        for k in ks:
            ans[k][rows] = _answer(np.concatenate(rs[:k], 1), np.concatenate(ws[:k], 1))
        if s0 % 200 == 0:
            print(f"{s0} rows, {time.perf_counter() - t0:.0f} s", flush=True)
    dt = time.perf_counter() - t0
    true = ds.r[:n]
    rel = {k: 100 * np.abs(v - true) / true for k, v in ans.items()}
    one = 100 * np.abs(each - true) / true  # every seed alone: the default, K times
    m = min(n, 48)  # k = 1 against predict on the first rows
    p = ests[0].predict(take_rows(*la, np.arange(m)), take_rows(*lb, np.arange(m)))
    same = np.isclose(p.r, ans[1][:m], rtol=1e-12).mean()
    if a.out:
        with atomic_output(a.out) as tmp:
            np.savez(tmp, **{f"rel_{k}": v for k, v in rel.items()}, each=one, true=true)
    kk = ks[-1]
    print(f"\nlimit3d at its default accuracy, {n} fresh rows of seed {a.seed} at nside "
          f"{a.nside}; draws of k seeds merged; {dt:.0f} s for {a.k} seeds; k = 1 equals "
          f"predict's answer on {100 * same:.1f} % of the first {m} rows\n")  # fmt: skip
    print("| seeds merged k | DD % | ± | DD(k) - DD(K), points | ± |")
    print("|---|---|---|---|---|")
    for k in ks:
        d = rel[k] - rel[kk]
        print(f"| {k} | {rel[k].mean():.4f} | {bootstrap_se(rel[k]):.4f} | "
              f"{d.mean():+.4f} | {bootstrap_se(d) if k != kk else 0:.4f} |")  # fmt: skip
    mean_one = one.mean(axis=0)  # the default's DD averaged over its K seeds, per row
    half = ks[-2] if len(ks) > 1 else kk
    conv = 2 * rel[kk] - rel[half]  # per row: DD(inf) = 2 DD(K) - DD(K/2)
    gap = mean_one - conv
    print(f"\nthe default (one seed; mean of the {a.k} seeds' DD): {mean_one.mean():.4f} ± "
          f"{bootstrap_se(mean_one):.4f} %; extrapolated converged DD(inf) = 2 DD({kk}) - "
          f"DD({half}): {conv.mean():.4f} ± {bootstrap_se(conv):.4f} %; default - DD(inf) "
          f"= {gap.mean():+.4f} ± {bootstrap_se(gap):.4f} points (paired)")  # fmt: skip


if __name__ == "__main__":
    main()
