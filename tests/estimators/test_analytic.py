"""Analytic triangulation: exact on noiseless geometry, far better than a constant."""

import math

import numpy as np
import pytest

from eyeviz import estimators
from eyeviz.core.geometry import EyePair
from eyeviz.estimators.base import triangulate


def test_triangulate_recovers_a_point():
    h = 40.0
    x, y = 300.0, 2000.0
    ta = math.atan2(y, x + h)
    tb = math.atan2(y, x - h)
    r, phi = triangulate(ta, tb, h)
    assert r == np.float64(np.hypot(x, y)) or abs(r - np.hypot(x, y)) < 1e-9
    assert abs(phi - math.atan2(y, x)) < 1e-12


def test_analytic_beats_constant_by_far():
    rng = np.random.default_rng(5)
    n = 5000
    r = rng.uniform(1000, 5000, n)
    phi = rng.uniform(np.pi / 6 + 0.1, 5 * np.pi / 6 - 0.1, n)
    g = rng.uniform(30, 400, n)
    ivs = EyePair().intervals(r * np.cos(phi), r * np.sin(phi), g)
    p = estimators.load("analytic").predict_intervals(*ivs)
    assert p.valid.all()
    mape_r = np.mean(np.abs(p.r - r) / r)
    mape_phi = np.mean(np.abs(p.phi - phi) / phi)
    const_r = np.mean(np.abs(np.median(r) - r) / r)
    const_phi = np.mean(np.abs(np.median(phi) - phi) / phi)
    assert mape_r < 0.3 * const_r
    assert mape_phi < 0.01 * const_phi
    assert mape_phi < 0.002 and mape_r < 0.15


@pytest.mark.parametrize("md", [0.25, 1.0])
def test_parallel_centre_rays_meet_at_the_disparity_floor(md):
    """Equal intervals in both eyes (zero disparity): the rays are raised to a disparity of
    ``min_disparity`` sectors; r then follows from the law of sines in triangle A B P."""
    m, h = 720, 40.0
    est = estimators.load("analytic", min_disparity=md)
    L, R = 170, 175
    p = est.predict_intervals(L, R, L, R)
    gam = 2 * np.pi / m
    ta = (L + R + 1) * gam / 2
    d = md * gam
    ra = 2 * h * np.sin(ta + d) / np.sin(d)
    x, y = -h + ra * np.cos(ta), ra * np.sin(ta)
    assert p.valid and p.r == pytest.approx(np.hypot(x, y), rel=1e-9)
    assert p.phi == pytest.approx(np.arctan2(y, x), abs=1e-12)
