"""The battery every estimator passes, one runner for every eye model (in the spirit of
scikit-learn's ``check_estimator`` / ``parametrize_with_checks``).

>>> from eyeviz import estimators
>>> from eyeviz.estimators.checks import check_estimator
>>> check_estimator(estimators.load("analytic"))      # raises AssertionError on a failure
['check_declares_domain', 'check_shapes_and_dtypes', ...]

For pytest, :func:`estimator_checks` yields ``(estimator, check)`` pairs to parametrize
over, so each check is its own test. Every check gets the estimator and small data of its
own domain (Algorithm 1, seeded) and raises AssertionError naming what is wrong.

The estimator's domain names its eye model (``domain.kind``) and :data:`BATTERIES` the
:class:`Battery` for it. The checks every model's estimators pass (the declared domain,
shapes and dtypes, bad input refused in one line, empty input, determinism, rows that do
not depend on each other, the masks, sensible answers) are written once; what differs by
model is data of its battery: the answer's coordinates and masks, a few rows of its own
Algorithm 1, how rows are taken, what bad input and a row that is not one feature look
like. A battery adds the checks of its model's own inputs: the planar eyes' half bitmaps
of m/2 and their intervals (Prop. 2); for the eyes in space (HEALPix and measured, the
same battery) the lit sets as CSR rows and as dense bitmaps.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from dataclasses import dataclass
from typing import Any

import numpy as np

from eyeviz.core.domain import RECORDS

__all__ = ["BATTERIES", "CHECKS", "CHECKS3D", "Battery", "check_estimator", "estimator_checks"]

#: phi is compared as an angle, absolutely: 1e-6 rad is a few float32 steps at phi ~ 1.5
#: (networks computing in float32 may round differently in another batch) and far below
#: a sector (2 pi / m = 8.7e-3 rad at m = 720); r is compared relatively (rtol 1e-6).
PHI_ATOL = 1e-6
#: the same absolute tolerance for the azimuth and elevation of the eyes in space
ANGLE_ATOL = PHI_ATOL


@dataclass(frozen=True)
class Battery:
    """What the checks need to know of one eye model's estimators."""

    #: the answer's coordinates, r first (``Prediction`` iterates over them)
    coords: tuple[str, ...]
    #: the answer's boolean masks, ``valid`` first
    masks: tuple[str, ...]
    #: rows of the data (:attr:`data`) and the rows of the subset of check_rows_independent
    n: int
    subset: tuple[int, ...]
    #: ``data(est) -> (a, b, ds)``: a few rows of the domain's Algorithm 1 (seeded): each
    #: eye's input as the estimator takes it, and the rows themselves (the truth)
    data: Callable[[Any], tuple[Any, Any, Any]]
    #: ``take(x, rows)``: the given rows of one eye's input
    take: Callable[[Any, np.ndarray], Any]
    #: ``first(a, b, ds) -> (x, y)``: the first row as one row (not a batch of one)
    first: Callable[[Any, Any, Any], tuple[Any, Any]]
    #: ``empty(est)``: one eye's input of zero rows
    empty: Callable[[Any], Any]
    #: ``bad_inputs(est, a, b, ds) -> {what: (x, y)}``: inputs to refuse in one line
    bad_inputs: Callable[[Any, Any, Any, Any], dict[str, tuple[Any, Any]]]
    #: ``not_one_feature(a, b, ds) -> (x, y, rows)``: the data with ``rows`` made into
    #: rows that are not one feature (the rest untouched)
    not_one_feature: Callable[[Any, Any, Any], tuple[Any, Any, list[int]]]
    #: the checks run, in order: the shared ones and the model's own
    checks: tuple[Callable[[Any], None], ...] = ()


def _battery(est) -> Battery:
    kind = getattr(getattr(est, "domain", None), "kind", None)
    assert kind in BATTERIES, f"no check battery for eyes of kind {kind!r}"
    return BATTERIES[kind]


def _same_r(x, y) -> bool:
    return bool(np.allclose(x, y, rtol=1e-6, atol=0.0, equal_nan=True))


def _same_phi(x, y) -> bool:
    return bool(np.allclose(x, y, rtol=0.0, atol=PHI_ATOL, equal_nan=True))


def _same(name: str, x, y) -> bool:
    """r relatively, an angle absolutely (:data:`PHI_ATOL`)."""
    return _same_r(x, y) if name == "r" else _same_phi(x, y)


def _copy(x):
    return tuple(np.copy(v) for v in x) if isinstance(x, tuple) else np.copy(x)


def _equal(x, y) -> bool:
    if isinstance(x, tuple):
        return all(np.array_equal(u, v) for u, v in zip(x, y, strict=True))
    return bool(np.array_equal(x, y))


# --- the checks of every model ---------------------------------------------------------


def check_declares_domain(est) -> None:
    """``name`` is a non-empty string; ``domain`` the record of its eyes' kind (a
    :class:`~eyeviz.core.domain.Domain` or ``Domain3D``); ``metadata`` a dict."""
    assert isinstance(getattr(est, "name", None), str) and est.name, "estimator has no name"
    dom = getattr(est, "domain", None)
    record = RECORDS.get(getattr(dom, "kind", None))  # type: ignore[arg-type]
    assert record is not None and isinstance(dom, record), (
        f"domain must be a Domain or Domain3D, got {type(dom)}"
    )
    assert isinstance(getattr(est, "metadata", None), dict), "metadata must be a dict"
    assert est.n_weights >= 0, "n_weights must be >= 0"


def check_shapes_and_dtypes(est) -> None:
    """(N,) float64 coordinates (r, phi or r, azimuth, elevation) and bool masks of the
    same shape; a single row gives scalars, equal to the batch's row."""
    bat = _battery(est)
    a, b, ds = bat.data(est)
    p = est.predict(a, b)
    for name, v in zip(bat.coords, p, strict=True):
        v = np.asarray(v)
        assert v.shape == (bat.n,), f"{name} has shape {v.shape}, expected ({bat.n},)"
        assert v.dtype == np.float64, f"{name} has dtype {v.dtype}, expected float64"
    for name in bat.masks:
        v = np.asarray(getattr(p, name))
        assert v.shape == (bat.n,) and v.dtype == bool, f"{name} must be bool of shape ({bat.n},)"
    one = est.predict(*bat.first(a, b, ds))
    for name in bat.coords:
        assert np.ndim(getattr(one, name)) == 0, "a single row must give scalars"
    for name in bat.coords:
        assert _same(name, getattr(one, name), getattr(p, name)[0]), (
            f"a single row must give the same {name} as in a batch"
        )


def check_rejects_bad_input(est) -> None:
    """Bad input of the model's form (non-binary values, mismatched row counts, a wrong
    shape; in space also bad CSR rows) is a ValueError of one line."""
    bat = _battery(est)
    a, b, ds = bat.data(est)
    for what, (x, y) in bat.bad_inputs(est, a, b, ds).items():
        try:
            est.predict(x, y)
        except ValueError as exc:
            assert str(exc) and "\n" not in str(exc), f"{what}: message must be one line"
        else:
            raise AssertionError(f"{what} was accepted")


def check_empty_input(est) -> None:
    """Zero rows give zero-length results, no error."""
    bat = _battery(est)
    e = bat.empty(est)
    p = est.predict(e, e)
    for name in bat.coords:
        assert np.shape(getattr(p, name)) == (0,), "empty input must give (0,)"


def check_deterministic(est) -> None:
    """The same input twice gives the same output, and the input is not modified."""
    bat = _battery(est)
    a, b, _ = bat.data(est)
    a0, b0 = _copy(a), _copy(b)
    p1 = est.predict(a, b)
    p2 = est.predict(a, b)
    for name in bat.coords:
        x, y = getattr(p1, name), getattr(p2, name)
        assert np.array_equal(x, y, equal_nan=True), f"{name} differs between two calls"
    assert _equal(a, a0) and _equal(b, b0), "predict modified its input"


def check_rows_independent(est) -> None:
    """A row's answer (every coordinate) does not depend on the other rows (subset and
    reversed order)."""
    bat = _battery(est)
    a, b, _ = bat.data(est)
    p = est.predict(a, b)
    rev = np.arange(bat.n)[::-1]
    q = est.predict(bat.take(a, rev), bat.take(b, rev))
    sub = np.array(bat.subset)
    s = est.predict(bat.take(a, sub), bat.take(b, sub))
    for name in bat.coords:
        assert _same(name, getattr(q, name)[::-1], getattr(p, name)), f"row order changes {name}"
        assert _same(name, getattr(s, name), getattr(p, name)[sub]), f"a subset changes {name}"


def check_masks(est) -> None:
    """Rows that are not one feature (planar: nothing lit, two runs; in space: an eye
    lit nothing) are NaN, not valid and in no other mask (in the domain, flagged); every
    other generated row is valid with finite r > 0 and finite angles (no NaN without the
    flag)."""
    bat = _battery(est)
    x, y, bad = bat.not_one_feature(*bat.data(est))
    p = est.predict(x, y)
    v = np.asarray(p.valid)
    assert not v[bad].any(), "rows that are not one feature must be invalid"
    for name in bat.coords:
        assert np.isnan(getattr(p, name)[bad]).all(), "invalid rows must be NaN"
    ok = np.ones(v.shape, bool)
    ok[bad] = False
    assert v[ok].all(), "generated single-feature rows must be valid"
    assert np.isfinite(p.r[ok]).all() and (p.r[ok] > 0).all(), "valid rows need finite r > 0"
    for name in bat.coords[1:]:
        assert np.isfinite(getattr(p, name)[ok]).all(), f"valid rows need a finite {name}"
    for name in bat.masks[1:]:
        assert not np.asarray(getattr(p, name))[~v].any(), f"invalid rows cannot be {name}"


def check_sensible_answers(est) -> None:
    """On data of its own domain the median relative error of r is below 100 % and
    every angle within 0.2 rad: a sanity floor, not a benchmark."""
    bat = _battery(est)
    a, b, ds = bat.data(est)
    p = est.predict(a, b)
    rel = np.abs(p.r / ds.r - 1)
    assert np.median(rel) < 1.0, f"median relative r error {np.median(rel):.3g} >= 100 %"
    for name in bat.coords[1:]:
        err = np.median(np.abs(getattr(p, name) - getattr(ds, name)))
        assert err < 0.2, f"median {name} error >= 0.2 rad"


# --- the planar eyes: half bitmaps of m/2 ----------------------------------------------


def _planar_data(est):
    from eyeviz import dataset

    d = est.domain
    ds = dataset.generate(PLANAR.n, d.eyes, d.r_min, d.r_max, d.g_max, "single", 7)
    return ds.omega_a.copy(), ds.omega_b.copy(), ds


def _planar_bad(est, a, b, ds) -> dict[str, tuple[Any, Any]]:
    bad = a.astype(np.int64)
    bad[2, 5] = 2
    return {
        "a value 2": (bad, b),
        "mismatched rows": (a[:5], b[:4]),
        "a 3-D array": (a[None], b[None]),
        "text": (np.array([["x"] * a.shape[1]]), b[:1]),
    }


def _planar_not_one(a, b, ds):
    a[0] = False  # nothing lit
    a[1] = False
    a[1, 3] = a[1, 10] = True  # two runs
    return a, b, [0, 1]


def check_accepts_bool_and_int(est) -> None:
    """0/1 as bool, uint8, int64 and float give the same answer (r and phi)."""
    a, b, _ = _planar_data(est)
    ref = est.predict(a, b)
    for dt in (np.uint8, np.int64, np.float64):
        p = est.predict(a.astype(dt), b.astype(dt))
        assert np.array_equal(p.r, ref.r, equal_nan=True), f"dtype {dt.__name__} changes r"
        assert np.array_equal(p.phi, ref.phi, equal_nan=True), f"dtype {dt.__name__} changes phi"


def check_rejects_wrong_m(est) -> None:
    """Rows of length != m/2 are refused with a message naming m/2."""
    w = est.domain.width
    for bad in (w + 1, w - 1):
        wa = np.zeros((3, bad), bool)
        try:
            est.predict(wa, wa)
        except ValueError as exc:
            assert "m/2" in str(exc), f"wrong-length message does not name m/2: {exc}"
        else:
            raise AssertionError(f"rows of length {bad} (m/2 = {w}) were accepted")


def check_predict_intervals(est) -> None:
    """``predict_intervals`` on the intervals of the bitmaps answers like ``predict``."""
    from eyeviz.estimators.base import bitmaps_to_intervals

    a, b, _ = _planar_data(est)
    LA, RA, LB, RB, ok = bitmaps_to_intervals(a, b, est.domain.width)
    p = est.predict(a, b)
    q = est.predict_intervals(LA[ok], RA[ok], LB[ok], RB[ok])
    assert _same_r(q.r, p.r[ok]), "predict_intervals disagrees with predict on r"
    assert _same_phi(q.phi, p.phi[ok]), "predict_intervals disagrees with predict on phi"


PLANAR = Battery(
    coords=("r", "phi"),
    masks=("valid", "in_domain"),
    n=48,
    subset=(5, 6, 7, 8),
    data=_planar_data,
    take=lambda x, rows: x[rows],
    first=lambda a, b, ds: (a[0], b[0]),
    empty=lambda est: np.zeros((0, est.domain.width), bool),
    bad_inputs=_planar_bad,
    not_one_feature=_planar_not_one,
    checks=(
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
    ),
)


# --- the eyes in space: lit sets as CSR rows and as bitmaps -----------------------------


def _space_data(est):
    from eyeviz.dataset.algorithm1_3d import generate3d

    ds = generate3d(SPACE.n, est.domain, "single", 7)
    return (ds.indptr_a, ds.indices_a), (ds.indptr_b, ds.indices_b), ds


def _space_take(lit, rows):
    from eyeviz.estimators.base import take_rows

    return take_rows(lit[0], lit[1], np.asarray(rows))


def _space_first(a, b, ds):
    ba, bb = ds.bitmaps(0, 1)
    return ba[0], bb[0]


def _space_bad(est, a, b, ds) -> dict[str, tuple[Any, Any]]:
    npix = est.domain.facet_counts[0]  # eye A's (a measured pair's eyes may differ)
    ba, bb = ds.bitmaps(0, 3)
    two = ba.astype(np.int64)
    two[1, 0] = 2
    one_b = _space_take(b, [0])
    return {
        "wrong npix": (np.zeros((3, npix + 1), bool), bb),
        "a value 2": (two, bb),
        "mismatched rows": (ba[:2], bb),
        "index out of range": ((np.array([0, 1]), np.array([npix])), one_b),
        "decreasing indices": ((np.array([0, 2]), np.array([9, 4])), one_b),
        "a 3-tuple": ((a[0], a[1], a[1]), b),
    }


def _space_not_one(a, b, ds):
    ba, bb = ds.bitmaps()
    ba[0] = False  # eye A lit nothing
    return ba, bb, [0]


def check_csr_equals_bitmaps(est) -> None:
    """CSR rows and the same lit sets as dense bitmaps (bool or 0/1 integers) agree."""
    a, b, ds = _space_data(est)
    p = est.predict(a, b)
    ba, bb = ds.bitmaps()
    for what, (x, y) in {
        "bitmaps": (ba, bb),
        "uint8": (ba.astype(np.uint8), bb.astype(np.uint8)),
    }.items():
        q = est.predict(x, y)
        for name in SPACE.coords:
            assert _same(name, getattr(q, name), getattr(p, name)), f"{what} and CSR rows disagree"


SPACE = Battery(
    coords=("r", "azimuth", "elevation"),
    masks=("valid", "in_domain", "flagged"),
    n=12,
    subset=(5, 2, 8),
    data=_space_data,
    take=_space_take,
    first=_space_first,
    empty=lambda est: (np.zeros(1, np.int64), np.zeros(0, np.int64)),
    bad_inputs=_space_bad,
    not_one_feature=_space_not_one,
    checks=(
        check_declares_domain,
        check_shapes_and_dtypes,
        check_csr_equals_bitmaps,
        check_rejects_bad_input,
        check_empty_input,
        check_deterministic,
        check_rows_independent,
        check_masks,
        check_sensible_answers,
    ),
)

#: The battery of each eye model (``domain.kind``): a model in space whose estimators
#: take CSR lit sets shares :data:`SPACE`.
BATTERIES: dict[str, Battery] = {"planar": PLANAR, "spherical": SPACE, "measured": SPACE}
#: The checks of the planar and of the spherical-side battery, in their order.
CHECKS: tuple[Callable, ...] = PLANAR.checks
CHECKS3D: tuple[Callable, ...] = SPACE.checks


def _checks_of(est) -> tuple[Callable, ...]:
    kind = getattr(getattr(est, "domain", None), "kind", None)
    battery = BATTERIES.get(kind) if isinstance(kind, str) else None
    return battery.checks if battery is not None else (check_declares_domain,)


def estimator_checks(est) -> Iterator[tuple[object, Callable]]:
    """``(estimator, check)`` pairs of the battery of the estimator's eyes, for
    ``pytest.mark.parametrize``."""
    for check in _checks_of(est):
        yield est, check


def check_estimator(est) -> list[str]:
    """Run the battery of the estimator's eyes (:data:`BATTERIES`) on ``est``: the names
    of the checks passed, or AssertionError naming the first failing check."""
    done = []
    for check in _checks_of(est):
        try:
            check(est)
        except AssertionError as exc:
            raise AssertionError(f"{est.name}: {check.__name__}: {exc}") from None
        done.append(check.__name__)
    return done
