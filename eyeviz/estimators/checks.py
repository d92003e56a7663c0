"""The battery every estimator passes (in the spirit of scikit-learn's
``check_estimator`` / ``parametrize_with_checks``).

>>> from eyeviz import estimators
>>> from eyeviz.estimators.checks import check_estimator
>>> check_estimator(estimators.load("analytic"))      # raises AssertionError on a failure
['check_declares_domain', 'check_shapes_and_dtypes', ...]

For pytest, :func:`estimator_checks` yields ``(estimator, check)`` pairs to parametrize
over, so each check is its own test. Every check gets the estimator and small data of its
own domain (Algorithm 1, seeded) and raises AssertionError naming what is wrong.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator

import numpy as np

from eyeviz.core.domain import Domain

__all__ = ["check_estimator", "estimator_checks", "CHECKS"]

_N = 48
#: phi is compared as an angle, absolutely: 1e-6 rad is a few float32 steps at phi ~ 1.5
#: (networks computing in float32 may round differently in another batch) and far below
#: a sector (2 pi / m = 8.7e-3 rad at m = 720); r is compared relatively (rtol 1e-6).
PHI_ATOL = 1e-6


def _data(est):
    from eyeviz import dataset

    d = est.domain
    ds = dataset.generate(_N, d.eyes, d.r_min, d.r_max, d.g_max, "single", 7)
    return ds.omega_a.copy(), ds.omega_b.copy(), ds


def _same_r(x, y) -> bool:
    return bool(np.allclose(x, y, rtol=1e-6, atol=0.0, equal_nan=True))


def _same_phi(x, y) -> bool:
    return bool(np.allclose(x, y, rtol=0.0, atol=PHI_ATOL, equal_nan=True))


def check_declares_domain(est) -> None:
    """``name`` is a non-empty string; ``domain`` a Domain; ``metadata`` a dict."""
    assert isinstance(getattr(est, "name", None), str) and est.name, "estimator has no name"
    assert isinstance(est.domain, Domain), f"domain must be a Domain, got {type(est.domain)}"
    assert isinstance(est.metadata, dict), "metadata must be a dict"
    assert est.n_weights >= 0, "n_weights must be >= 0"


def check_shapes_and_dtypes(est) -> None:
    """(N,) float64 r and phi, bool masks of the same shape; a single row gives scalars."""
    a, b, _ = _data(est)
    p = est.predict(a, b)
    r, phi = p
    for name, v in (("r", r), ("phi", phi)):
        v = np.asarray(v)
        assert v.shape == (_N,), f"{name} has shape {v.shape}, expected ({_N},)"
        assert v.dtype == np.float64, f"{name} has dtype {v.dtype}, expected float64"
    for name in ("valid", "in_domain"):
        v = np.asarray(getattr(p, name))
        assert v.shape == (_N,) and v.dtype == bool, f"{name} must be bool of shape ({_N},)"
    one = est.predict(a[0], b[0])
    assert np.ndim(one.r) == 0 and np.ndim(one.phi) == 0, "a single row must give scalars"
    assert _same_r(one.r, r[0]), "a single row must give the same r as in a batch"
    assert _same_phi(one.phi, phi[0]), "a single row must give the same phi as in a batch"


def check_accepts_bool_and_int(est) -> None:
    """0/1 as bool, uint8, int64 and float give the same answer (r and phi)."""
    a, b, _ = _data(est)
    ref = est.predict(a, b)
    for dt in (np.uint8, np.int64, np.float64):
        p = est.predict(a.astype(dt), b.astype(dt))
        assert np.array_equal(p.r, ref.r, equal_nan=True), f"dtype {dt.__name__} changes r"
        assert np.array_equal(p.phi, ref.phi, equal_nan=True), f"dtype {dt.__name__} changes phi"


def check_rejects_wrong_m(est) -> None:
    """Rows of length != m/2 are refused with a message naming m/2."""
    a, b, _ = _data(est)
    w = est.domain.width
    for bad in (w + 1, w - 1):
        wa = np.zeros((3, bad), bool)
        try:
            est.predict(wa, wa)
        except ValueError as exc:
            assert "m/2" in str(exc), f"wrong-length message does not name m/2: {exc}"
        else:
            raise AssertionError(f"rows of length {bad} (m/2 = {w}) were accepted")


def check_rejects_bad_input(est) -> None:
    """Non-binary values, mismatched row counts and 3-D arrays are ValueErrors."""
    a, b, _ = _data(est)
    bad = a.astype(np.int64)
    bad[2, 5] = 2
    cases = {
        "a value 2": (bad, b),
        "mismatched rows": (a[:5], b[:4]),
        "a 3-D array": (a[None], b[None]),
        "text": (np.array([["x"] * a.shape[1]]), b[:1]),
    }
    for what, (x, y) in cases.items():
        try:
            est.predict(x, y)
        except ValueError as exc:
            assert str(exc) and "\n" not in str(exc), f"{what}: message must be one line"
        else:
            raise AssertionError(f"{what} was accepted")


def check_empty_input(est) -> None:
    """Zero rows give zero-length results, no error."""
    w = est.domain.width
    p = est.predict(np.zeros((0, w), bool), np.zeros((0, w), bool))
    assert np.shape(p.r) == (0,) and np.shape(p.phi) == (0,), "empty input must give (0,)"


def check_deterministic(est) -> None:
    """The same input twice gives the same output, and the input is not modified."""
    a, b, _ = _data(est)
    a0, b0 = a.copy(), b.copy()
    p1 = est.predict(a, b)
    p2 = est.predict(a, b)
    assert np.array_equal(p1.r, p2.r, equal_nan=True), "r differs between two calls"
    assert np.array_equal(p1.phi, p2.phi, equal_nan=True), "phi differs between two calls"
    assert np.array_equal(a, a0) and np.array_equal(b, b0), "predict modified its input"


def check_rows_independent(est) -> None:
    """A row's answer (r and phi) does not depend on the other rows (subset and reversed
    order)."""
    a, b, _ = _data(est)
    p = est.predict(a, b)
    q = est.predict(a[::-1], b[::-1])
    assert _same_r(q.r[::-1], p.r), "row order changes r"
    assert _same_phi(q.phi[::-1], p.phi), "row order changes phi"
    s = est.predict(a[5:9], b[5:9])
    assert _same_r(s.r, p.r[5:9]), "a subset changes r"
    assert _same_phi(s.phi, p.phi[5:9]), "a subset changes phi"


def check_masks(est) -> None:
    """Rows that are not one feature (nothing lit; two runs) are NaN with valid False;
    every valid row has finite r > 0 and finite phi (no NaN without the flag)."""
    a, b, _ = _data(est)
    a[0] = False
    a[1] = False
    a[1, 3] = a[1, 10] = True
    p = est.predict(a, b)
    assert not p.valid[0] and not p.valid[1], "rows that are not one feature must be invalid"
    assert np.isnan(p.r[:2]).all() and np.isnan(p.phi[:2]).all(), "invalid rows must be NaN"
    v = np.asarray(p.valid)
    assert v[2:].all(), "generated single-feature rows must be valid"
    assert np.isfinite(p.r[v]).all() and (p.r[v] > 0).all(), "valid rows need finite r > 0"
    assert np.isfinite(p.phi[v]).all(), "valid rows need a finite phi"
    assert not np.asarray(p.in_domain)[~v].any(), "invalid rows cannot be in the domain"


def check_sensible_answers(est) -> None:
    """On data of its own domain the median relative error of r is below 100 % and phi
    within 0.2 rad: a sanity floor, not a benchmark."""
    a, b, ds = _data(est)
    p = est.predict(a, b)
    rel = np.abs(p.r / ds.r - 1)
    assert np.median(rel) < 1.0, f"median relative r error {np.median(rel):.3g} >= 100 %"
    assert np.median(np.abs(p.phi - ds.phi)) < 0.2, "median phi error >= 0.2 rad"


def check_predict_intervals(est) -> None:
    """``predict_intervals`` on the intervals of the bitmaps answers like ``predict``."""
    from eyeviz.estimators.base import bitmaps_to_intervals

    a, b, _ = _data(est)
    LA, RA, LB, RB, ok = bitmaps_to_intervals(a, b, est.domain.width)
    p = est.predict(a, b)
    q = est.predict_intervals(LA[ok], RA[ok], LB[ok], RB[ok])
    assert _same_r(q.r, p.r[ok]), "predict_intervals disagrees with predict on r"
    assert _same_phi(q.phi, p.phi[ok]), "predict_intervals disagrees with predict on phi"


CHECKS: tuple[Callable, ...] = (
    check_declares_domain,
    check_shapes_and_dtypes,
    check_accepts_bool_and_int,
    check_rejects_wrong_m,
    check_rejects_bad_input,
    check_empty_input,
    check_deterministic,
    check_rows_independent,
    check_masks,
    check_sensible_answers,
    check_predict_intervals,
)


def _is_3d(est) -> bool:
    from eyeviz.core.domain import Domain3D

    return isinstance(getattr(est, "domain", None), Domain3D)


def estimator_checks(est) -> Iterator[tuple[object, Callable]]:
    """``(estimator, check)`` pairs, for ``pytest.mark.parametrize`` (the 3D battery of
    :mod:`eyeviz.estimators.checks3d` for an estimator of the spherical eyes)."""
    if _is_3d(est):
        from eyeviz.estimators.checks3d import estimator_checks3d

        yield from estimator_checks3d(est)
        return
    for check in CHECKS:
        yield est, check


def check_estimator(est) -> list[str]:
    """Run every check on ``est``; AssertionError naming the first failing check. An
    estimator whose domain is a Domain3D gets the 3D battery (:mod:`.checks3d`)."""
    if _is_3d(est):
        from eyeviz.estimators.checks3d import check_estimator3d

        return check_estimator3d(est)
    done = []
    for check in CHECKS:
        try:
            check(est)
        except AssertionError as exc:
            raise AssertionError(f"{est.name}: {check.__name__}: {exc}") from None
        done.append(check.__name__)
    return done
