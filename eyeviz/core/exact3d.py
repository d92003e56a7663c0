"""The high-precision fallback of the spherical lit sets (:mod:`eyeviz.core.geometry3d`).

The float64 fast path hands over the few (ball, cell) pairs whose answer lies within its
rounding bound. Inputs are the exact rationals the floats denote (d = ball centre - eye
centre taken exactly). A cell is lit iff the closed cap of chord^2 radius
s2 = 2 (1 - cos(alpha)) about c = d / |d| meets the cell (docs/spherical.md):

* c maps to the cell: lit;
* some point of the cell's closure has chord^2 < s2: lit (a point of the cap's interior
  near a point of the closure of the cell's interior);
* every point of the closure has chord^2 > s2: not lit;
* else the cap touches the closure (a tie): lit iff the touch point maps to the cell
  under ang2pix, evaluated with the floors snapped to the integers the touch point lies on.

Edges are the face lines x = const, y = const of :func:`eyeviz.core.healpix.xyf2vec`;
each edge is sampled and its minimum refined by golden-section search in mpmath at
rising precision; sub-intervals are excluded with the same second-derivative bound as the
fast path. The ties list of docs/spherical.md says which ties are decided by this rule
with a proof and which rest on the snapping.
"""

from __future__ import annotations

from fractions import Fraction

import mpmath

from eyeviz.core import healpix

__all__ = ["cell_lit", "ang2pix_snap", "edge_bound", "whole_eye"]

_JRLL = [int(v) for v in healpix.JRLL]
_JPLL = [int(v) for v in healpix.JPLL]
_SAMPLES = 16
_PRECS = (96, 256)
#: A cap of chord below 2^-(_TINY_BITS + the inputs' bits) is decided as one of that size
_TINY_BITS = 96


def whole_eye(X: Fraction, Y: Fraction, Z: Fraction, G: Fraction) -> bool:
    """The eye centre lies in the closed ball: every facet is lit."""
    return X * X + Y * Y + Z * Z <= G * G


def edge_bound(n: int, face: int, fixed_is_y: bool, fixed: float, lo: float) -> float:
    """Bound of |d^2 P / dt^2| along one pixel edge, t in [0, 1] (docs/spherical.md).

    The edge is ``y = fixed`` (x from lo to lo + 1) or ``x = fixed``, in pixel units.
    Equatorial regime: 2 / n^2. Polar caps: (2 + 7.2 a / nr_min^2) / n^2 with nr the
    distance from the pole in face units and a the edge's distance from the face's
    polar meridians (0 on a meridian, where the edge is a great circle).
    """
    fx = fixed / n
    lo_f, hi_f = lo / n, (lo + 1) / n
    if face < 4:
        a = 1.0 - fx
        nr_min = 2.0 - fx - hi_f
    elif face >= 8:
        a = fx
        nr_min = fx + lo_f
    else:
        return 2.0 / (n * n)
    if nr_min >= 1.0 or a <= 0.0:
        return 2.0 / (n * n)
    return (2.0 + 7.2 * a / (nr_min * nr_min)) / (n * n)


def _vec(n: int, x, y, face: int):
    """mpmath unit vector of the face point (x, y) in pixel units (healpy's xyf2loc)."""
    fx = x / n
    fy = y / n
    jr = _JRLL[face] - fx - fy
    if jr < 1:
        nr = jr
        z = 1 - nr * nr / 3
        sth = nr * mpmath.sqrt((2 - nr * nr / 3) / 3)
    elif jr > 3:
        nr = 4 - jr
        z = nr * nr / 3 - 1
        sth = nr * mpmath.sqrt((2 - nr * nr / 3) / 3)
    else:
        nr = mpmath.mpf(1)
        z = (2 - jr) * 2 / mpmath.mpf(3)
        sth = mpmath.sqrt(1 - z * z)
    if nr == 0:
        return (mpmath.mpf(0), mpmath.mpf(0), z)
    phi = mpmath.pi / 4 * (_JPLL[face] * nr + fx - fy) / nr
    return (sth * mpmath.cos(phi), sth * mpmath.sin(phi), z)


def _snap_floor(v, tol) -> int:
    r = mpmath.nint(v)
    if abs(v - r) <= tol:
        return int(r)
    return int(mpmath.floor(v))


def ang2pix_snap(n: int, v, tol) -> int:
    """ang2pix of the mpmath vector v, every floor within ``tol`` of an integer snapped.

    A point at the pole (sin(theta) within tol of 0) has longitude 0 (atan2(0, 0) = 0).
    """
    x, y, z = v
    r = mpmath.sqrt(x * x + y * y + z * z)
    zz = z / r
    rho = mpmath.sqrt(x * x + y * y) / r
    if rho <= tol:
        tt = mpmath.mpf(0)
        zz = mpmath.mpf(1) if zz > 0 else mpmath.mpf(-1)
    else:
        tt = mpmath.atan2(y, x) * 2 / mpmath.pi
        if tt < 0:
            tt += 4
        k = mpmath.nint(tt)
        if abs(tt - k) <= tol:
            tt = mpmath.mpf(int(k) % 4)
    za = abs(zz)
    if abs(za - mpmath.mpf(2) / 3) <= tol:
        za = mpmath.mpf(2) / 3
    if za <= mpmath.mpf(2) / 3:
        t1 = n * (mpmath.mpf(1) / 2 + tt)
        t2 = n * zz * 3 / 4
        jp = _snap_floor(t1 - t2, tol)
        jm = _snap_floor(t1 + t2, tol)
        ir = n + 1 + jp - jm
        kshift = 1 - (ir & 1)
        ip = ((jp + jm - n + kshift + 1 + 8 * n) >> 1) % (4 * n)
        return 2 * n * (n - 1) + (ir - 1) * 4 * n + ip
    tfl = int(mpmath.floor(tt))
    tp = tt - tfl
    tmp = n * mpmath.sqrt(3 * (1 - za))
    jp = _snap_floor(tp * tmp, tol)
    jm = _snap_floor((1 - tp) * tmp, tol)
    ir = jp + jm + 1
    ip = min(_snap_floor(tt * ir, tol), 4 * ir - 1)
    if zz > 0:
        return 2 * ir * (ir - 1) + ip
    return 12 * n * n - 2 * ir * (ir + 1) + ip


def _edges(ix: int, iy: int):
    """The four edges of pixel (ix, iy): (fixed_is_y, fixed, lo) in pixel units."""
    return ((True, iy + 1, ix), (False, ix, iy), (True, iy, ix), (False, ix + 1, iy))


def _point(n, face, edge, t):
    fixed_is_y, fixed, lo = edge
    if fixed_is_y:
        return _vec(n, lo + t, mpmath.mpf(fixed), face)
    return _vec(n, mpmath.mpf(fixed), lo + t, face)


def _chord2(p, c):
    return (p[0] - c[0]) ** 2 + (p[1] - c[1]) ** 2 + (p[2] - c[2]) ** 2


def _minimise(fun, a, b, prec):
    """(t, f) near the minimum of ``fun`` on [a, b]: golden section to bracket it, then
    Newton steps on finite differences (quadratic convergence at a smooth minimum).
    Returns the best point evaluated; an endpoint minimum is left to the samples."""
    gr = (mpmath.sqrt(5) - 1) / 2
    c, d = b - gr * (b - a), a + gr * (b - a)
    fc, fd = fun(c), fun(d)
    for _ in range(24):
        if fc < fd:
            b, d, fd = d, c, fc
            c = b - gr * (b - a)
            fc = fun(c)
        else:
            a, c, fc = c, d, fd
            d = a + gr * (b - a)
            fd = fun(d)
    t, f = (c, fc) if fc < fd else (d, fd)
    h = mpmath.ldexp(1, -prec // 3)
    for _ in range(8):
        fp, fm = fun(t + h), fun(t - h)
        d2 = fp - 2 * f + fm
        if d2 <= 0:
            break
        step = (fp - fm) * h / (2 * d2)
        tn = min(max(t - step, a), b)
        fn = fun(tn)
        if fn >= f:
            break
        t, f = tn, fn
        if abs(step) < h:
            break
    return t, f


def _decide(n, X, Y, Z, G, face, ix, iy, pix, prec):
    """True / False when decided at this precision, else the touch point (a tie)."""
    mp = mpmath.mpf
    X_, Y_, Z_, G_ = (mp(q.numerator) / q.denominator for q in (X, Y, Z, G))
    d = mpmath.sqrt(X_ * X_ + Y_ * Y_ + Z_ * Z_)
    c = (X_ / d, Y_ / d, Z_ / d)
    q = G_ / d
    s2 = 2 * q * q / (1 + mpmath.sqrt((1 - q) * (1 + q)))
    eps = mpmath.ldexp(1, 24 - prec)
    tol_snap = mpmath.ldexp(1, -prec // 3)
    if ang2pix_snap(n, c, eps) == pix:
        return True
    best, best_pt = None, None
    for edge in _edges(ix, iy):
        bound = 2.5 * edge_bound(n, face, edge[0], float(edge[1]), float(edge[2]))
        slack = mp(bound) / (8 * _SAMPLES * _SAMPLES)
        ts = [mp(k) / _SAMPLES for k in range(_SAMPLES + 1)]
        fs = [_chord2(_point(n, face, edge, t), c) for t in ts]
        for k in range(_SAMPLES + 1):
            if best is None or fs[k] < best:
                best, best_pt = fs[k], (edge, ts[k])
        if best < s2 - eps:
            return True
        for k in range(_SAMPLES):
            if min(fs[k], fs[k + 1]) - slack > s2 + eps:
                continue  # proven clear: the bound holds on the whole sub-interval
            t, f = _minimise(
                lambda t, e=edge: _chord2(_point(n, face, e, t), c), ts[k], ts[k + 1], prec
            )
            if f < best:
                best, best_pt = f, (edge, t)
            if f < s2 - eps:
                return True
    if best > s2 + eps:
        return False
    assert best_pt is not None  # set at the first sample of the first edge
    edge, t = best_pt
    if t <= tol_snap:
        t = mp(0)
    elif t >= 1 - tol_snap:
        t = mp(1)
    return ("tie", _point(n, face, edge, t), tol_snap)


def cell_lit(
    n: int,
    X: Fraction,
    Y: Fraction,
    Z: Fraction,
    G: Fraction,
    face: int,
    ix: int,
    iy: int,
    pix: int,
) -> bool:
    """Whether the closed cap of the ball (X, Y, Z, G) about the eye centre meets pixel
    ``pix`` = (face, ix, iy) of nside n under exact ang2pix (see the module docstring)."""
    if whole_eye(X, Y, Z, G):
        return True
    res = None
    # enough bits for the inputs' spread of exponents and for a cap of chord^2 ~ q^2
    bits = max(max(abs(v.numerator).bit_length(), v.denominator.bit_length()) for v in (X, Y, Z))
    ratio = G * G / (X * X + Y * Y + Z * Z)
    floor = _TINY_BITS + bits
    lr = ratio.numerator.bit_length() - ratio.denominator.bit_length()  # log2(ratio) +- 1
    if lr < -2 * floor - 2:
        # a cap far below a facet lights the cells whose closure holds its centre: any
        # smaller cap lights the same as one of chord ~ 2^-floor (docs/spherical.md)
        shift = (-2 * floor - 1 - lr) // 2
        G = G * 2**shift
        ratio = ratio * 4**shift
    scale = max(0, ratio.denominator.bit_length() - ratio.numerator.bit_length())
    extra = max(0, 2 * bits - 128) + 3 * scale
    for base in _PRECS:
        prec = base + extra
        with mpmath.workprec(prec):
            res = _decide(n, X, Y, Z, G, face, ix, iy, pix, prec)
            if isinstance(res, bool):
                return res
            _, point, tol = res
            if base == _PRECS[-1]:
                return ang2pix_snap(n, point, tol) == pix
    raise AssertionError("unreachable")  # pragma: no cover
