"""The exact predicates: signs in Q(sqrt 2), Q(sqrt 3) and the generic mpmath path."""

from __future__ import annotations

import math
from fractions import Fraction as F

import mpmath
import pytest
from hypothesis import given
from hypothesis import strategies as st

from eyeviz.core import exact

small = st.fractions(min_value=-50, max_value=50, max_denominator=64)


@given(small, small)
def test_sign_a_plus_b_sqrt_matches_high_precision(a, b):
    for k in (2, 3):
        expect = mpmath.mpf(a.numerator) / a.denominator + mpmath.mpf(
            b.numerator
        ) / b.denominator * mpmath.sqrt(k)
        s = exact.sign_a_plus_b_sqrt(a, b, k)
        assert s == (expect > 0) - (expect < 0)


@given(small, small, small, st.integers(0, 359), st.sampled_from([4, 8, 12, 24, 360, 720, 7, 100]))
def test_sign_linear_matches_high_precision(u, v, w, n, m):
    with mpmath.workdps(60):
        beta = 2 * mpmath.pi * n / m
        val = (
            mpmath.mpf(u.numerator) / u.denominator
            + mpmath.mpf(v.numerator) / v.denominator * mpmath.cos(beta)
            + mpmath.mpf(w.numerator) / w.denominator * mpmath.sin(beta)
        )
        expect = 0 if abs(val) < mpmath.mpf(10) ** -50 else (1 if val > 0 else -1)
    assert exact.sign_linear(u, v, w, n, m) == expect


def test_exact_zero_on_rational_and_quadratic_boundaries():
    # cos(60 deg) = 1/2: u + v cos b = 0 exactly
    assert exact.sign_linear(F(-1), F(2), F(0), 1, 6) == 0
    # sin(60 deg) * 2 - sqrt(3) = 0 cannot be written with rationals; a near miss is not 0
    assert exact.sign_linear(F(-173205, 100000), F(0), F(2), 1, 6) == 1
    # 45 degrees: cos = sin, so v = -w gives exactly 0 with u = 0
    assert exact.sign_linear(F(0), F(3), F(-3), 1, 8) == 0


def test_exact_floor_pair_ground_tie():
    # the example, eye B at (40, 0): lower tangent on direction 0 exactly
    lo, hi = exact.exact_floor_pair(50.5, 3.0, 3.0, 40.0, 720)
    assert lo == 0 and hi == math.floor(
        (math.atan2(3, 10.5) + math.asin(3 / math.hypot(10.5, 3))) * 720 / (2 * math.pi)
    )


def test_exact_floor_pair_inside_returns_none():
    assert exact.exact_floor_pair(40.0, 3.0, 3.0, 40.0, 720) is None
    assert exact.exact_floor_pair(40.0, 3.0, 3.000000001, 40.0, 720) is None


def test_exact_in_bfv_and_overlap_on_the_boundary():
    assert exact.exact_overlaps(61.0, 0.0, 1.0, 40.0, 20.0)
    assert not exact.exact_overlaps(61.0, 0.0, math.nextafter(1.0, 0), 40.0, 20.0)
    # h = 5, l = 3 -> w = 4: disc tangent to the right bound at distance g
    assert exact.exact_in_bfv(37.0, 34.0, 5.0, 5.0, 3.0)
    assert not exact.exact_in_bfv(37.0, 34.0, math.nextafter(5.0, 6.0), 5.0, 3.0)


@pytest.mark.parametrize("y", [1.0, -1.0, 0.0])
def test_sign_sqrt_times_minus(y):
    for c in (F(-3), F(0), F(2), F(3)):
        expect = y * math.sqrt(2) - float(c)
        s = exact.sign_sqrt_times_minus(F(y), F(2), c)
        assert s == (expect > 0) - (expect < 0)
