"""The exact predicates: signs in Q(sqrt 2), Q(sqrt 3) and the generic mpmath path."""

from __future__ import annotations

import math
from fractions import Fraction as F

import mpmath
import numpy as np
import pytest
from hypothesis import given, settings
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


# --- vectorised ties (issue 14) --------------------------------------------------------
coord = st.one_of(
    st.integers(-64, 64).map(float),
    st.floats(-1e3, 1e3, allow_nan=False),
    st.floats(-1e-200, 1e-200, allow_nan=False),
    st.floats(-1e250, 1e250, allow_nan=False),
)


@settings(max_examples=400, deadline=None)
@given(
    coord,
    coord,
    st.floats(0, 1e3, allow_nan=False),
    st.sampled_from([4, 8, 12, 24, 360, 720, 100, 2**20]),
    st.integers(-3, 27),
    st.booleans(),
    st.sampled_from([-40.0, 40.0, 0.0, 1e-300]),
)
def test_vectorised_ties_agree_with_the_rational_predicate(x, y, g, m, j, upper, cx):
    # boundaries at 30- and 45-degree multiples (and a few others, which must say -1)
    n = j * m // 24 if j % 3 else j * m // 8
    got = int(exact.ties_at_or_past([x], [y], [g], cx, [n], m, [upper])[0])
    X, Y, G = F(x) - F(cx), F(y), F(g)
    if X == 0 and Y == 0:
        return
    want = exact._endpoint_at_or_past(X, Y, G, n, m, upper)
    nice = (12 * n) % m == 0 or (8 * n) % m == 0
    if not nice:
        assert got == -1
        return
    assert got == int(want)


def test_vectorised_ties_on_the_sqrt_part():
    # 30 degrees: the sqrt(3) parts carry y; signs of a and b differ on both sides of 0
    xs = np.array([1.0, 1.0, 3.0, 3.0, 1e-200, 7.5])
    ys = np.array([0.5, 0.6, 1.7320508075688772, 1.7320508075688774, 1e-200, -2.0])
    gs = np.array([0.5, 0.25, 0.0, 0.0, 0.0, 1.0])
    n = np.full(6, 60)  # 30 degrees at m = 720
    for upper in (False, True):
        got = exact.ties_at_or_past(xs, ys, gs, 0.0, n, 720, np.full(6, upper))
        want = [
            exact._endpoint_at_or_past(F(x), F(y), F(g), 60, 720, upper)
            for x, y, g in zip(xs, ys, gs, strict=True)
        ]
        assert got.tolist() == [int(w) for w in want]


def test_expansion_sign_is_exact_where_float_sums_cancel():
    a = np.array([1e16, 1.0, 0.1])
    b = np.array([1.0, 1e-30, 0.2])
    c = np.array([-1e16, -1.0, -0.30000000000000004])
    signs = exact._sign_of(exact._expansion([a, b, c]))
    want = [
        int(np.sign(F(float(p)) + F(float(q)) + F(float(r))))
        for p, q, r in zip(a, b, c, strict=True)
    ]
    assert signs.tolist() == want == [1, 1, -1]


def test_the_cosine_tables_are_the_cosines():
    """cos(30 k deg) = a + b sqrt 3 and cos(45 k deg) = a + b sqrt 2, in the Fraction
    tables and the doubled float tables alike (entries no other test reaches included)."""
    for table, doubled, full, root in (
        (exact._COS30, exact._COS30_2, 12, 3),
        (exact._COS45, exact._COS45_2, 8, 2),
    ):
        assert len(table) == len(doubled) == full
        for k in range(full):
            want = math.cos(2 * math.pi * k / full)
            a, b = table[k]
            assert float(a) + float(b) * math.sqrt(root) == pytest.approx(want, abs=1e-15), k
            a2, b2 = doubled[k]
            assert a2 + b2 * math.sqrt(root) == pytest.approx(2 * want, abs=1e-15), k
