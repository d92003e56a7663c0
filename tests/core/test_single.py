"""The one-feature path (eyeviz.core.single) against the vectorised, exact EyePair."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from eyeviz.core import single
from eyeviz.core.geometry import EyePair
from eyeviz.reference import stability_cases as sc
from eyeviz.reference.digits80 import reference_intervals

PAPER = EyePair(40.0, 20.0, 720)


def _check(eyes: EyePair, x: np.ndarray, y: np.ndarray, g: np.ndarray) -> int:
    """Every element agrees with the vectorised methods; returns how many the one-feature
    intervals left to them (None)."""
    iv = np.array(eyes.intervals(x, y, g))
    bfv = eyes.in_bfv(x, y, g)
    oa, ob = eyes.overlaps_eye(x, y, g)
    left = 0
    for i, (xi, yi, gi) in enumerate(zip(x.tolist(), y.tolist(), g.tolist(), strict=True)):
        got = single.intervals_one(eyes, xi, yi, gi)
        if got is None:
            left += 1
        else:
            assert got == tuple(iv[:, i].tolist()), (xi, yi, gi)
            assert all(type(v) is int for v in got)
        assert single.in_bfv_one(eyes, xi, yi, gi) == bfv[i], (xi, yi, gi)
        assert single.overlaps_one(eyes, xi, yi, gi) == (oa[i], ob[i]), (xi, yi, gi)
    return left


@pytest.mark.parametrize("name", list(sc.CLASSES))
def test_agrees_with_the_vectorised_path_on_every_stability_class(name):
    cs = sc.make(name, 600, seed=11)
    _check(cs.eyes, cs.x, cs.y, cs.g)


def test_agrees_with_the_80_digit_reference_where_it_answers():
    for name in ("paper", "ground", "vertical", "grazing"):
        cs = sc.make(name, 400, seed=3)
        ref = np.array(reference_intervals(cs.eyes, cs.x, cs.y, cs.g))
        for i in range(cs.x.size):
            got = single.intervals_one(cs.eyes, float(cs.x[i]), float(cs.y[i]), float(cs.g[i]))
            if got is not None:
                assert got == tuple(ref[:, i].tolist())


def test_answers_almost_every_paper_regime_feature_itself():
    """The point of the path: a drag frame in the paper's regime rarely needs numpy."""
    cs = sc.make("paper", 2000, seed=5)
    assert _check(cs.eyes, cs.x, cs.y, cs.g) < 0.05 * cs.x.size


def test_leaves_ties_to_the_exact_path():
    """A disc resting on y = 0 has a tangent exactly on a sector boundary: the float
    floor alone is wrong on some of them (test_geometry), so the bound must hand every
    such tie back."""
    cs = sc.make("ground", 300, seed=7)
    fast = np.array(cs.eyes._intervals(cs.x, cs.y, cs.g, refine=False))
    exact = np.array(cs.eyes.intervals(cs.x, cs.y, cs.g))
    wrong = np.flatnonzero((fast != exact).any(axis=0))
    assert wrong.size
    for i in wrong.tolist():
        assert single.intervals_one(cs.eyes, cs.x[i], cs.y[i], cs.g[i]) is None


def test_bfv_and_eye_contact_ties_are_decided_exactly():
    # h = 5, l = 3: the disc of radius 5 at (37, 34) touches the right BFV bound (4, 3)
    eyes = EyePair(5.0, 3.0, 8)
    assert single.in_bfv_one(eyes, 37.0, 34.0, 5.0)
    assert not single.in_bfv_one(eyes, 37.0, 34.0, math.nextafter(5.0, 6.0))
    g = 7.0  # touching eye B from outside: |(x, 0) - B| = g + l exactly
    assert single.overlaps_one(PAPER, 40.0 + 20.0 + g, 0.0, g) == (False, True)
    assert single.overlaps_one(PAPER, math.nextafter(67.0, 99.0), 0.0, g) == (False, False)
    # squares overflow: issue 12 item 11's (True, True) came from inf <= inf
    assert single.overlaps_one(PAPER, 1e160, 1e160, 1e159) == (False, False)
    # products that overflow to inf or underflow where rounding is no longer relative
    for x, y, g in ((1e160, 1e160, 1e159), (1e307, 1.7e308, 1e306), (-1e307, 1.7e308, 1e300),
                    (0.0, 1e-320, 5e-324), (3e-321, 8e-321, 1e-322)):  # fmt: skip
        assert single.in_bfv_one(PAPER, x, y, g) == bool(PAPER.in_bfv(x, y, g)), (x, y, g)
        want = tuple(bool(v) for v in PAPER.overlaps_eye(x, y, g))
        assert single.overlaps_one(PAPER, x, y, g) == want, (x, y, g)
    assert single.in_bfv_one(PAPER, 1e307, 1.7e308, 1e306)


@pytest.mark.parametrize(
    ("x", "y", "g"),
    [(math.nan, 1.0, 1.0), (1.0, math.inf, 1.0), (0.0, 100.0, 0.0), (0.0, 100.0, -1.0)],
)
def test_invalid_input_is_left_to_the_vectorised_path(x, y, g):
    assert single.intervals_one(PAPER, x, y, g) is None
    with pytest.raises(ValueError):
        PAPER.intervals(x, y, g)


def test_float32_and_int_inputs_are_computed_in_float64():
    """numpy float32 scalars would otherwise run the arithmetic in float32 and pass the
    float64 bound with a wrong interval (found in review)."""
    eyes = EyePair(40.0, 20.0, 36000)
    x, y, g = np.float32(2325.6523), np.float32(476.1301), np.float32(188.34451)
    want = tuple(int(v[0]) for v in eyes.intervals([float(x)], [float(y)], [float(g)]))
    assert single.intervals_one(eyes, x, y, g) in (None, want)
    assert single.intervals_one(eyes, float(x), float(y), float(g)) == want
    assert single.intervals_one(PAPER, 0, 1500, 50) == single.intervals_one(
        PAPER, 0.0, 1500.0, 50.0
    )
    assert single.intervals_one(PAPER, 0, 10**400, 50) is None  # too large for a float
    assert single.in_bfv_one(eyes, x, y, g) == bool(eyes.in_bfv(float(x), float(y), float(g)))


@settings(max_examples=400, deadline=None)
@given(
    st.floats(-1e6, 1e6),
    st.floats(-1e6, 1e6),
    st.floats(1e-3, 1e4),
    st.sampled_from([4, 16, 360, 720, 36000, 2**20]),
    st.sampled_from([(40.0, 20.0), (3.0, 1.0), (1e4, 9999.0)]),
)
def test_agrees_anywhere(x, y, g, m, hl):
    eyes = EyePair(hl[0], hl[1], m)
    _check(eyes, np.array([x]), np.array([y]), np.array([g]))


@pytest.mark.parametrize("q", [0.3, 0.7])
def test_an_endpoint_within_the_rounding_bound_of_a_boundary_is_handed_back(q):
    """The bound is the vectorised fast path's (module docstring), (64 + 16 / (1 - 0.75))
    u m = 128 u m whatever g / r_E: a tangent computed 100 u m past a sector boundary (more
    than the base term, less than the whole bound) is not answered here but left to
    ``pair.intervals``, near grazing or not; one 300 u m past is answered."""
    from eyeviz.core.geometry import _U

    pair, k = PAPER, PAPER._k
    r, phi = 1500.0, 1.1  # the centre seen from eye A
    x, y = -pair.h + r * math.cos(phi), r * math.sin(phi)
    dx = x + pair.h
    for ulps, answered in ((100, False), (300, True)):
        # g such that the upper tangent t = (phi + asin(g / r)) k is an integer + ulps u m
        t = math.floor((math.atan2(y, dx) + math.asin(q)) * k) + ulps * _U * pair.m
        g = math.sqrt(dx * dx + y * y) * math.sin(t / k - math.atan2(y, dx))
        t_hi = (math.atan2(y, dx) + math.asin(g / math.sqrt(dx * dx + y * y))) * k
        frac = (t_hi - math.floor(t_hi)) / (_U * pair.m)
        assert ulps - 20 < frac < ulps + 20  # the case is what it claims
        got = single.intervals_one(pair, x, y, g)
        assert (got is not None) == answered, (ulps, frac, got)
        if got is not None:
            assert got == tuple(int(v[0]) for v in pair.intervals([x], [y], [g]))
