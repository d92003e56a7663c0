"""The battery every estimator of the spherical eyes passes (the 3D form of
:mod:`eyeviz.estimators.checks`; :func:`eyeviz.estimators.checks.check_estimator` runs it
for an estimator whose domain is a :class:`~eyeviz.core.domain.Domain3D`).

Each check gets the estimator and a few rows of its own domain's 3D Algorithm 1
(seeded) and raises AssertionError naming what is wrong. The lit sets are given both as
CSR rows (the data set's form) and as dense bitmaps.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator

import numpy as np

from eyeviz.core.domain import Domain3D

__all__ = ["CHECKS3D", "check_estimator3d", "estimator_checks3d"]

_N = 12
#: angles are compared absolutely (float32 networks may round differently by batch)
ANGLE_ATOL = 1e-6


def _data(est):
    from eyeviz.dataset.algorithm1_3d import generate3d

    ds = generate3d(_N, est.domain, "single", 7)
    return (ds.indptr_a, ds.indices_a), (ds.indptr_b, ds.indices_b), ds


def _rows(lit, rows):
    from eyeviz.estimators.base3d import take_rows

    return take_rows(lit[0], lit[1], np.asarray(rows))


def _same(p, q) -> bool:
    return bool(
        np.allclose(p[0], q[0], rtol=1e-6, atol=0.0, equal_nan=True)
        and np.allclose(p[1], q[1], rtol=0.0, atol=ANGLE_ATOL, equal_nan=True)
        and np.allclose(p[2], q[2], rtol=0.0, atol=ANGLE_ATOL, equal_nan=True)
    )


def check_declares_domain3d(est) -> None:
    """``name`` a non-empty string; ``domain`` a Domain3D; ``metadata`` a dict."""
    assert isinstance(getattr(est, "name", None), str) and est.name, "estimator has no name"
    assert isinstance(est.domain, Domain3D), f"domain must be a Domain3D, got {type(est.domain)}"
    assert isinstance(getattr(est, "metadata", None), dict), "metadata must be a dict"


def check_shapes_and_dtypes3d(est) -> None:
    """(N,) float64 r, azimuth, elevation and bool valid/in_domain/flagged; one dense
    bitmap row gives scalars equal to the batch's row."""
    a, b, ds = _data(est)
    p = est.predict(a, b)
    for name, v in zip(("r", "azimuth", "elevation"), p, strict=True):
        v = np.asarray(v)
        assert v.shape == (_N,), f"{name} has shape {v.shape}, expected ({_N},)"
        assert v.dtype == np.float64, f"{name} has dtype {v.dtype}, expected float64"
    for name in ("valid", "in_domain", "flagged"):
        v = np.asarray(getattr(p, name))
        assert v.shape == (_N,) and v.dtype == bool, f"{name} must be bool of shape ({_N},)"
    ba, bb = ds.bitmaps(0, 1)
    one = est.predict(ba[0], bb[0])
    assert np.ndim(one.r) == 0 and np.ndim(one.elevation) == 0, "one row must give scalars"
    assert _same(tuple(np.atleast_1d(v) for v in one), tuple(v[:1] for v in p)), (
        "one bitmap row must answer as in the batch"
    )


def check_csr_equals_bitmaps(est) -> None:
    """CSR rows and the same lit sets as dense bitmaps (bool or 0/1 integers) agree."""
    a, b, ds = _data(est)
    p = est.predict(a, b)
    ba, bb = ds.bitmaps()
    assert _same(est.predict(ba, bb), p), "bitmaps and CSR rows disagree"
    assert _same(est.predict(ba.astype(np.uint8), bb.astype(np.uint8)), p), "uint8 differs"


def check_rejects_bad_input3d(est) -> None:
    """Wrong npix, non-binary values, mismatched rows, bad CSR: one-line ValueErrors."""
    a, b, ds = _data(est)
    npix = est.domain.facet_counts[0]  # eye A's (a measured pair's eyes may differ)
    ba, bb = ds.bitmaps(0, 3)
    two = ba.astype(np.int64)
    two[1, 0] = 2
    cases = {
        "wrong npix": (np.zeros((3, npix + 1), bool), bb),
        "a value 2": (two, bb),
        "mismatched rows": (ba[:2], bb),
        "index out of range": ((np.array([0, 1]), np.array([npix])), _rows(b, [0])),
        "decreasing indices": ((np.array([0, 2]), np.array([9, 4])), _rows(b, [0])),
        "a 3-tuple": ((a[0], a[1], a[1]), b),
    }
    for what, (x, y) in cases.items():
        try:
            est.predict(x, y)
        except ValueError as exc:
            assert str(exc) and "\n" not in str(exc), f"{what}: message must be one line"
        else:
            raise AssertionError(f"{what} was accepted")


def check_empty_input3d(est) -> None:
    """Zero rows give zero-length results, no error."""
    e = (np.zeros(1, np.int64), np.zeros(0, np.int64))
    p = est.predict(e, e)
    assert all(np.shape(v) == (0,) for v in p), "empty input must give (0,)"


def check_deterministic3d(est) -> None:
    """The same input twice gives the same output; the input is not modified."""
    a, b, _ = _data(est)
    a0 = (a[0].copy(), a[1].copy())
    p1 = est.predict(a, b)
    p2 = est.predict(a, b)
    for x, y in zip(p1, p2, strict=True):
        assert np.array_equal(x, y, equal_nan=True), "two calls differ"
    assert np.array_equal(a[0], a0[0]) and np.array_equal(a[1], a0[1]), "input modified"


def check_rows_independent3d(est) -> None:
    """A row's answer does not depend on the other rows (reversed order, subset)."""
    a, b, _ = _data(est)
    p = est.predict(a, b)
    rev = np.arange(_N)[::-1]
    q = est.predict(_rows(a, rev), _rows(b, rev))
    assert _same(tuple(v[::-1] for v in q), p), "row order changes the answers"
    sub = np.array([5, 2, 8])
    s = est.predict(_rows(a, sub), _rows(b, sub))
    assert _same(s, tuple(v[sub] for v in p)), "a subset changes the answers"


def check_masks3d(est) -> None:
    """A row where an eye lit nothing is NaN, not valid, not in the domain, not flagged;
    every other generated row is valid with finite r > 0 and finite angles."""
    a, b, ds = _data(est)
    ba, bb = ds.bitmaps()
    ba[0] = False
    p = est.predict(ba, bb)
    assert not p.valid[0] and np.isnan(p.r[0]) and np.isnan(p.elevation[0]), "row 0: NaN"
    assert not p.in_domain[0] and not p.flagged[0], "an invalid row is neither"
    v = np.asarray(p.valid)
    assert v[1:].all(), "generated rows must be valid"
    assert np.isfinite(p.r[1:]).all() and (p.r[1:] > 0).all(), "valid rows need r > 0"
    assert np.isfinite(p.azimuth[1:]).all() and np.isfinite(p.elevation[1:]).all()


def check_sensible_answers3d(est) -> None:
    """On rows of its own domain: median relative r error < 100 %, azimuth and elevation
    within 0.2 rad (a sanity floor, not a benchmark)."""
    a, b, ds = _data(est)
    p = est.predict(a, b)
    assert np.median(np.abs(p.r / ds.r - 1)) < 1.0, "median relative r error >= 100 %"
    assert np.median(np.abs(p.azimuth - ds.azimuth)) < 0.2, "median azimuth error >= 0.2"
    assert np.median(np.abs(p.elevation - ds.elevation)) < 0.2, "median elevation error >= 0.2"


CHECKS3D: tuple[Callable, ...] = (
    check_declares_domain3d,
    check_shapes_and_dtypes3d,
    check_csr_equals_bitmaps,
    check_rejects_bad_input3d,
    check_empty_input3d,
    check_deterministic3d,
    check_rows_independent3d,
    check_masks3d,
    check_sensible_answers3d,
)


def estimator_checks3d(est) -> Iterator[tuple[object, Callable]]:
    """``(estimator, check)`` pairs, for ``pytest.mark.parametrize``."""
    for check in CHECKS3D:
        yield est, check


def check_estimator3d(est) -> list[str]:
    """Run every 3D check on ``est``; AssertionError naming the first failing check."""
    done = []
    for check in CHECKS3D:
        try:
            check(est)
        except AssertionError as exc:
            raise AssertionError(f"{est.name}: {check.__name__}: {exc}") from None
        done.append(check.__name__)
    return done
