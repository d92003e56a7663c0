"""The check battery over every registered estimator that can load here, and proof that
the battery catches broken estimators."""

from __future__ import annotations

import numpy as np
import pytest

from eyeviz import EyevizError, estimators
from eyeviz.estimators import checks, registry
from eyeviz.estimators.analytic import AnalyticEstimator

SMALL = estimators.Domain(h=10, l=5, m=180, r_min=200, r_max=1000, g_max=100)


def _loadable():
    out = []
    for e in registry.entries():
        kw = {"domain": SMALL} if e.any_design else {}
        try:
            est = e.load_estimator(**kw)
        except (ValueError, OSError) as exc:  # weights missing here: checked below
            out.append(pytest.param(e.name, None, marks=pytest.mark.skip(reason=str(exc))))
            continue
        out.append(pytest.param(e.name, est, id=e.name))
        if e.any_design:
            out.append(pytest.param(e.name, e.load_estimator(), id=f"{e.name}-paper-domain"))
    return out


_CASES = [
    pytest.param(est, check, id=f"{id_}-{check.__name__}")
    for p in _loadable()
    if p.values[1] is not None
    for id_, est in [(p.id or p.values[0], p.values[1])]
    for check in checks.CHECKS
]


@pytest.mark.parametrize("est, check", _CASES)
def test_registered_estimator_passes(est, check):
    check(est)


def test_every_shipped_estimator_is_checked():
    names = {c.values[0].name for c in _CASES}
    assert {"analytic", "bayes", "compact"} <= names


def test_paper_entry_says_weights_missing(tmp_path, monkeypatch):
    monkeypatch.setenv("EYEVIZ_PAPER_DIR", str(tmp_path))
    with pytest.raises(EyevizError) as info:
        estimators.load("paper")
    msg = str(info.value)
    assert "not found" in msg and "eyeviz train paper" in msg and "\n" not in msg


def test_check_estimator_returns_every_check_name():
    done = checks.check_estimator(estimators.load("analytic"))
    assert done == [c.__name__ for c in checks.CHECKS]


class _Float32(AnalyticEstimator):
    name = "float32"

    def predict(self, a, b):
        p = super().predict(a, b)
        return type(p)(np.asarray(p.r, np.float32), p.phi, p.valid, p.in_domain)


class _NoMask(AnalyticEstimator):
    name = "nomask"

    def predict(self, a, b):
        p = super().predict(a, b)
        return type(p)(np.nan_to_num(p.r, nan=1.0), p.phi, p.valid, p.in_domain)


class _Noisy(AnalyticEstimator):
    name = "noisy"

    def _predict_intervals(self, LA, RA, LB, RB):
        r, phi = super()._predict_intervals(LA, RA, LB, RB)
        return r * np.random.default_rng().uniform(0.9, 1.1, r.shape), phi


class _AcceptsAnything(AnalyticEstimator):
    name = "lenient"

    def predict(self, a, b):
        a = np.asarray(a)
        if a.ndim == 2 and a.shape[1] != self.domain.width:
            a = np.zeros((a.shape[0], self.domain.width), bool)
            return super().predict(a, a)
        return super().predict(a, b)


class _NoDomain(AnalyticEstimator):
    name = "nodomain"

    def __init__(self):
        super().__init__()
        self.domain = {"m": 720}


@pytest.mark.parametrize(
    "broken, failing",
    [
        (_Float32(), "check_shapes_and_dtypes"),
        (_NoMask(), "check_masks"),
        (_Noisy(), "check_deterministic"),
        (_AcceptsAnything(), "check_rejects_wrong_m"),
        (_NoDomain(), "check_declares_domain"),
    ],
)
def test_battery_catches_broken_estimators(broken, failing):
    with pytest.raises(AssertionError):
        getattr(checks, failing)(broken)
    with pytest.raises(AssertionError, match=f"{broken.name}: check_"):
        checks.check_estimator(broken)


# --- phi slips (issue 20 item 7): the battery compares phi wherever it compares r -------
class _PhiSlipInIntervals(AnalyticEstimator):
    """predict_intervals answers phi + 0.01 rad (about one sector at m = 720)."""

    name = "phislip-intervals"

    def predict_intervals(self, LA, RA, LB, RB):
        p = super().predict_intervals(LA, RA, LB, RB)
        return type(p)(p.r, p.phi + 0.01, p.valid, p.in_domain)


class _MirroredPhiForIntegers(AnalyticEstimator):
    """Integer bitmaps get the azimuth of the mirrored side, pi - phi."""

    name = "phimirror-int"

    def predict(self, a, b):
        p = super().predict(a, b)
        if np.asarray(a).dtype != bool:
            return type(p)(p.r, np.pi - p.phi, p.valid, p.in_domain)
        return p


class _PhiSlipInBigBatches(AnalyticEstimator):
    """A 'fast path' for batches over 8 rows adds 0.01 rad to phi."""

    name = "phislip-batch"

    def _predict_intervals(self, LA, RA, LB, RB):
        r, phi = super()._predict_intervals(LA, RA, LB, RB)
        return r, phi + (0.01 if len(LA) > 8 else 0.0)


class _MirroredPhi(AnalyticEstimator):
    """Every path answers the azimuth of the mirrored side, pi - phi."""

    name = "phimirror"

    def _predict_intervals(self, LA, RA, LB, RB):
        r, phi = super()._predict_intervals(LA, RA, LB, RB)
        return r, np.pi - phi


@pytest.mark.parametrize(
    "broken, failing",
    [
        (_PhiSlipInIntervals(), "check_predict_intervals"),
        (_MirroredPhiForIntegers(), "check_accepts_bool_and_int"),
        (_PhiSlipInBigBatches(), "check_rows_independent"),
        (_PhiSlipInBigBatches(), "check_shapes_and_dtypes"),
        (_MirroredPhi(), "check_sensible_answers"),
    ],
)
def test_battery_catches_a_phi_slip(broken, failing):
    with pytest.raises(AssertionError, match="phi"):
        getattr(checks, failing)(broken)
    with pytest.raises(AssertionError, match=f"{broken.name}: check_.*phi"):
        checks.check_estimator(broken)


def test_phi_tolerance_is_an_angle_far_below_a_sector():
    """Float32 rounding of phi ~ 1.5 passes; a hundredth of a sector at m = 2880 fails."""
    phi = np.linspace(0.1, 3.0, 7)
    assert checks._same_phi(phi.astype(np.float32).astype(np.float64), phi)
    assert not checks._same_phi(phi + 0.01 * 2 * np.pi / 2880, phi)
    assert checks._same_phi(np.array([np.nan, 1.0]), np.array([np.nan, 1.0]))
    assert not checks._same_phi(np.array([np.nan, 1.0]), np.array([1.0, 1.0]))


class _DropsARow(AnalyticEstimator):
    """Calls the third row of every batch invalid (NaN, out of the domain)."""

    name = "dropsarow"

    def predict(self, a, b):
        p = super().predict(a, b)
        r, phi, v, dom = (np.array(x) for x in (p.r, p.phi, p.valid, p.in_domain))
        if v.size > 2:
            r[2], phi[2], v[2], dom[2] = np.nan, np.nan, False, False
        return type(p)(r, phi, v, dom)


def test_battery_catches_a_valid_row_called_invalid():
    with pytest.raises(AssertionError, match="must be valid"):
        checks.check_masks(_DropsARow())
