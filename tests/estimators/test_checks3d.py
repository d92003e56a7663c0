"""The check battery of the eyes in space (checks.SPACE): the spherical estimators pass
it, broken ones fail it."""

from __future__ import annotations

import numpy as np
import pytest

from eyeviz.core.domain import Domain3D
from eyeviz.estimators import registry
from eyeviz.estimators.analytic3d import Analytic3DEstimator
from eyeviz.estimators.checks import check_estimator, estimator_checks
from eyeviz.estimators.limit3d import Limit3DEstimator

D16 = Domain3D(nside=16)


@pytest.mark.parametrize(
    ("est", "check"),
    list(estimator_checks(Analytic3DEstimator(D16)))
    + list(estimator_checks(Limit3DEstimator(D16, samples=32))),
    ids=lambda v: getattr(v, "__name__", getattr(v, "name", str(v))),
)
def test_battery(est, check):
    check(est)


def test_learned3d_passes_at_its_design():
    if "learned3d" not in registry.available("spherical"):
        pytest.skip("learned3d is not registered")
    est = registry.load("learned3d")
    assert "check_masks" in check_estimator(est)


class _OrderDependent(Analytic3DEstimator):
    name = "order_dependent"

    def _predict_csr(self, lit_a, lit_b):
        r, az, el, fl = super()._predict_csr(lit_a, lit_b)
        return r * (1 + 1e-3 * np.arange(r.size)), az, el, fl


class _ElevationSlip(Analytic3DEstimator):
    name = "elevation_slip"

    def _predict_csr(self, lit_a, lit_b):
        r, az, el, fl = super()._predict_csr(lit_a, lit_b)
        return r, az, el + 0.3, fl


@pytest.mark.parametrize(
    ("bad", "which"),
    [(_OrderDependent, "check_rows_independent"), (_ElevationSlip, "check_sensible_answers")],
)
def test_broken_estimators_fail(bad, which):
    with pytest.raises(AssertionError, match=which):
        check_estimator(bad(D16))


def test_the_analytic_estimator_on_a_measured_pair_passes_the_battery(toy_pair):
    """One battery for every model on the spherical side: the measured pair's analytic
    estimator passes the checks the HEALPix estimators pass."""
    est = registry.load("analytic3d", domain=Domain3D.for_eyes(toy_pair))
    done = check_estimator(est)
    assert "check_rejects_bad_input" in done and "check_sensible_answers" in done


def test_one_runner_has_a_battery_for_every_kind_of_domain():
    from eyeviz.core.domain import RECORDS
    from eyeviz.estimators import checks

    assert set(checks.BATTERIES) == set(RECORDS)
    assert checks.BATTERIES["measured"] is checks.BATTERIES["spherical"] is checks.SPACE
    est = Analytic3DEstimator(D16)
    assert [c for _, c in estimator_checks(est)] == list(checks.CHECKS3D)
    est.domain = {"nside": 16}  # not a domain: the runner stops at the declaration
    with pytest.raises(AssertionError, match="^analytic3d: check_declares_domain: domain must"):
        check_estimator(est)
