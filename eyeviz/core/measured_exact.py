"""The exact fallback of the measured eyes' seen rule (:mod:`eyeviz.core.measured`).

Facet (p, a, dr) sees the ball (c, g) iff the closed ball meets the closed cone
{p + t u : t >= 0, angle(u, a) <= alpha}, alpha = dr / 2 (docs/measured.md). With
v = c - p, s = v . a, q = |v x a|, N = |a|, C = cos(alpha), S = sin(alpha), the plane of
a and v holds the point V (cos theta, sin theta) = (s, q) / N, theta = angle(v, a); the
cone's edge in that plane is the ray of direction (C, S), and

* E = (s C + q S) / N is the point's coordinate along that edge,
* M = (q C - s S) / N its signed distance from the edge's line (<= 0: inside the cone),

so dist(c, cone) = 0 when M <= 0, M when M > 0 and E >= 0 (the nearest point is on the
edge), and |v| when E <= 0 (the nearest point is the apex). Hence (alpha < pi / 2):

    seen  <=>  |v|^2 <= g^2  or  (s C + q S >= 0  and  q C - s S - g N <= 0).

The first test is exact in rationals (the float inputs are the rationals they denote).
The other two are decided in mpmath at rising precision with a rigorous error bound.
Neither is ever exactly 0 unless v = 0: alpha is a non-zero rational, so by
Lindemann-Weierstrass cos(alpha), sin(alpha) and tan(alpha)^2 are transcendental; s C + q S
= 0 would make tan(alpha)^2 = s^2 / q^2 rational, and q C - s S = g N would make
exp(i alpha) = exp(i acos(g / |v|)) exp(-i atan2(s, q)) algebraic. Tangency (distance
exactly g) therefore happens only through the apex test |v| = g, which is exact.
"""

from __future__ import annotations

from fractions import Fraction

import mpmath

__all__ = ["seen_exact", "lens_in_ball_exact"]

_START_PREC = 96
_MAX_PREC = 1 << 16


def _mpf(q: Fraction):
    return mpmath.mpf(q.numerator) / q.denominator


def _parts(c, g, p, a):
    """Exact rationals: V2 = |v|^2, G2 = g^2, s, Q = |v x a|^2, N2 = |a|^2, G = g."""
    vx, vy, vz = (Fraction(ci) - Fraction(pi) for ci, pi in zip(c, p, strict=True))
    ax, ay, az = (Fraction(ai) for ai in a)
    G = Fraction(g)
    s = vx * ax + vy * ay + vz * az
    wx, wy, wz = vy * az - vz * ay, vz * ax - vx * az, vx * ay - vy * ax
    return (
        vx * vx + vy * vy + vz * vz,
        G * G,
        s,
        wx * wx + wy * wy + wz * wz,
        ax * ax + ay * ay + az * az,
        G,
    )


def _sign(fun, scale, half_dr: Fraction) -> int:
    """Sign of fun(C, S) at rising precision, C, S = cos, sin of half_dr; ``scale`` (mpf
    thunk) bounds the sum of the absolute values of the terms, whose relative errors are
    a few units of the working precision each (correctly rounded mpmath operations)."""
    prec = _START_PREC
    while prec <= _MAX_PREC:
        with mpmath.workprec(prec):
            al = _mpf(half_dr)
            val = fun(mpmath.cos(al), mpmath.sin(al))
            err = scale() * mpmath.ldexp(1, 8 - prec)
            if abs(val) > err:
                return 1 if val > 0 else -1
        prec *= 2
    raise ArithmeticError(f"cannot separate a seen test from 0 at {_MAX_PREC} bits")


def seen_exact(c, g: float, p, a, dr: float) -> bool:
    """Whether the facet (lens p, axis a, full acceptance dr) sees the closed ball (c, g),
    in exact real arithmetic on the float inputs (the module docstring gives the rule)."""
    V2, G2, s, Q, N2, G = _parts(c, g, p, a)
    if V2 <= G2:
        return True  # the lens lies in the closed ball (v = 0 included)
    half = Fraction(dr) / 2
    # E >= 0: s C + q S with C, S > 0 (0 < alpha < pi / 2) and q >= 0
    if s < 0:
        if Q == 0:
            return False  # c behind the lens on the axis line: E = s C < 0
        e_sign = _sign(
            lambda C, S: _mpf(s) * C + mpmath.sqrt(_mpf(Q)) * S,
            lambda: abs(_mpf(s)) + mpmath.sqrt(_mpf(Q)),
            half,
        )
        if e_sign < 0:
            return False
    # M <= 0: q C - s S - g N
    m_sign = _sign(
        lambda C, S: mpmath.sqrt(_mpf(Q)) * C - _mpf(s) * S - _mpf(G) * mpmath.sqrt(_mpf(N2)),
        lambda: mpmath.sqrt(_mpf(Q)) + abs(_mpf(s)) + _mpf(G) * mpmath.sqrt(_mpf(N2)),
        half,
    )
    return m_sign < 0


def lens_in_ball_exact(c, g: float, p) -> bool:
    """The closed ball (c, g) contains the lens p: |c - p|^2 <= g^2 in rationals."""
    d2 = sum((Fraction(ci) - Fraction(pi)) ** 2 for ci, pi in zip(c, p, strict=True))
    return d2 <= Fraction(g) ** 2
