"""Cost of the ``posterior`` layer during a drag (issue 10 item 5): it must not slow one.

Measured in the same run, as ratios against the baseline a drag frame pays anyway:
``compute_state`` of the default scene (three features, every layer's geometry).

- new key: the posterior computed (limit estimate, quadrature nodes, density on the grid);
  paid once per key met (a drag changes the key every few pixels at most);
- same key: the lookup a frame pays while the key holds (intervals of one feature + cache).

    PYTHONPATH=$PWD .venv/bin/python scripts/bench_posterior.py [--keys 60]
"""

from __future__ import annotations

import argparse
import statistics
import time


def _median_ms(fn, n: int) -> float:
    out = []
    for _ in range(n):
        t = time.perf_counter()
        fn()
        out.append(time.perf_counter() - t)
    return 1e3 * statistics.median(out)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--keys", type=int, default=60, help="distinct keys to time")
    args = ap.parse_args()

    import numpy as np

    from eyeviz.core.domain import Domain
    from eyeviz.model import posterior as pm
    from eyeviz.model.scene import load
    from eyeviz.model.state import compute_state
    from eyeviz.resources import scene_path

    sc = load(scene_path("default"))
    pair = sc.eyes.pair()
    dom = Domain.from_eyes(pair)
    base = _median_ms(lambda: compute_state(sc), 200)
    rng = np.random.default_rng(1)
    feats = []
    while len(feats) < args.keys:
        r, phi, g = rng.uniform(1200, 4800), rng.uniform(1.2, 1.95), rng.uniform(20, 400)
        x, y = r * np.cos(phi), r * np.sin(phi)
        k = pm.key_of(pair, x, y, g)
        if k not in {f[3] for f in feats}:
            feats.append((x, y, g, k))
    pm.posterior_for_key(feats[0][3], dom)  # imports, warm-up
    pm._CACHE.clear()
    new = []
    for x, y, g, _ in feats:
        t = time.perf_counter()
        pm.posterior_for_key(pm.key_of(pair, x, y, g), dom)
        new.append(time.perf_counter() - t)
    x, y, g, _ = feats[-1]
    same = _median_ms(lambda: pm.posterior_for_key(pm.key_of(pair, x, y, g), dom), 500)
    new_ms = 1e3 * statistics.median(new)
    p95 = 1e3 * float(np.percentile(new, 95))
    print(f"baseline compute_state (default scene): {base:.3f} ms")
    print(f"posterior, new key:  median {new_ms:.2f} ms, p95 {p95:.2f} ms  ({new_ms / base:.1f}x)")
    print(f"posterior, same key: median {same:.4f} ms  ({same / base:.2f}x)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
