"""`limit`'s speed against baselines measured in the same run (issue 25), as ratios.

1. cached path: the same 10^5 rows again (every key cached) against the bayes table
   lookup on those rows; target: limit / bayes time <= 1;
2. a new key's CPU cost (cache cold), now / before, against the computation before
   issue 25 (every ray's nodes, an argsort weighted median: the module as of commit
   PREVIOUS_COMMIT read from git, else a copy kept here), both measured in this run:
   ``limit_estimates`` batched (distinct keys) and one key per call, and the estimator
   (validation, cache look-up and insertion included) batched and one key per call;
   target: now / before <= 0.5;
3. keys no feature can produce (g = 5 beyond r = 1146: empty posterior) against real
   keys, one key per call; target: impossible / real <= 2.

``--large-m`` repeats item 2 at m = 2^20; ``--stages`` adds where a new key's time goes
(rays, nodes, medians; validation and cache bookkeeping as the estimator's time beyond
``limit_estimates``). The load average is printed before and after: other processes
inflate every figure, less so the ratios.

    PYTHONPATH=. .venv/bin/python scripts/bench_limit.py [--rows 100000] [--keys 2000]
        [--stages] [--large-m]
"""

from __future__ import annotations

import argparse
import os
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
    """The previous limit_estimates: nodes on every ray, argsort medians, 4x retry, in
    blocks of 200,000 nodes as before."""
    from eyeviz.estimators.limit import posterior_nodes

    step = max(1, 200_000 // (n * n * k))
    empty = np.zeros(len(keys), bool)
    for s0 in range(0, len(keys), step):
        nd = posterior_nodes(keys[s0 : s0 + step], domain, "single", n, k)
        empty[s0 : s0 + step] = ~(nd.w.sum(axis=1) > 0)
        with np.errstate(divide="ignore", invalid="ignore"):
            _previous_median(nd.r, nd.w / np.where(nd.r > 0, nd.r, 1.0))
            _previous_median(nd.phi, nd.w / np.where(nd.phi > 0, nd.phi, 1.0))
    if empty.any() and n < 48:
        _previous(keys[empty], domain, 4 * n, k)
    return empty


#: The last commit with the previous `limit` (sort-based median, nodes on every ray).
PREVIOUS_COMMIT = "6d63657"


def _previous_module():
    """The previous eyeviz/estimators/limit.py from git, imported on its own; None
    without git (then the in-file baseline :func:`_previous` is used)."""
    import importlib.util
    import subprocess
    import sys
    import tempfile
    from pathlib import Path

    root = Path(__file__).resolve().parents[1]
    try:
        src = subprocess.run(
            ["git", "show", f"{PREVIOUS_COMMIT}:eyeviz/estimators/limit.py"],
            cwd=root, capture_output=True, text=True, check=True, timeout=30,
        ).stdout  # fmt: skip
    except (OSError, subprocess.SubprocessError):
        return None
    path = Path(tempfile.mkdtemp()) / "limit_previous.py"
    path.write_text(src)
    spec = importlib.util.spec_from_file_location("limit_previous", path)
    if spec is None or spec.loader is None:
        return None
    mod = importlib.util.module_from_spec(spec)
    sys.modules["limit_previous"] = mod
    spec.loader.exec_module(mod)
    return mod


def _per_call(keys, make) -> None:
    """Each key through its own predict_intervals call on one fresh estimator: every key
    new to the cache."""
    est = make()
    for k in keys:
        est.predict_intervals(*(np.array([v]) for v in k))


def _stages(keys, one, domain, repeat: int, solve_one: float, est_one: float) -> None:
    """Where a new key's CPU time goes: batched, each stage timed in place over the
    blocks limit_estimates cuts (best of ``repeat``); per call, the estimator's time
    beyond limit_estimates (validation, in_domain, cache look-up and insertion)."""
    from eyeviz.estimators import limit_solve as ls

    p = ls.plan(domain, 12, 6)
    step = max(1, 60_000 // (12 * 12 * 6))
    best = {"rays": np.inf, "nodes": np.inf, "medians": np.inf}
    for _ in range(repeat):
        t = dict.fromkeys(best, 0.0)
        for i in range(0, len(keys), step):
            t0 = time.process_time()
            *ray, ok = ls.rays(keys[i : i + step], p)
            live = ok.any(axis=1)
            t1 = time.process_time()
            vals, wts, span, _ = ls._nodes(*(a[live] for a in ray), p, "single")
            t2 = time.process_time()
            ls.row_medians(vals, wts, span)
            t3 = time.process_time()
            t["rays"] += t1 - t0
            t["nodes"] += t2 - t1
            t["medians"] += t3 - t2
        best = {k: min(v, t[k]) for k, v in best.items()}
    total = _cpu(lambda: ls.estimates(keys, domain), repeat)
    n = len(keys)
    parts = ", ".join(f"{k} {v / n * 1e6:.1f} us" for k, v in best.items())
    rest = (total - sum(best.values())) / n * 1e6
    print(f"   stages, batched, a key: {parts}, the rest {rest:.1f} us (of {total / n * 1e6:.1f})")
    print(
        f"   one key per call: limit_estimates {solve_one * 1e3:.3f} ms, validation and cache "
        f"bookkeeping {(est_one - solve_one) * 1e3:.3f} ms (estimator {est_one * 1e3:.3f} ms)"
    )


def _large_m(prev, repeat: int) -> None:
    """Item 2 at m = 2^20 (MAX_M; keys beyond the int64 packing: the estimator's tuple
    cache), on the distinct keys of 300 fresh rows."""
    from eyeviz import dataset
    from eyeviz.core.bounds import MAX_M
    from eyeviz.core.domain import Domain
    from eyeviz.estimators.base import bitmaps_to_intervals
    from eyeviz.estimators.limit import LimitEstimator, limit_estimates

    dom = Domain(m=MAX_M)
    ds = dataset.generate(300, eyes=dom.eyes, seed=5)
    keys = np.unique(np.stack(bitmaps_to_intervals(ds.omega_a, ds.omega_b)[:4], 1), axis=0)
    one = keys[:100]
    t = [
        _cpu(lambda: limit_estimates(keys, dom), repeat),
        _cpu(lambda: prev.limit_estimates(keys, dom), repeat),
        _cpu(lambda: _per_call(one, lambda: LimitEstimator(dom)), repeat),
        _cpu(lambda: _per_call(one, lambda: prev.LimitEstimator(dom)), repeat),
    ]
    print(
        f"   m = 2^20, {len(keys)} keys: limit_estimates batched {t[0] / len(keys) * 1e6:.0f} us "
        f"a key (before {t[1] / len(keys) * 1e6:.0f} us), now / before {t[0] / t[1]:.2f}x; "
        f"the estimator one key per call {t[2] / len(one) * 1e3:.3f} ms (before "
        f"{t[3] / len(one) * 1e3:.3f} ms), now / before {t[2] / t[3]:.2f}x (target <= 0.5)"
    )


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rows", type=int, default=100_000)
    ap.add_argument("--keys", type=int, default=2000)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--stages", action="store_true", help="where a new key's time goes")
    ap.add_argument("--large-m", action="store_true", help="item 2 at m = 2^20 as well")
    args = ap.parse_args()
    print(f"load average at start: {os.getloadavg()[0]:.2f} (2 cores)")

    from eyeviz import dataset, estimators
    from eyeviz.estimators.base import PAPER_DOMAIN, bitmaps_to_intervals
    from eyeviz.estimators.limit import LimitEstimator, limit_estimates

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
    prev = _previous_module()
    old = prev.limit_estimates if prev is not None else _previous
    print(f"   previous: {'git ' + PREVIOUS_COMMIT if prev is not None else 'in-file copy'}")
    t_new = _cpu(lambda: limit_estimates(keys, d), args.repeat)
    t_old = _cpu(lambda: old(keys, d), args.repeat)
    s_new = _cpu(lambda: [limit_estimates(k[None], d) for k in one], args.repeat)
    s_old = _cpu(lambda: [old(k[None], d) for k in one], args.repeat)
    nk, n1 = len(keys), len(one)
    print(
        f"2. new key, limit_estimates: {nk} distinct keys batched {t_new / nk * 1e6:.0f} us "
        f"a key (before {t_old / nk * 1e6:.0f} us), now / before {t_new / t_old:.2f}x; one "
        f"key per call {s_new / n1 * 1e3:.3f} ms (before {s_old / n1 * 1e3:.3f} ms), now / "
        f"before {s_new / s_old:.2f}x (target <= 0.5)"
    )
    cols = [np.ascontiguousarray(c) for c in keys.T]
    e_new = _cpu(lambda: LimitEstimator().predict_intervals(*cols), args.repeat)
    if prev is not None:
        e_old = _cpu(lambda: prev.LimitEstimator().predict_intervals(*cols), args.repeat)
        p_old = _cpu(lambda: _per_call(one, prev.LimitEstimator), args.repeat)
    p_new = _cpu(lambda: _per_call(one, LimitEstimator), args.repeat)
    if prev is not None:
        print(
            f"   the estimator, cache cold: batched {e_new / nk * 1e6:.0f} us a key (before "
            f"{e_old / nk * 1e6:.0f} us), now / before {e_new / e_old:.2f}x; one key per call "
            f"{p_new / n1 * 1e3:.3f} ms (before {p_old / n1 * 1e3:.3f} ms), now / before "
            f"{p_new / p_old:.2f}x (target <= 0.5)"
        )
    if args.stages:
        _stages(keys, one, d, args.repeat, s_new / n1, p_new / n1)
    if args.large_m and prev is not None:
        _large_m(prev, args.repeat)

    eyes = d.eyes
    rng = np.random.default_rng(1)
    y = rng.uniform(1500, 4800, 400)
    x = rng.uniform(-0.2, 0.2, 400) * y
    imp = np.stack(eyes.intervals(x, y, np.full(400, 5.0)), 1)
    imp = np.unique(imp, axis=0)
    imp = imp[limit_estimates(imp, d)[2]][: len(one)]

    per_call = _per_call
    lim_new = lambda: estimators.load("limit")  # noqa: E731
    t_imp = _cpu(lambda: per_call(imp, lim_new), args.repeat) / len(imp)
    t_real = _cpu(lambda: per_call(one, lim_new), args.repeat) / len(one)
    b_imp = _cpu(lambda: limit_estimates(imp, d), args.repeat) / len(imp)
    b_real = _cpu(lambda: limit_estimates(one, d), args.repeat) / len(one)
    print(f"   batched: impossible {b_imp * 1e6:.0f} us/key, real {b_real * 1e6:.0f} us/key; "
          f"ratio {b_imp / b_real:.2f}x")  # fmt: skip
    if prev is not None:
        q_imp = _cpu(lambda: prev.limit_estimates(imp, d), args.repeat) / len(imp)
        q_real = _cpu(lambda: prev.limit_estimates(one, d), args.repeat) / len(one)
        print(f"   previous batched: impossible {q_imp * 1e6:.0f} us/key, real "
              f"{q_real * 1e6:.0f} us/key; ratio {q_imp / q_real:.2f}x")  # fmt: skip
    if prev is not None:
        p_imp = _cpu(lambda: per_call(imp, prev.LimitEstimator), args.repeat) / len(imp)
        p_real = _cpu(lambda: per_call(one, prev.LimitEstimator), args.repeat) / len(one)
        print(f"   previous: impossible {p_imp * 1e3:.3f} ms, real {p_real * 1e3:.3f} ms; "
              f"ratio {p_imp / p_real:.2f}x")  # fmt: skip
    print(
        f"3. one new key per predict call: impossible {t_imp * 1e3:.3f} ms "
        f"({len(imp)} keys), real {t_real * 1e3:.3f} ms; ratio {t_imp / t_real:.2f}x "
        "(target <= 2)"
    )
    print(f"load average at end: {os.getloadavg()[0]:.2f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
