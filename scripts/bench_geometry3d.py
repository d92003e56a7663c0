"""Benchmark: exact lit sets of the spherical eyes against astropy-healpix and healpy.

Paper-regime balls (h = 40, l = 20, r in [1000, 5000], azimuth inside the planar BFV,
elevation within +-30 deg, g in [r sin(gamma/2), 500]) seen by both eyes. Ours:
``EyePair3D.lit_csr`` on the whole batch (exact). Theirs, one cone per ball and eye:
astropy-healpix ``HEALPix.cone_search_lonlat`` (nside a power of two only) and healpy
``query_disc(inclusive=True)`` (any nside; GPL, only if installed:
``pip install -e .[bench]``). Neither is exact; the script counts the balls where their
set differs from ours. Targets (issue 21): ours >= 2x faster than astropy-healpix and at
least as fast as healpy. Times are measured in the same run.

    .venv/bin/python scripts/bench_geometry3d.py [-n 1000] [--n-astropy 100] [--seed 0]
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np

from eyeviz.core.geometry3d import FALLBACK_COUNTS, EyePair3D

H, L = 40.0, 20.0


def paper_balls(n: int, nside: int, rng: np.random.Generator):
    gamma = 2 * math.pi / (4 * nside)
    r = rng.uniform(1000, 5000, 4 * n)
    gmin = r * math.sin(gamma / 2)
    g = rng.uniform(gmin, 500)
    ok = g <= r
    r, g = r[ok][:n], g[ok][:n]
    psi = math.asin(L / H)
    a = np.arcsin(g / r)
    az = rng.uniform(psi + a, math.pi - psi - a)
    el = rng.uniform(-math.pi / 6, math.pi / 6, r.size)
    x = r * np.cos(el) * np.cos(az)
    y = r * np.cos(el) * np.sin(az)
    z = r * np.sin(el)
    return x, y, z, g


def cones(x, y, z, g):
    """Per eye (A, B): unit direction vectors and cap radii (radians)."""
    out = []
    for cx in (-H, H):
        d = np.stack([x - cx, y, z], -1)
        dist = np.linalg.norm(d, axis=1)
        out.append((d / dist[:, None], np.arcsin(np.minimum(g / dist, 1.0))))
    return out


def best_of(fun, repeat: int = 3) -> tuple[float, object]:
    best, res = math.inf, None
    for _ in range(repeat):
        t = time.perf_counter()
        res = fun()
        best = min(best, time.perf_counter() - t)
    return best, res


def ours(nside, x, y, z, g):
    e = EyePair3D(H, L, nside)
    return best_of(lambda: e.lit_csr(x, y, z, g))


def differ(csr, sets) -> int:
    (pa, ia), (pb, ib) = csr
    bad = 0
    for i, (sa, sb) in enumerate(sets):
        if not (
            np.array_equal(np.sort(sa), ia[pa[i] : pa[i + 1]])
            and np.array_equal(np.sort(sb), ib[pb[i] : pb[i + 1]])
        ):
            bad += 1
    return bad


def run_astropy(nside, x, y, z, g):
    import astropy.units as u
    from astropy_healpix import HEALPix

    hp = HEALPix(nside=nside, order="ring")
    (va, ra), (vb, rb) = cones(x, y, z, g)

    def go():
        res = []
        for v_a, r_a, v_b, r_b in zip(va, ra, vb, rb, strict=True):
            pair = []
            for v, r in ((v_a, r_a), (v_b, r_b)):
                lon = math.atan2(v[1], v[0]) * u.rad
                lat = math.asin(max(-1.0, min(1.0, v[2]))) * u.rad
                pair.append(hp.cone_search_lonlat(lon, lat, r * u.rad))
            res.append(pair)
        return res

    return best_of(go, 1)


def run_healpy(nside, x, y, z, g):
    import healpy

    (va, ra), (vb, rb) = cones(x, y, z, g)

    def go():
        return [
            (
                healpy.query_disc(nside, v_a, r_a, inclusive=True),
                healpy.query_disc(nside, v_b, r_b, inclusive=True),
            )
            for v_a, r_a, v_b, r_b in zip(va, ra, vb, rb, strict=True)
        ]

    return best_of(go)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("-n", type=int, default=1000, help="balls per nside (default 1000)")
    ap.add_argument(
        "--n-astropy",
        type=int,
        default=100,
        help="of them, how many astropy-healpix searches (slow: 0.3 s per ball at nside 256)",
    )
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args()
    try:
        import healpy  # noqa: F401

        have_healpy = True
    except ImportError:
        have_healpy = False
    print(
        f"{args.n} paper-regime balls, both eyes, ours in one batch; times are the best of 3 "
        f"(astropy-healpix: one pass over the first {args.n_astropy})"
    )
    for nside in (16, 64, 128, 180, 256):
        rng = np.random.default_rng(args.seed + nside)
        x, y, z, g = paper_balls(args.n, nside, rng)
        FALLBACK_COUNTS.clear()
        t_ours, csr = ours(nside, x, y, z, g)
        lit = (csr[0][0][-1] + csr[1][0][-1]) / (2 * x.size)
        exact_cells = FALLBACK_COUNTS["exact"] // 3
        print(
            f"nside {nside:4d}: ours {t_ours / x.size * 1e6:8.1f} us/ball "
            f"(mean {lit:7.0f} facets per eye; {exact_cells} cells to mpmath)"
        )
        if nside & (nside - 1) == 0:
            k = min(args.n_astropy, x.size)
            t_ap, sets = run_astropy(nside, x[:k], y[:k], z[:k], g[:k])
            per_ap, per_ours = t_ap / k, t_ours / x.size
            print(
                f"    astropy-healpix cone_search_lonlat {per_ap * 1e6:8.1f} us/ball: "
                f"ours {per_ap / per_ours:5.2f}x faster (target >= 2); "
                f"{differ(csr, sets)}/{k} balls differ from the exact sets"
            )
        else:
            print("    astropy-healpix: nside must be a power of two (not compared)")
        if have_healpy:
            t_hp, sets = run_healpy(nside, x, y, z, g)
            print(
                f"    healpy query_disc(inclusive=True) {t_hp / x.size * 1e6:8.1f} us/ball: "
                f"ours {t_hp / t_ours:5.2f}x as fast (target >= 1); "
                f"{differ(csr, sets)}/{x.size} balls differ from the exact sets"
            )
        else:
            print("    healpy not installed (pip install -e .[bench]); not compared")


if __name__ == "__main__":
    main()
