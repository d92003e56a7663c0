"""The rays and triangulation every spherical-side estimator reads (estimators.triangulation):
the HEALPix answers identical to the code they were moved from, the measured rays and the
closest approach against independent computations, and the analytic estimator on a
measured pair."""

from __future__ import annotations

import numpy as np
import pytest

from eyeviz import EyevizError
from eyeviz.core.domain import Domain3D
from eyeviz.dataset.algorithm1_3d import generate3d
from eyeviz.estimators import analytic3d, learned3d_features, registry
from eyeviz.estimators.triangulation import (
    boundary_rays,
    cap_estimates,
    lens_rays,
    triangulate,
    triangulate_rays,
    triangulate_xyz,
)

# --- frozen copies of the code before the move (analytic3d.triangulate and
# learned3d_features.triangulate), to pin the moved functions bit for bit


def _old_analytic_triangulate(u, v, h):
    b = np.einsum("ij,ij->i", u, v)
    d = -2.0 * h * u[:, 0]
    e = -2.0 * h * v[:, 0]
    den = 1.0 - b * b
    with np.errstate(divide="ignore", invalid="ignore"):
        s = (b * e - d) / den
        t = (e - b * d) / den
    ok = (den > 1e-15) & (s > 0) & (t > 0) & np.isfinite(s) & np.isfinite(t)
    s = np.where(ok, s, np.nan)
    t = np.where(ok, t, np.nan)
    return 0.5 * (s[:, None] * u + t[:, None] * v), ok


def _old_features_triangulate(u, v, h):
    b = np.einsum("ij,ij->i", u, v)
    d = -2.0 * h * u[:, 0]
    e = -2.0 * h * v[:, 0]
    den = 1.0 - b * b
    with np.errstate(divide="ignore", invalid="ignore"):
        s = (b * e - d) / den
        t = (e - b * d) / den
    ok = (den > 1e-15) & (s > 0) & (t > 0) & np.isfinite(s) & np.isfinite(t)
    s = np.where(ok, s, 1.0)
    t = np.where(ok, t, 1.0)
    return (
        0.5 * (s * u[:, 0] + t * v[:, 0]),
        0.5 * (s * u[:, 1] + t * v[:, 1]),
        0.5 * (s * u[:, 2] + t * v[:, 2]),
        ok,
    )


def _unit(a):
    return a / np.linalg.norm(a, axis=1, keepdims=True)


def test_moved_triangulations_give_identical_healpix_answers():
    rng = np.random.default_rng(5)
    u = _unit(rng.normal(size=(2000, 3)) + [0.3, 2.0, 0.0])
    v = _unit(rng.normal(size=(2000, 3)) + [-0.3, 2.0, 0.0])
    v[:5] = u[:5]  # parallel rays: not triangulated
    p, ok = triangulate(u, v, 40.0)
    p0, ok0 = _old_analytic_triangulate(u, v, 40.0)
    assert np.array_equal(ok, ok0) and np.array_equal(p, p0, equal_nan=True)
    assert 0 < ok.sum() < ok.size and not ok[:5].any()
    got, want = triangulate_xyz(u, v, 40.0), _old_features_triangulate(u, v, 40.0)
    assert all(np.array_equal(a, b) for a, b in zip(got, want, strict=True))
    assert learned3d_features.triangulate is triangulate_xyz
    assert analytic3d.triangulate is triangulate and analytic3d.cap_estimates is cap_estimates


def test_analytic3d_healpix_answers_are_those_of_the_frozen_pipeline():
    """estimate() on HEALPix rows: the frozen triangulation on the same cap centres."""
    d = Domain3D(nside=8)
    ds = generate3d(200, d, seed=4)
    la, lb = (ds.indptr_a, ds.indices_a), (ds.indptr_b, ds.indices_b)
    r, az, el, flagged = analytic3d.estimate(d, la, lb)
    u, _ = cap_estimates(8, la)
    v, _ = cap_estimates(8, lb)
    p, ok = _old_analytic_triangulate(u, v, d.h)
    mean = _unit(u + v)
    p = np.where(ok[:, None], p, d.r_max * mean)
    rho = np.linalg.norm(p, axis=1)
    assert np.array_equal(flagged, ~ok)
    assert np.array_equal(r, np.clip(rho, d.r_min, d.r_max))
    # flagged rows answer r_max, as the docstring says (issue 37: not r_min)
    assert flagged.any() and np.allclose(r[flagged], d.r_max, rtol=1e-12)
    assert np.array_equal(az, np.arctan2(p[:, 1], p[:, 0]))
    assert np.array_equal(el, np.arcsin(np.clip(p[:, 2] / rho, -1.0, 1.0)))


def test_triangulate_rays_meets_a_known_point_from_any_origins():
    rng = np.random.default_rng(1)
    target = rng.uniform(-5, 5, (50, 3)) + [0, 30, 0]
    oa = rng.normal(0, 0.3, (50, 3)) + [-2, 0, 0]
    ob = rng.normal(0, 0.3, (50, 3)) + [2, 0, 0]
    p, ok = triangulate_rays(oa, _unit(target - oa), ob, _unit(target - ob))
    assert ok.all() and np.allclose(p, target, atol=1e-9)
    # skew rays: the midpoint of the common perpendicular, equidistant from both rays
    u, v = np.array([[1.0, 1.0, 0.0]]) / 2**0.5, np.array([[-1.0, 1.0, 0.0]]) / 2**0.5
    p, ok = triangulate_rays(np.array([-1.0, 0, -1]), u, np.array([1.0, 0, 1]), v)
    assert ok[0] and np.allclose(p[0], [0.0, 1.0, 0.0])
    _, ok = triangulate_rays(np.array([-1.0, 0, 0]), v, np.array([1.0, 0, 0]), u)
    assert not ok[0]  # they meet behind both origins


def test_lens_rays_are_the_lit_facets_mean_lens_and_mean_unit_axis():
    pos = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [5, 5, 5]])
    axes = np.array([[0.0, 2, 0], [0, 0, 3], [0, 1, 0], [1, 0, 0]])  # not unit
    ptr, idx = np.array([0, 2, 2, 4]), np.array([0, 1, 2, 3])
    origin, direction, count = lens_rays(pos, axes, (ptr, idx))
    assert count.tolist() == [2, 0, 2]
    assert np.allclose(origin[0], [0.5, 0, 0]) and np.allclose(origin[2], [2.5, 3, 2.5])
    assert np.allclose(direction[0], np.array([0, 1, 1]) / 2**0.5)
    assert np.allclose(direction[2], np.array([1, 1, 0]) / 2**0.5)
    assert np.isnan(origin[1]).all() and np.isnan(direction[1]).all()


def test_analytic3d_on_a_measured_pair_is_the_closest_approach_of_the_boundary_rays(toy_pair):
    d = Domain3D.for_eyes(toy_pair)
    ds = generate3d(30, d, seed=7)
    est = registry.load("analytic3d", domain=d)
    pred = est.predict_dataset(ds)
    assert pred.valid.all() and pred.in_domain.all()
    la, lb = (ds.indptr_a, ds.indices_a), (ds.indptr_b, ds.indices_b)
    oa, u, _ = boundary_rays(toy_pair.eye_a.positions, toy_pair.eye_a.axes, la)
    ob, v, _ = boundary_rays(toy_pair.eye_b.positions, toy_pair.eye_b.axes, lb)
    ok = ~np.asarray(pred.flagged)
    assert ok.sum() >= 10
    # where the rays meet: the midpoint of the closest approach, solved independently
    o = np.asarray(d.origin)
    for i in np.flatnonzero(ok):
        m = np.array([[u[i] @ u[i], -(u[i] @ v[i])], [u[i] @ v[i], -(v[i] @ v[i])]])
        s, t = np.linalg.solve(m, [(ob[i] - oa[i]) @ u[i], (ob[i] - oa[i]) @ v[i]])
        q = 0.5 * (oa[i] + s * u[i] + ob[i] + t * v[i]) - o
        rho = np.linalg.norm(q)
        assert np.isclose(pred.r[i], np.clip(rho, d.r_min, d.r_max), rtol=1e-9)
        assert np.isclose(pred.azimuth[i], np.arctan2(q[1], q[0]), atol=1e-9)
        assert np.isclose(pred.elevation[i], np.arcsin(q[2] / rho), atol=1e-9)
    # flagged rows answer r_max along the mean of the two axes
    # rays that diverge (eye A's outermost facets look left, eye B's right) are flagged
    # and answer r_max along the mean of the two axes
    la = np.argsort(toy_pair.eye_a.axes[:, 0])[:3]
    lb = np.argsort(-toy_pair.eye_b.axes[:, 0])[:3]
    far = est.predict((np.array([0, 3]), np.sort(la)), (np.array([0, 3]), np.sort(lb)))
    assert far.flagged[0] and np.isclose(far.r[0], d.r_max, rtol=1e-12)
    ra, rb = (np.array([0, 3]), np.sort(la)), (np.array([0, 3]), np.sort(lb))
    _, u1, _ = boundary_rays(toy_pair.eye_a.positions, toy_pair.eye_a.axes, ra)
    _, v1, _ = boundary_rays(toy_pair.eye_b.positions, toy_pair.eye_b.axes, rb)
    mean = (u1 + v1)[0] / np.linalg.norm((u1 + v1)[0])
    assert np.isclose(far.azimuth[0], np.arctan2(mean[1], mean[0]))
    # the toy's field is wide and its facets coarse: the triangulation still finds the
    # ball's direction to a few degrees where the rays meet
    assert np.median(np.abs(pred.azimuth[ok] - ds.azimuth[ok])) < 0.1


def test_rows_with_an_unlit_eye_are_not_answered(toy_pair):
    est = registry.load("analytic3d", domain=Domain3D.for_eyes(toy_pair))
    na, nb = toy_pair.facet_counts
    p = est.predict((np.array([0, 2, 2]), np.array([0, 1])), (np.array([0, 2, 4]), [0, 1, 2, 3]))
    assert p.valid.tolist() == [True, False] and np.isnan(p.r[1])
    assert p.in_domain.tolist() == [True, False]
    with pytest.raises(ValueError, match=f"lit_a: indices must lie in \\[0, npix = {na}\\)"):
        est.predict((np.array([0, 1]), np.array([na])), (np.array([0, 1]), np.array([0])))


@pytest.mark.parametrize("name", ["learned3d"])
def test_healpix_only_estimators_refuse_a_measured_domain_in_one_line(toy_pair, name):
    with pytest.raises(EyevizError) as info:
        registry.load(name, domain=Domain3D.for_eyes(toy_pair))
    text = str(info.value)
    assert "\n" not in text and "answers for spherical eyes only, not measured" in text
    assert text.endswith("use analytic3d, limit3d")
    assert registry.available_for("measured") == ["analytic3d", "limit3d"]
    assert set(registry.available_for("spherical")) >= {"analytic3d", "limit3d", "learned3d"}
