"""Graded responses against the lit sets they sit on (issue 34): the time of
``responses(kind)`` over the time of ``lit_csr`` for the same balls, measured in the same
run (best of --repeat), for the honeybee (flat, gaussian), HEALPix (cell) and the planar
ring (cell, against ``intervals``).

    python scripts/bench_responses.py [--balls 2000] [--repeat 3]
"""

from __future__ import annotations

import argparse
import time

import numpy as np


def best(f, repeat: int) -> float:
    ts = []
    for _ in range(repeat):
        t = time.perf_counter()
        f()
        ts.append(time.perf_counter() - t)
    return min(ts)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--balls", type=int, default=2000)
    ap.add_argument("--repeat", type=int, default=3)
    a = ap.parse_args()
    from eyeviz.core.geometry import EyePair
    from eyeviz.core.geometry3d import EyePair3D
    from eyeviz.measured import load_eyes, shipped_eye

    rng = np.random.default_rng(34)
    n = a.balls
    bee = load_eyes(shipped_eye("AM_60185-real.eye"))
    x, y, z = rng.uniform(-20, 20, (3, n))
    g = rng.uniform(0.1, 3, n)
    bee.responses(x[:64], y[:64], z[:64], g[:64])  # warm the kernels
    base = best(lambda: bee.lit_csr(x, y, z, g), a.repeat)
    pairs = int(bee.lit_csr(x, y, z, g)[0][0][-1])
    print(f"honeybee, {n} balls ({pairs} lit pairs in eye A): lit_csr {base:.3f} s")
    for kind in ("flat", "gaussian"):
        t = best(lambda k=kind: bee.responses(x, y, z, g, kind=k), a.repeat)
        print(f"  responses {kind:8s} {t:.3f} s  ratio {t / base:.1f}")
    hp = EyePair3D(40.0, 20.0, 16)
    m = max(1, n // 100)
    x3, y3, z3 = rng.uniform(-200, 200, (3, m))
    g3 = rng.uniform(1, 40, m)
    base = best(lambda: hp.lit_csr(x3, y3, z3, g3), a.repeat)
    t = best(lambda: hp.responses(x3, y3, z3, g3), a.repeat)
    print(
        f"HEALPix nside 16, {m} balls: lit_csr {base:.3f} s, cell {t:.3f} s, ratio {t / base:.1f}"
    )
    ring = EyePair(40.0, 20.0, 720)
    xp, yp = rng.uniform(-300, 300, (2, n))
    gp = rng.uniform(0.5, 30, n)
    base = best(lambda: ring.intervals(xp, yp, gp), a.repeat)
    t = best(lambda: ring.responses(xp, yp, gp), a.repeat)
    print(f"planar m 720, {n} discs: intervals {base:.4f} s, cell {t:.4f} s, ratio {t / base:.1f}")


if __name__ == "__main__":
    main()
