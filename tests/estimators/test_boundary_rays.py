"""The measured eyes' rays from the lit set's inner boundary (triangulation.boundary_rays):
unbiased where an eye's field cuts the lit cap off, and on the honeybee a better
triangulation than the lit facets' mean rays (docs/measured.md)."""

from __future__ import annotations

import math

import numpy as np

from eyeviz.core.domain import Domain3D
from eyeviz.dataset.algorithm1_3d import generate3d
from eyeviz.estimators import analytic3d
from eyeviz.estimators.triangulation import boundary_rays, lens_rays, triangulate_rays


def _fibonacci(n: int) -> np.ndarray:
    k = np.arange(n) + 0.5
    z = 1 - 2 * k / n
    phi = k * math.pi * (3 - math.sqrt(5))
    rho = np.sqrt(1 - z * z)
    return np.column_stack([rho * np.cos(phi), rho * np.sin(phi), z])


def test_a_cap_cut_off_by_the_eyes_rim_keeps_its_centre():
    # an eye whose axes cover the sphere's x <= 0.05 half (its rim is the plane x = 0.05),
    # and a cap of 12 degrees about a direction 3 degrees inside the rim: the lit axes'
    # mean leans away from the rim by several degrees, the boundary fit does not
    axes = _fibonacci(40000)
    axes = axes[axes[:, 0] <= 0.05]
    pos = np.zeros_like(axes)
    d = np.array([0.05 - math.sin(math.radians(3.0)), 0.0, 0.0])
    d[1] = math.sqrt(1 - d[0] ** 2)
    lit = np.flatnonzero(axes @ d >= math.cos(math.radians(12.0)))
    csr = (np.array([0, lit.size]), lit)
    _, mean, _ = lens_rays(pos, axes, csr)
    _, fit, fitted = boundary_rays(pos, axes, csr)
    err_mean = math.degrees(math.acos(min(1.0, float(mean[0] @ d))))
    err_fit = math.degrees(math.acos(min(1.0, float(fit[0] @ d))))
    assert fitted[0]
    assert err_mean > 2.0 and err_fit < 0.3, (err_mean, err_fit)
    # one lit facet: its six neighbours ring it, and the fit is its own axis (to a
    # fraction of the 1-degree spacing)
    one = (np.array([0, 1]), lit[:1])
    _, v, ok = boundary_rays(pos, axes, one)
    a = axes[lit[0]] / np.linalg.norm(axes[lit[0]])
    assert ok[0] and math.degrees(math.acos(min(1.0, float(v[0] @ a)))) < 0.3


def _mean_rays(domain, la, lb):
    (pa, xa, _), (pb, xb, _) = domain.eyes.facets("A"), domain.eyes.facets("B")
    oa, u, _ = lens_rays(pa, xa, la)
    ob, v, _ = lens_rays(pb, xb, lb)
    p, ok = triangulate_rays(oa, u, ob, v)
    rho = np.linalg.norm(p - np.asarray(domain.origin), axis=1)
    return np.clip(rho, domain.r_min, domain.r_max), ~ok


def test_on_the_honeybee_the_boundary_rays_beat_the_mean_rays(honeybee):
    d = Domain3D.for_eyes(honeybee)
    ds = generate3d(200, d, seed=11, mode="multi")
    la, lb = (ds.indptr_a, ds.indices_a), (ds.indptr_b, ds.indices_b)
    r_old, flag_old = _mean_rays(d, la, lb)
    r_new, _, _, flag_new = analytic3d.estimate(d, la, lb)
    rows = ~flag_old  # the rows the old rule answers: the same rows for both

    def mape(r):
        return float(np.mean(np.abs(r[rows] - ds.r[rows]) / ds.r[rows]))

    assert rows.sum() >= 80
    assert mape(r_new) < mape(r_old), (mape(r_new), mape(r_old))
    assert flag_new.mean() < 0.75 * flag_old.mean(), (flag_new.mean(), flag_old.mean())
