"""Exact predicates behind the geometry core's fallback path.

The float64 fast path in :mod:`eyeviz.core.geometry` decides almost every element; the few
whose tangent direction lies within rounding distance of an ommatidium boundary come
here. Inputs are taken as the exact rationals their floats denote, so the answer is the
one of exact real arithmetic on the float inputs, with the half-open sectors of Eq. 8.

Every boundary test reduces to the sign of ``u + v*cos(beta) + w*sin(beta)`` with
rational u, v, w and ``beta = 2*pi*n/m``. When beta is a multiple of 30 or 45 degrees,
cos and sin lie in Q(sqrt 3) or Q(sqrt 2) and the sign is decided in exact rational
arithmetic. For every other beta, 1, cos(beta), sin(beta) are linearly independent over Q
at the degrees that occur (so the form vanishes only when u = v = w = 0) and the sign
is found with mpmath at increasing precision until the error bound separates it from 0.
"""

from __future__ import annotations

from fractions import Fraction
from math import gcd

#: cos(30k deg) = a + b*sqrt(3), k = 0..11, as (a, b)
_COS30 = [
    (1, 0), (0, Fraction(1, 2)), (Fraction(1, 2), 0), (0, 0),
    (Fraction(-1, 2), 0), (0, Fraction(-1, 2)), (-1, 0), (0, Fraction(-1, 2)),
    (Fraction(-1, 2), 0), (0, 0), (Fraction(1, 2), 0), (0, Fraction(1, 2)),
]  # fmt: skip
#: cos(45k deg) = a + b*sqrt(2), k = 0..7, as (a, b)
_COS45 = [
    (1, 0), (0, Fraction(1, 2)), (0, 0), (0, Fraction(-1, 2)),
    (-1, 0), (0, Fraction(-1, 2)), (0, 0), (0, Fraction(1, 2)),
]  # fmt: skip

_MAX_PREC = 1 << 14


def sign_a_plus_b_sqrt(a: Fraction, b: Fraction, k: int) -> int:
    """Exact sign of ``a + b*sqrt(k)`` for rationals a, b and a non-square k > 0."""
    sa = (a > 0) - (a < 0)
    sb = (b > 0) - (b < 0)
    if sa == sb or sb == 0:
        return sa
    if sa == 0:
        return sb
    diff = a * a - k * b * b
    return sa if diff > 0 else sb if diff < 0 else 0


def _mpf(q: Fraction):
    import mpmath  # imported on first use: most programs never reach the exact path

    return mpmath.mpf(q.numerator) / q.denominator


def sign_linear(u: Fraction, v: Fraction, w: Fraction, n: int, m: int) -> int:
    """Sign of ``u + v*cos(2*pi*n/m) + w*sin(2*pi*n/m)``, exact."""
    n %= m
    d = gcd(n, m)
    n1, m1 = n // d, m // d
    for table, full, root in ((_COS30, 12, 3), (_COS45, 8, 2)):
        if full % m1 == 0:
            k = n1 * (full // m1)
            ca, cb = table[k % full]
            sa, sb = table[(k - full // 4) % full]
            return sign_a_plus_b_sqrt(u + v * ca + w * sa, v * cb + w * sb, root)
    if u == 0 and v == 0 and w == 0:
        return 0
    import mpmath

    scale = abs(u) + abs(v) + abs(w)
    prec = 128
    while prec <= _MAX_PREC:
        with mpmath.workprec(prec):
            beta = 2 * mpmath.pi * n / m
            val = _mpf(u) + _mpf(v) * mpmath.cos(beta) + _mpf(w) * mpmath.sin(beta)
            err = _mpf(scale) * mpmath.ldexp(1, 8 - prec)
            if abs(val) > err:
                return 1 if val > 0 else -1
        prec *= 2
    raise ArithmeticError(f"cannot separate a boundary test from 0 at {_MAX_PREC} bits")


def exact_floor_pair(x: float, y: float, g: float, cx: float, m: int) -> tuple[int, int] | None:
    """Exact ``(floor(t_lo), floor(t_hi))`` of Eq. 11 for one feature and one eye.

    ``t = (phi_E -/+ asin(g / r_E)) * m / (2*pi)`` with phi_E in (-pi, pi]. Returns None
    when the eye centre lies in the closed disc (the whole eye sees the feature). g = 0 is
    a point: both floors are then Proposition 1's index (Eq. 8).
    """
    X = Fraction(x) - Fraction(cx)
    Y = Fraction(y)
    G = Fraction(g)
    if X * X + Y * Y <= G * G:
        return None
    import mpmath

    # enough bits to hold x - cx exactly, however far apart their exponents are
    prec = max(192, 2 * max(X.numerator.bit_length(), X.denominator.bit_length()))
    while True:
        with mpmath.workprec(prec):
            dx, dy, gg = _mpf(X), _mpf(Y), _mpf(G)
            r = mpmath.hypot(dx, dy)
            q = gg / r
            if q >= 1:  # outside by less than this precision resolves
                prec *= 2
                continue
            phi = mpmath.atan2(dy, dx)
            alpha = mpmath.asin(q)
            k = m / (2 * mpmath.pi)
            t_lo, t_hi = (phi - alpha) * k, (phi + alpha) * k
            eps = mpmath.ldexp(m * (4 + 1 / (1 - q)), 24 - prec)
            if eps < 0.25:
                break
        prec *= 2
    out = []
    for t, upper in ((t_lo, False), (t_hi, True)):
        n = int(mpmath.nint(t))
        if abs(t - n) > eps:
            out.append(int(mpmath.floor(t)))
        else:
            out.append(n if _endpoint_at_or_past(X, Y, G, n, m, upper) else n - 1)
    return out[0], out[1]


def _endpoint_at_or_past(
    X: Fraction, Y: Fraction, G: Fraction, n: int, m: int, upper: bool
) -> bool:
    """Is the tangent direction (upper: phi + alpha, else phi - alpha) >= beta_n?

    With delta = phi - beta_n near -/+alpha (so |delta| < pi), s = r*sin(delta) and
    e = r*cos(delta): phi + alpha >= beta  <=>  s >= 0 or (e >= 0 and s + g >= 0);
    phi - alpha >= beta  <=>  s >= 0 and (e < 0 or s - g >= 0).
    """
    zero = Fraction(0)
    s = sign_linear(zero, Y, -X, n, m)  # s = y cos b - x sin b
    e = sign_linear(zero, X, Y, n, m)  # e = x cos b + y sin b
    if upper:
        return s >= 0 or (e >= 0 and sign_linear(G, Y, -X, n, m) >= 0)
    return s >= 0 and (e < 0 or sign_linear(-G, Y, -X, n, m) >= 0)


def sign_sqrt_times_minus(y: Fraction, W: Fraction, c: Fraction) -> int:
    """Exact sign of ``y*sqrt(W) - c`` for rationals y, c and W >= 0."""
    sy = (y > 0) - (y < 0)
    sc = (c > 0) - (c < 0)
    if W == 0 or sy == 0:
        return -sc
    if sc == 0:
        return sy
    if sy != sc:
        return sy
    diff = y * y * W - c * c
    s = (diff > 0) - (diff < 0)
    return s * sy


def exact_in_bfv(x: float, y: float, g: float, h: float, l: float) -> bool:
    """Proposition 4 in exact arithmetic: the closed disc lies in the BFV wedge.

    The wedge is the intersection of two half-planes through the origin bounded by the
    tangents at angles psi and pi - psi; with w = sqrt(h^2 - l^2) the disc is inside iff
    w*y - l*x >= g*h and w*y + l*x >= g*h (Eq. 17 written without trigonometry).
    """
    X, Y, G, H, Lq = map(Fraction, (x, y, g, h, l))
    W = H * H - Lq * Lq
    return (
        sign_sqrt_times_minus(Y, W, G * H + Lq * X) >= 0
        and sign_sqrt_times_minus(Y, W, G * H - Lq * X) >= 0
    )


def exact_overlaps(x: float, y: float, g: float, cx: float, l: float) -> bool:
    """The closed feature disc meets the closed eye disc: |P - E| <= g + l."""
    X = Fraction(x) - Fraction(cx)
    Y, S = Fraction(y), Fraction(g) + Fraction(l)
    return X * X + Y * Y <= S * S
