"""Issue 13 items 5 and 7: exact predicates over the whole float range, the cap on m (the
one bound of issue 20, eyeviz.core.bounds.MAX_M), one-line errors for out-of-range
parameters, and no dependence on mpmath.mp.prec."""

from __future__ import annotations

import math
from fractions import Fraction as F

import mpmath
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from eyeviz.core.bounds import MAX_M
from eyeviz.core.geometry import EyePair
from eyeviz.reference.digits80 import reference_intervals

EYES = EyePair(40.0, 20.0, 720)
M_RULE = "m must be an even integer >= 4 and <= 1048576, got "
scale = st.integers(-300, 300).map(lambda k: 10.0**k)
unit = st.floats(-4, 4, allow_nan=False).filter(lambda v: abs(v) > 1e-3)


def _overlap_reference(x, y, g, cx, l):
    X, Y, S = F(x) - F(cx), F(y), F(g) + F(l)
    return X * X + Y * Y <= S * S


def _bfv_reference(x, y, g, h, l):
    """Eq. 17 at 4,000 bits with mpmath (an independent route: square roots, no squares)."""
    with mpmath.workprec(4000):
        w = mpmath.sqrt(mpmath.mpf(h) ** 2 - mpmath.mpf(l) ** 2)
        X, Y, G = mpmath.mpf(x), mpmath.mpf(y), mpmath.mpf(g)
        tiny = (abs(w * Y) + abs(l * X) + abs(G * h)) * mpmath.ldexp(1, -3900)
        return all(w * Y + sx * l * X - G * h >= -tiny for sx in (-1, 1))


@settings(max_examples=300, deadline=None)
@given(unit, unit, st.floats(0.01, 3), scale, st.booleans())
def test_overlaps_eye_is_exact_at_every_scale(a, b, c, s, tie):
    x, y = a * s, b * s
    g = c * s
    if tie:  # a disc that just touches eye B's disc, to within rounding
        g = math.hypot(x - EYES.h, y) - EYES.l
        if not (g > 0 and math.isfinite(g)):
            g = c * s
    got_a, got_b = EYES.overlaps_eye(x, y, g)
    assert bool(got_a) == _overlap_reference(x, y, g, -EYES.h, EYES.l)
    assert bool(got_b) == _overlap_reference(x, y, g, EYES.h, EYES.l)


@settings(max_examples=300, deadline=None)
@given(unit, st.floats(0.01, 4), st.floats(0.01, 3), scale, st.booleans())
def test_in_bfv_is_exact_at_every_scale(a, b, c, s, tie):
    x, y, g = a * s, b * s, c * s
    if tie:  # on the right bound of the wedge, to within rounding
        g = (math.sqrt(EYES.h**2 - EYES.l**2) * y - EYES.l * abs(x)) / EYES.h
        if not (g > 0 and math.isfinite(g)):
            g = c * s
    assert bool(EYES.in_bfv(x, y, g)) == _bfv_reference(x, y, g, EYES.h, EYES.l)


def test_the_issue_examples():
    assert [bool(v) for v in EYES.overlaps_eye(2e200, 0, 1e200)] == [False, False]
    assert bool(EYES.in_bfv(0, 1e308, 1e307))
    # touching eye A's disc at distance 40 exactly, missed or met by 1e-300
    assert not bool(EYES.overlaps_eye(1e-300, 0, 20.0)[0])
    assert bool(EYES.overlaps_eye(-1e-300, 0, 20.0)[0])
    assert bool(EYES.overlaps_eye(0.0, 0, 20.0)[0])


@pytest.mark.parametrize("m", [2**18, MAX_M - 2, MAX_M])
def test_huge_m_up_to_the_cap_matches_the_reference(m):
    eyes = EyePair(40, 20, m)
    for x, y, g in ((0.0, 1500.0, 50.0), (50.5, 3.0, 3.0), (-1234.5, 0.125, 0.125)):
        got = np.array([np.ravel(v)[0] for v in eyes.intervals(x, y, g)])
        ref = np.array([np.ravel(v)[0] for v in reference_intervals(eyes, x, y, g)])
        assert (got == ref).all(), (m, x, y, g, got, ref)


def test_m_cap_is_the_one_bound_of_the_package():
    assert MAX_M == 2**20 and EyePair(40, 20, MAX_M).m == MAX_M
    with pytest.raises(ValueError, match="<= 1048576, got 1048578"):
        EyePair(40, 20, MAX_M + 2)


@pytest.mark.parametrize(
    "kwargs, message",
    [
        ({"m": 2**62}, M_RULE + "4611686018427387904"),
        ({"m": 2**63}, M_RULE + "9223372036854775808"),
        ({"m": MAX_M + 2}, M_RULE + "1048578"),
        ({"m": 10**400}, M_RULE + "100000000000"),
        ({"h": 10**400}, "h must be a finite real number (0 < l < h), got 100000000000"),
        ({"l": -(10**400)}, "l must be a finite real number (0 < l < h), got -10000000000"),
    ],
)
def test_out_of_range_parameters_give_one_line_value_errors(kwargs, message):
    args = {"h": 40, "l": 20, "m": 720, **kwargs}
    with pytest.raises(ValueError) as info:
        EyePair(**args)
    text = str(info.value)
    assert text.startswith(message) and "\n" not in text and len(text) < 120


@pytest.mark.parametrize("prec", [4, 2000])
def test_exact_path_does_not_depend_on_the_global_precision(prec):
    eyes = EyePair(40, 20, MAX_M)
    # ties at m = 2^20, and the same features scaled by 1e200 (squares overflow): every
    # element of these goes through the exact path, the scaled ones through mpmath
    xs = np.array([0.0, 50.5, 61.0, -1234.5, 40.0])
    ys = np.array([1500.0, 3.0, 0.0, 0.125, 40.0])
    gs = np.array([50.0, 3.0, 21.0, 0.125, 20.0])
    xs, ys, gs = (np.concatenate([v, v * 1e200]) for v in (xs, ys, gs))
    ref = np.array(reference_intervals(eyes, xs, ys, gs))
    old = mpmath.mp.prec
    try:
        mpmath.mp.prec = prec
        got = np.array(eyes.intervals(xs, ys, gs))
        # grazing: every element of these goes through mpmath
        graze = EyePair(40, 20, 720).intervals(40 + 3.0, 4.0, 5.0 * (1 - 2.0**-50))
    finally:
        mpmath.mp.prec = old
    assert (got == ref).all()
    want = reference_intervals(EyePair(40, 20, 720), 43.0, 4.0, 5.0 * (1 - 2.0**-50))
    assert [int(np.ravel(v)[0]) for v in graze] == [int(np.ravel(v)[0]) for v in want]
