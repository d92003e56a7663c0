"""The 3D estimator protocol (base.Estimator3D) and the analytic triangulation of the
spherical eyes."""

from __future__ import annotations

import math

import numpy as np
import pytest

from eyeviz import EyevizError
from eyeviz.core.domain import Domain, Domain3D
from eyeviz.dataset.algorithm1_3d import generate3d
from eyeviz.estimators import registry
from eyeviz.estimators.analytic3d import Analytic3DEstimator, triangulate
from eyeviz.estimators.base import Prediction3D, as_csr
from eyeviz.estimators.metrics import mape

D16 = Domain3D(nside=16)


@pytest.fixture(scope="module")
def ds16():
    return generate3d(300, D16, seed=11)


def test_registry_kinds_and_domain_type():
    assert registry.available() == registry.available("planar")
    assert "analytic3d" not in registry.available()
    assert "analytic3d" in registry.available("spherical")
    assert set(registry.available(None)) >= {"analytic", "analytic3d"}
    est = registry.load("analytic3d", domain=D16)
    assert isinstance(est, Analytic3DEstimator) and est.domain == D16
    with pytest.raises(EyevizError, match="domain must be a Domain3D, got Domain"):
        registry.load("analytic3d", domain=Domain())
    with pytest.raises(EyevizError, match="use analytic3d"):
        registry.load("analytic", domain=D16)
    with pytest.raises(EyevizError, match="kind must be one of"):
        registry.available("cubic")


def test_triangulate_exact_point():
    h = 40.0
    p = np.array([[100.0, 2000.0, 300.0], [-50.0, 1200.0, -400.0]])
    u = p - [-h, 0, 0]
    v = p - [h, 0, 0]
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    v /= np.linalg.norm(v, axis=1, keepdims=True)
    q, ok = triangulate(u, v, h)
    assert ok.all()
    assert np.allclose(q, p, rtol=1e-9)
    # diverging rays (B looks further left than A): not in front of both eyes
    q2, ok2 = triangulate(v[:1], u[:1], h)
    assert not ok2[0] and np.isnan(q2).all()


def test_analytic_accuracy_and_conventions(ds16):
    est = Analytic3DEstimator(D16)
    p = est.predict_dataset(ds16)
    assert isinstance(p, Prediction3D)
    assert p.valid.all() and p.in_domain.all()
    ok = ~p.flagged
    assert ok.mean() > 0.8
    # azimuth and elevation in the data set's convention (atan2(y, x), asin(z / r))
    assert np.median(np.abs(p.azimuth[ok] - ds16.azimuth[ok])) < D16.gamma / 4
    assert np.median(np.abs(p.elevation[ok] - ds16.elevation[ok])) < D16.gamma / 4
    assert mape(ds16.r, p.r) < 40.0
    assert np.all((p.r >= D16.r_min) & (p.r <= D16.r_max))


def test_csr_and_bitmaps_agree(ds16):
    est = Analytic3DEstimator(D16)
    a, b = ds16.bitmaps(0, 40)
    p1 = est.predict(a, b)
    p2 = est.predict((ds16.indptr_a[:41], ds16.indices_a[: ds16.indptr_a[40]]),
                     (ds16.indptr_b[:41], ds16.indices_b[: ds16.indptr_b[40]]))  # fmt: skip
    for x, y in zip(p1, p2, strict=True):
        assert np.array_equal(x, y, equal_nan=True)
    one = est.predict(a[3], b[3])
    assert np.ndim(one.r) == 0 and math.isclose(one.r, p1.r[3])


def test_invalid_rows_and_errors(ds16):
    est = Analytic3DEstimator(D16)
    a, b = ds16.bitmaps(0, 4)
    a[1] = False
    p = est.predict(a, b)
    assert list(p.valid) == [True, False, True, True]
    assert np.isnan(p.r[1]) and not p.flagged[1] and not p.in_domain[1]
    assert np.isfinite(p.r[[0, 2, 3]]).all()
    npix = D16.npix
    with pytest.raises(ValueError, match="lit_a must be .* npix = 3072"):
        est.predict(np.zeros((2, 5), bool), b[:2])
    with pytest.raises(ValueError, match="different row counts"):
        est.predict(a[:2], b[:3])
    with pytest.raises(ValueError, match="lit_b bitmaps must hold 0/1"):
        est.predict(a, b * 2)
    with pytest.raises(ValueError, match=r"indices must lie in \[0, npix"):
        as_csr("lit_a", (np.array([0, 1]), np.array([npix])), npix)
    with pytest.raises(ValueError, match="increase strictly"):
        as_csr("lit_a", (np.array([0, 2]), np.array([5, 5])), npix)
    with pytest.raises(ValueError, match="indptr must start at 0"):
        as_csr("lit_a", (np.array([1, 2]), np.array([5])), npix)
    # a new row may start below the previous row's end
    ptr, ind, _ = as_csr("lit_a", (np.array([0, 2, 3]), np.array([5, 9, 1])), npix)
    assert ind.tolist() == [5, 9, 1]
    with pytest.raises(ValueError, match="Dataset3D"):
        est.predict_dataset(object())
    empty = est.predict((np.zeros(1, np.int64), np.zeros(0, np.int64)),
                        (np.zeros(1, np.int64), np.zeros(0, np.int64)))  # fmt: skip
    assert empty.r.shape == (0,)


def test_the_report_counts_no_weights_for_the_analytic_estimator(ds16):
    """`eyeviz report estimators` prints each estimator's weight count (measure_lit): the
    analytic estimator has none (a closed form, nothing trained)."""
    from eyeviz.reports.estimators import measure_lit

    (res,) = measure_lit(ds16, ["analytic3d"], limit_rows=20)
    assert res.n_weights == 0
    assert Analytic3DEstimator(D16).metadata["train_seconds"] == 0.0


def test_measured_rows_answer_their_direction_and_flagged_ones_r_max_along_the_mean_ray(
    toy_pair,
):
    """A measured pair: rows of its own data set are answered in their direction (about
    the domain's origin, to within a few facets); lit sets whose rays diverge (eye A's
    leftmost facets, eye B's rightmost) are flagged and answered at r_max along the
    mean of the two fitted rays, as estimate_measured's docstring says."""
    from eyeviz.estimators.triangulation import boundary_rays, facet_neighbours

    dom = Domain3D.for_eyes(toy_pair)
    ds = generate3d(20, dom, seed=3)
    est = Analytic3DEstimator(dom)
    p = est.predict((ds.indptr_a, ds.indices_a), (ds.indptr_b, ds.indices_b))
    d = np.c_[ds.x, ds.y, ds.z] - np.asarray(dom.origin)
    d /= np.linalg.norm(d, axis=1)[:, None]
    az, el = np.asarray(p[1]), np.asarray(p[2])
    d_hat = np.c_[np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)]
    err = np.arccos(np.clip((d * d_hat).sum(axis=1), -1, 1))
    assert np.ptp(ds.azimuth) > 0.5 and np.median(err) < 0.15
    pos_a, ax_a, _ = toy_pair.facets("A")
    pos_b, ax_b, _ = toy_pair.facets("B")
    ua, ub = (
        ax_a / np.linalg.norm(ax_a, axis=1)[:, None],
        ax_b / np.linalg.norm(ax_b, axis=1)[:, None],
    )
    lit_a = [np.flatnonzero((ua[:, 0] < -0.6) & (np.abs(ua[:, 2]) < 0.3))]
    lit_b = [np.flatnonzero((ub[:, 0] > 0.6) & (ub[:, 2] > 0.3))]
    assert lit_a[0].size >= 3 and lit_b[0].size >= 3
    ca = (np.array([0, lit_a[0].size]), lit_a[0])
    cb = (np.array([0, lit_b[0].size]), lit_b[0])
    q = est.predict(ca, cb)
    assert bool(q.flagged[0]) and float(q[0][0]) == dom.r_max
    _, u, _ = boundary_rays(pos_a, ax_a, ca, facet_neighbours(ax_a))
    _, v, _ = boundary_rays(pos_b, ax_b, cb, facet_neighbours(ax_b))
    m = (u + v)[0] / np.linalg.norm((u + v)[0])
    assert float(q[1][0]) == pytest.approx(math.atan2(m[1], m[0]), abs=1e-12)
    assert float(q[2][0]) == pytest.approx(math.asin(m[2]), abs=1e-12)
