"""`limit`'s speed against baselines measured in the same run (issue 25), as ratios.

1. cached path: the same 10^5 rows again (every key cached) against the bayes table
   lookup on those rows; target: limit / bayes time <= 1;
2. a new key's CPU cost, batched (distinct keys, empty cache) and one key per call,
   against the previous computation (every ray's nodes, an argsort weighted median; kept
   here as the baseline); target: new / previous <= 0.5;
3. keys no feature can produce (g = 5 beyond r = 1146: empty posterior) against real
   keys, one key per call; target: impossible / real <= 2.

    PYTHONPATH=. .venv/bin/python scripts/bench_limit.py [--rows 100000] [--keys 2000]
"""

from __future__ import annotations

import argparse
import time

import numpy as np


def _cpu(fn, repeat: int) -> float:
    best = float("inf")
    for _ in range(repeat):
        t = time.process_time()
        fn()
        best = min(best, time.process_time() - t)
    return best


def _previous_median(v, w):
    """The weighted median as it was: argsort and two gathers per row."""
    order = np.argsort(v, axis=1)
    vs = np.take_along_axis(v, order, 1)
    ws = np.take_along_axis(w, order, 1)
    cw = np.cumsum(ws, axis=1)
    tot = cw[:, -1:]
    mid = (cw - 0.5 * ws) / np.where(tot > 0, tot, 1.0)
    i1 = np.clip((mid < 0.5).sum(axis=1), 1, v.shape[1] - 1)
    i0 = i1 - 1
    rows = np.arange(v.shape[0])
    m0, m1 = mid[rows, i0], mid[rows, i1]
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.clip((0.5 - m0) / (m1 - m0), 0.0, 1.0)
    t = np.where(np.isfinite(t), t, 0.0)
    return vs[rows, i0] + t * (vs[rows, i1] - vs[rows, i0])


def _previous(keys, domain, n=12, k=6):
    """The previous limit_estimates: nodes on every ray, argsort medians, 4x retry."""
    from eyeviz.estimators.limit import posterior_nodes

    nd = posterior_nodes(keys, domain, "single", n, k)
    e = ~(nd.w.sum(axis=1) > 0)
    with np.errstate(divide="ignore", invalid="ignore"):
        r = _previous_median(nd.r, nd.w / np.where(nd.r > 0, nd.r, 1.0))
        p = _previous_median(nd.phi, nd.w / np.where(nd.phi > 0, nd.phi, 1.0))
    if e.any() and n < 48:
        _previous(keys[e], domain, 4 * n, k)
    return r, p, e


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rows", type=int, default=100_000)
    ap.add_argument("--keys", type=int, default=2000)
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()

    from eyeviz import dataset, estimators
    from eyeviz.estimators.base import PAPER_DOMAIN, bitmaps_to_intervals
    from eyeviz.estimators.limit import limit_estimates

    ds = dataset.generate(args.rows, seed=2024)
    a, b = ds.omega_a, ds.omega_b
    lim = estimators.load("limit")
    lim.predict(a, b)  # every key cached
    bay = estimators.load("bayes")
    t_lim = _cpu(lambda: lim.predict(a, b), args.repeat)
    t_bay = _cpu(lambda: bay.predict(a, b), args.repeat)
    print(
        f"1. cached path, {args.rows:,} rows: limit {t_lim * 1e3:.0f} ms, bayes lookup "
        f"{t_bay * 1e3:.0f} ms CPU; limit / bayes {t_lim / t_bay:.2f}x (target <= 1)"
    )

    iv = np.stack(bitmaps_to_intervals(a, b)[:4], 1)
    keys = np.unique(iv, axis=0)[: args.keys]
    one = keys[:200]
    d = PAPER_DOMAIN
    t_new = _cpu(lambda: limit_estimates(keys, d), args.repeat)
    t_old = _cpu(lambda: _previous(keys, d), args.repeat)
    s_new = _cpu(lambda: [limit_estimates(k[None], d) for k in one], args.repeat)
    s_old = _cpu(lambda: [_previous(k[None], d) for k in one], args.repeat)
    print(
        f"2. new key, {len(keys)} distinct keys batched: {t_new / len(keys) * 1e6:.0f} us "
        f"(previous {t_old / len(keys) * 1e6:.0f} us), ratio {t_new / t_old:.2f}x; one key "
        f"per call: {s_new / len(one) * 1e3:.3f} ms (previous {s_old / len(one) * 1e3:.3f} "
        f"ms), ratio {s_new / s_old:.2f}x (target <= 0.5)"
    )

    eyes = d.eyes
    rng = np.random.default_rng(1)
    y = rng.uniform(1500, 4800, 400)
    x = rng.uniform(-0.2, 0.2, 400) * y
    imp = np.stack(eyes.intervals(x, y, np.full(400, 5.0)), 1)
    imp = np.unique(imp, axis=0)
    imp = imp[limit_estimates(imp, d)[2]][: len(one)]

    def per_call(kk):
        est = estimators.load("limit")
        for k in kk:
            est.predict_intervals(*(np.array([v]) for v in k))

    t_imp = _cpu(lambda: per_call(imp), args.repeat) / len(imp)
    t_real = _cpu(lambda: per_call(one), args.repeat) / len(one)
    print(
        f"3. one new key per predict call: impossible {t_imp * 1e3:.3f} ms "
        f"({len(imp)} keys), real {t_real * 1e3:.3f} ms; ratio {t_imp / t_real:.2f}x "
        "(target <= 2)"
    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
