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

import numpy as np

#: cos(30k deg) = a + b*sqrt(3), k = 0..11, as (a, b)
_COS30: list[tuple[int | Fraction, int | Fraction]] = [
    (1, 0), (0, Fraction(1, 2)), (Fraction(1, 2), 0), (0, 0),
    (Fraction(-1, 2), 0), (0, Fraction(-1, 2)), (-1, 0), (0, Fraction(-1, 2)),
    (Fraction(-1, 2), 0), (0, 0), (Fraction(1, 2), 0), (0, Fraction(1, 2)),
]  # fmt: skip
#: cos(45k deg) = a + b*sqrt(2), k = 0..7, as (a, b)
_COS45: list[tuple[int | Fraction, int | Fraction]] = [
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

    # enough bits to hold x - cx exactly, however far apart their exponents are; every
    # mpmath operation, rounding included, runs inside workprec: the caller's global
    # mpmath.mp.prec never matters
    prec = max(192, 2 * max(X.numerator.bit_length(), X.denominator.bit_length()))
    while True:
        with mpmath.workprec(prec):
            floors = _floors_at(X, Y, G, m, prec)
        if floors is not None:
            lo, hi = floors
            break
        prec *= 2
    out = []
    for (n, t_floor), upper in ((lo, False), (hi, True)):
        if t_floor is not None:
            out.append(t_floor)
        else:
            out.append(n if _endpoint_at_or_past(X, Y, G, n, m, upper) else n - 1)
    return out[0], out[1]


def _floors_at(X: Fraction, Y: Fraction, G: Fraction, m: int, prec: int):
    """Inside a workprec(prec) block: per endpoint (n, floor) with floor None when the
    value lies within the error bound of the integer n; None when prec is too small."""
    import mpmath

    dx, dy, gg = _mpf(X), _mpf(Y), _mpf(G)
    r = mpmath.hypot(dx, dy)
    q = gg / r
    if q >= 1:  # outside by less than this precision resolves
        return None
    phi = mpmath.atan2(dy, dx)
    alpha = mpmath.asin(q)
    k = m / (2 * mpmath.pi)
    eps = mpmath.ldexp(m * (4 + 1 / (1 - q)), 24 - prec)
    if not eps < 0.25:
        return None
    res = []
    for t in ((phi - alpha) * k, (phi + alpha) * k):
        n = int(mpmath.nint(t))
        res.append((n, int(mpmath.floor(t)) if abs(t - n) > eps else None))
    return res


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


# --- vectorised ties: floating-point expansions instead of mpmath ------------------------
#
# On a boundary beta_n at a multiple of 30 or 45 degrees, 2*cos(beta_n) and 2*sin(beta_n)
# are A + B*sqrt(k) with integers A, B in -2..2 (k = 3 or 2). Every test of
# :func:`_endpoint_at_or_past` then is the sign of a + b*sqrt(k) where 2a and 2b are sums
# of at most four floats (x - cx split exactly by two-sum, times 0, +-1 or +-2: exact).
# Those sums' signs are exact from a nonoverlapping expansion (Shewchuk's GROW-EXPANSION);
# a + b*sqrt(k) with b != 0 is never 0 (sqrt(k) is irrational), so when the signs of a and
# b differ, |a| against |b|*sqrt(k) is decided in floats with a wide relative margin and
# only the undecidable rest (near-ties in Q(sqrt k), magnitudes near the ends of the float
# range) is decided in exact rationals, element by element.

#: doubled cos(30 j deg), j = 0..11, as (rational, sqrt 3) integer parts
_COS30_2 = np.array([(2, 0), (0, 1), (1, 0), (0, 0), (-1, 0), (0, -1),
                     (-2, 0), (0, -1), (-1, 0), (0, 0), (1, 0), (0, 1)], np.float64)  # fmt: skip
#: doubled cos(45 j deg), j = 0..7, as (rational, sqrt 2) integer parts
_COS45_2 = np.array([(2, 0), (0, 1), (0, 0), (0, -1),
                     (-2, 0), (0, -1), (0, 0), (0, 1)], np.float64)  # fmt: skip
_SAFE_MAG = 2.0**1000  # doubling and two-sum cannot overflow below this
_TINY = 2.0**-960  # below this a product b*sqrt(k) may lose relative accuracy
_UNKNOWN = 2


def _two_sum(a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Knuth's error-free sum: s + e == a + b exactly, s = fl(a + b)."""
    s = a + b
    bb = s - a
    e = (a - (s - bb)) + (b - bb)
    return s, e


def _expansion(terms: list[np.ndarray]) -> list[np.ndarray]:
    """Nonoverlapping expansion (increasing magnitude, zeros allowed) of a sum of floats."""
    e: list[np.ndarray] = []
    for t in terms:
        q, grown = t, []
        for comp in e:
            q, h = _two_sum(q, comp)
            grown.append(h)
        grown.append(q)
        e = grown
    return e


def _sign_of(e: list[np.ndarray]) -> np.ndarray:
    """Exact sign of an expansion: the sign of its largest nonzero component."""
    s = np.zeros(e[0].shape, np.int8)
    for comp in reversed(e):
        s = np.where(s == 0, np.sign(comp).astype(np.int8), s)
    return s


def _sign_quadratic(a_terms, b_terms, root: np.ndarray) -> np.ndarray:
    """Sign of a + b*sqrt(root) (a, b sums of floats); ``_UNKNOWN`` where undecided."""
    ea = _expansion(a_terms)
    sa = _sign_of(ea)
    if not any(t.any() for t in b_terms):  # rational boundaries (multiples of 90 degrees)
        return sa
    eb = _expansion(b_terms)
    sb = _sign_of(eb)
    out = np.where(sb == 0, sa, np.where((sa == 0) | (sa == sb), sb, 0)).astype(np.int8)
    mixed = (sa != 0) & (sb != 0) & (sa != sb)
    if mixed.any():
        A = np.abs(sum(ea))  # relative error a few ulps: the margin below is 2^-40
        B = np.abs(sum(eb)) * np.sqrt(root)
        big_a = A > B * (1 + 2.0**-40)
        big_b = B > A * (1 + 2.0**-40)
        ok = (A > _TINY) & (B > _TINY) & (big_a | big_b)
        out[mixed] = np.where(ok, np.where(big_a, sa, sb), _UNKNOWN)[mixed]
    return out


def ties_at_or_past(x, y, g, cx: float, n, m: int, upper) -> np.ndarray:
    """Vectorised :func:`_endpoint_at_or_past` on boundaries at 30 or 45 degree multiples.

    Arrays x, y, g (floats), n (int64 boundary indices), upper (bool). Returns int8:
    1 if the tangent direction is at or past beta_n, 0 if before, -1 for boundaries at other
    angles (use the scalar path). The rare elements the expansions leave undecided are
    decided here in exact rationals (no mpmath).
    """
    n = np.asarray(n, np.int64)
    x, y, g = (np.asarray(v, np.float64) for v in (x, y, g))
    is30 = (12 * n) % m == 0
    is45 = ~is30 & ((8 * n) % m == 0)
    j30 = ((12 * n) // m) % 12
    j45 = ((8 * n) // m) % 8
    cos2 = np.where(is30[:, None], _COS30_2[j30], _COS45_2[j45])
    sin2 = np.where(is30[:, None], _COS30_2[(j30 - 3) % 12], _COS45_2[(j45 - 2) % 8])
    root = np.where(is30, 3.0, 2.0)
    mag = np.maximum(np.maximum(np.abs(x), abs(cx)), np.maximum(np.abs(y), np.abs(g)))
    usable = (is30 | is45) & (mag < _SAFE_MAG)
    xh, xl = _two_sum(x, np.full_like(x, -cx))
    ca, cb, sa, sb = cos2[:, 0], cos2[:, 1], sin2[:, 0], sin2[:, 1]
    # s = y cos - x sin ; e = x cos + y sin ; s -/+ g  (all doubled)
    s_b = [y * cb, -xh * sb, -xl * sb]
    s = _sign_quadratic([y * ca, -xh * sa, -xl * sa], s_b, root)
    e = _sign_quadratic([xh * ca, xl * ca, y * sa], [xh * cb, xl * cb, y * sb], root)
    gs = np.where(upper, 2 * g, -2 * g)
    sg = _sign_quadratic([gs, y * ca, -xh * sa, -xl * sa], s_b, root)
    known = usable & (s != _UNKNOWN) & (e != _UNKNOWN) & (sg != _UNKNOWN)
    up = (s >= 0) | ((e >= 0) & (sg >= 0))
    lo = (s >= 0) & ((e < 0) | (sg >= 0))
    res = np.where(upper, up, lo).astype(np.int8)
    res[~(is30 | is45)] = -1
    # what the floats could not decide (near-ties in Q(sqrt k), magnitudes near the ends of
    # the float range): the same predicate in exact rationals, one element at a time
    upper = np.broadcast_to(upper, n.shape)
    for i in np.flatnonzero((is30 | is45) & ~known):
        X = Fraction(float(x[i])) - Fraction(cx)
        res[i] = _endpoint_at_or_past(X, Fraction(float(y[i])), Fraction(float(g[i])),
                                      int(n[i]), m, bool(upper[i]))  # fmt: skip
    return res
