"""Measure three triangulation rules for measured eyes on a 3D data set (docs/measured.md).

- *boundary rays* (analytic3d): per eye the ray from the lit facets' mean lens position
  along the centre of the cap fitted to the lit set's inner boundary
  (``triangulation.boundary_rays``), then as the mean rays;
- *mean rays* (analytic3d before): per eye the ray from the lit facets' mean lens position
  along their normalised mean axis, the midpoint of the two rays' closest approach;
  rays that do not meet in front of both eyes are flagged (answer r_max along their mean);
- *all facet lines*: the least-squares point nearest every lit facet's line (through its
  lens along its axis), sum (I - a a^T) p = sum (I - a a^T) lens, each eye's rows weighted
  1 / (its lit count) so both eyes count equally; flagged when the 3x3 system's condition
  number exceeds 1e8 or the point is behind either eye's mean ray.

Prints DD (distance MAPE), AD and elevation error (median, degrees) and the flagged
fraction of each, on all rows and on the rows the mean-rays rule does not flag, each
figure ± its bootstrap standard error over the rows (1,000 resamples, seed 0: the mean's
by :func:`eyeviz.reports.errors.bootstrap_se`, the medians' and the fraction's alike).

Run: ``python scripts/compare_triangulation3d.py BEE.npz`` (from ``eyeviz generate --eye``)
"""

from __future__ import annotations

import argparse

import numpy as np

from eyeviz.dataset.sparse3d import load3d
from eyeviz.estimators import analytic3d
from eyeviz.estimators.triangulation import lens_rays, triangulate_rays
from eyeviz.reports.errors import N_BOOT, bootstrap_se, with_error


def _normal_equations(pos, axes, lit) -> tuple[np.ndarray, np.ndarray]:
    """Per row: (M (n, 3, 3), b (n, 3)) of one eye's lit facets' lines, weight 1 / count."""
    ptr, idx = np.asarray(lit[0], np.int64), np.asarray(lit[1], np.int64)
    n, cnt = ptr.size - 1, np.diff(ptr)
    a = axes[idx] / np.linalg.norm(axes[idx], axis=1, keepdims=True)
    p = pos[idx]
    row = np.repeat(np.arange(n), cnt)
    w = 1.0 / np.maximum(cnt, 1)[row]
    m = np.empty((n, 3, 3))
    b = np.empty((n, 3))
    ap = np.einsum("ij,ij->i", a, p)
    for i in range(3):
        b[:, i] = np.bincount(row, w * (p[:, i] - a[:, i] * ap), minlength=n)
        for j in range(3):
            m[:, i, j] = np.bincount(row, w * (float(i == j) - a[:, i] * a[:, j]), minlength=n)
    return m, b


def all_lines(domain, lit_a, lit_b):
    """(r, azimuth, elevation, flagged) of the least-squares point of all lit facets' lines."""
    eyes = domain.eyes
    (pa, xa, _), (pb, xb, _) = eyes.facets("A"), eyes.facets("B")
    ma, ba = _normal_equations(pa, xa, lit_a)
    mb, bb = _normal_equations(pb, xb, lit_b)
    m, b = ma + mb, ba + bb
    ev = np.linalg.eigvalsh(m)
    ok = ev[:, 0] > 1e-8 * ev[:, 2]
    p = np.linalg.solve(np.where(ok[:, None, None], m, np.eye(3)), b[..., None])[..., 0]
    oa, u, _ = lens_rays(pa, xa, lit_a)
    ob, v, _ = lens_rays(pb, xb, lit_b)
    ok &= (np.einsum("ij,ij->i", p - oa, u) > 0) & (np.einsum("ij,ij->i", p - ob, v) > 0)
    return _answer(domain, p, ok, u, v)


def _answer(domain, p, ok, u, v):
    mean = (u + v) / np.linalg.norm(u + v, axis=1, keepdims=True)
    q = np.where(ok[:, None], p - np.asarray(domain.origin), domain.r_max * mean)
    rho = np.linalg.norm(q, axis=1)
    r = np.clip(rho, domain.r_min, domain.r_max)
    return r, np.arctan2(q[:, 1], q[:, 0]), np.arcsin(np.clip(q[:, 2] / rho, -1, 1)), ~ok


def mean_rays(domain, lit_a, lit_b):
    """(r, azimuth, elevation, flagged) of the two mean rays' closest approach."""
    (pa, xa, _), (pb, xb, _) = domain.eyes.facets("A"), domain.eyes.facets("B")
    oa, u, _ = lens_rays(pa, xa, lit_a)
    ob, v, _ = lens_rays(pb, xb, lit_b)
    p, ok = triangulate_rays(oa, u, ob, v)
    return _answer(domain, p, ok, u, v)


def _median_se(terms: np.ndarray, n_boot: int = N_BOOT, seed: int = 0) -> float:
    """The bootstrap standard error of ``median(terms)`` (resampling the rows)."""
    rng = np.random.default_rng(seed)
    idx = rng.integers(0, terms.size, size=(n_boot, terms.size))
    return float(np.median(terms[idx], axis=1).std(ddof=1))


def scores(ds, est, rows) -> str:
    r, az, el, flagged = est
    fl = flagged.astype(float)
    fl_text = f"flagged {with_error(100 * fl.mean(), 100 * bootstrap_se(fl))} %"
    if not rows.any():
        return f"no rows  {fl_text}"
    dd = 100 * np.abs(r[rows] - ds.r[rows]) / ds.r[rows]
    dz = np.degrees(np.abs(np.angle(np.exp(1j * (az[rows] - ds.azimuth[rows])))))
    de = np.degrees(np.abs(el[rows] - ds.elevation[rows]))
    return (
        f"DD {with_error(dd.mean(), bootstrap_se(dd))} %  "
        f"AD {with_error(np.median(dz), _median_se(dz))} deg  "
        f"elevation {with_error(np.median(de), _median_se(de))} deg  {fl_text}"
    )


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("data")
    args = ap.parse_args(argv)
    ds = load3d(args.data)
    la, lb = (ds.indptr_a, ds.indices_a), (ds.indptr_b, ds.indices_b)
    rules = (
        ("boundary rays", analytic3d.estimate(ds.domain, la, lb)),
        ("mean rays", mean_rays(ds.domain, la, lb)),
        ("all facet lines", all_lines(ds.domain, la, lb)),
    )
    old = rules[1][1]
    every = np.ones(ds.r.size, bool)
    for label, rows in (("all rows", every), ("rows the mean rays meet", ~old[3])):
        print(f"{label} ({rows.sum()}):")
        for name, est in rules:
            print(f"  {name:16s} {scores(ds, est, rows)}")


if __name__ == "__main__":
    main()
