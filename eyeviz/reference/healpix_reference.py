"""High-precision reference for the lit sets of the spherical eyes (docs/spherical.md).

An independent, slow implementation used to judge :mod:`eyeviz.core.geometry3d`. It shares
no code with it: pixels are taken apart from the definitions of ang2pix (Gorski et al.
2005, Eq. 4-9) instead of the face coordinates the core uses. Inside the equatorial zone
a pixel is the square jp <= U < jp + 1, jm <= V < jm + 1 of
U = n (1/2 + tt - 3z/4), V = n (1/2 + tt + 3z/4) (tt = 2 phi / pi); in a polar cap it is
the square of U = tp * t, V = (1 - tp) * t with t = n sqrt(3 (1 - |z|)) and tp the
fractional part of tt inside the quadrant; the pixels of rings n and 3n are half of each.
The pixel's edges are the sides of its squares, mapped back to the sphere.

A pixel is lit iff the cap centre maps to it, or the minimum chord^2 from the cap centre
over its edges (dense samples, then golden-section refinement, in mpmath at ``dps``
digits) is below the cap's chord^2 2 (1 - cos alpha); within ``10**-(dps - 20)`` of it
the touch point decides, through ang2pix with every floor within that distance of an
integer taken to be that integer (as :mod:`eyeviz.reference.digits80` does on the plane).
Pixels far from the cap's rim are decided on float64 distances with a margin of 1e-3 in
chord^2, far above any rounding.
"""

from __future__ import annotations

import functools
import math
from fractions import Fraction

import mpmath
import numpy as np

__all__ = ["reference_lit", "pixel_centre"]


def _ring_of(n: int, p: int) -> tuple[int, int, int]:
    """(ring, index in ring, pixels in ring) by counting, no closed forms."""
    ncap = 2 * n * (n - 1)
    if p < ncap:
        i = 1
        while 2 * i * (i + 1) <= p:
            i += 1
        return i, p - 2 * i * (i - 1), 4 * i
    if p < 12 * n * n - ncap:
        k = (p - ncap) // (4 * n)
        return n + k, p - ncap - 4 * n * k, 4 * n
    q = 12 * n * n - 1 - p  # counted from the last pixel
    i = 1
    while 2 * i * (i + 1) <= q:
        i += 1
    first = 12 * n * n - 2 * i * (i + 1)
    return 4 * n - i, p - first, 4 * i


def pixel_centre(n: int, p: int) -> tuple[Fraction, Fraction]:
    """(z, tt) of a pixel centre, exact rationals, tt = 2 phi / pi in [0, 4) (healpy's
    pix2ang)."""
    ring, j, num = _ring_of(n, p)
    if ring < n:
        return 1 - Fraction(ring * ring, 3 * n * n), Fraction(4 * (2 * j + 1), 2 * num)
    if ring > 3 * n:
        k = 4 * n - ring
        return Fraction(k * k, 3 * n * n) - 1, Fraction(4 * (2 * j + 1), 2 * num)
    twice = 2 * j + (1 if (ring - n) % 2 == 0 else 0)
    return Fraction(4 * n - 2 * ring, 3 * n), Fraction(4 * twice, 2 * num)


@functools.lru_cache(maxsize=8)
def _centre_vectors(n: int) -> np.ndarray:
    """Unit vectors (12 n^2, 3) of every pixel centre (from :func:`pixel_centre`), for the
    float screening; computed once per nside."""
    out = np.empty((12 * n * n, 3))
    for p in range(12 * n * n):
        zc, ttc = (float(v) for v in pixel_centre(n, p))
        rc = math.sqrt(max(1 - zc * zc, 0.0))
        out[p] = (rc * math.cos(ttc * math.pi / 2), rc * math.sin(ttc * math.pi / 2), zc)
    return out


def _mpq(q: Fraction):
    return mpmath.mpf(q.numerator) / q.denominator


def _coords(n: int, z, tt):
    """Zone and (U, V, quadrant) of a point: 'eq', or 'n'/'s' polar."""
    if abs(z) <= mpmath.mpf(2) / 3:
        return "eq", n * (0.5 + tt - 0.75 * z), n * (0.5 + tt + 0.75 * z), 0
    q = int(mpmath.floor(tt))
    tp = tt - q
    t = n * mpmath.sqrt(3 * (1 - abs(z)))
    return ("n" if z > 0 else "s"), tp * t, (1 - tp) * t, q


@functools.lru_cache(maxsize=1 << 16)
def _edges(n: int, p: int):
    """The edges of pixel p: (zone, quadrant, fixed is U, fixed value, other from)."""
    ring, _, _ = _ring_of(n, p)
    z, tt = pixel_centre(n, p)
    with mpmath.workdps(30):
        zone, U, V, q = _coords(n, _mpq(z), _mpq(tt))
        jp, jm = int(mpmath.floor(U)), int(mpmath.floor(V))
    full = [(zone, q, True, jp, jm), (zone, q, True, jp + 1, jm)]
    full += [(zone, q, False, jm, jp), (zone, q, False, jm + 1, jp)]
    if ring not in (n, 3 * n):
        return full
    # half polar, half equatorial: the polar square's two sides nearer the pole, and
    # the equatorial square's two sides away from it
    zp = "n" if ring == n else "s"
    with mpmath.workdps(30):
        eps = mpmath.mpf(10) ** -12
        ztop = _mpq(z) + (eps if ring == n else -eps)
        _, Up, Vp, qp = _coords(n, ztop, _mpq(tt))
        pp, pm = int(mpmath.floor(Up)), int(mpmath.floor(Vp))
    polar = [(zp, qp, True, pp, pm), (zp, qp, False, pm, pp)]
    if ring == n:  # equatorial V = jm (W to S) and U = jp + 1 (S to E)
        eq = [("eq", 0, False, jm, jp), ("eq", 0, True, jp + 1, jm)]
    else:  # equatorial U = jp (W to N) and V = jm + 1 (N to E)
        eq = [("eq", 0, True, jp, jm), ("eq", 0, False, jm + 1, jp)]
    return polar + eq


def _point(n: int, edge, t, lib):
    """Unit vector of the point at t in [0, 1] along an edge (lib = math or mpmath)."""
    zone, q, fixed_u, fixed, start = edge
    U, V = (fixed, start + t) if fixed_u else (start + t, fixed)
    pi = lib.pi
    if zone == "eq":
        tt = (U + V) / (2 * n) - 0.5
        z = (V - U) / (1.5 * n)
    else:
        s = U + V
        tp = U / s if s != 0 else 0 * s
        z = 1 - s * s / (3 * n * n)
        if zone == "s":
            z = -z
        tt = q + tp
    rho = lib.sqrt(max(1 - z * z, 0 * z))
    phi = tt * pi / 2
    return (rho * lib.cos(phi), rho * lib.sin(phi), z)


def _points_np(n: int, edge, t: np.ndarray) -> np.ndarray:
    """float64 points (k, 3) along an edge (the screening of :func:`reference_lit`)."""
    zone, q, fixed_u, fixed, start = edge
    U, V = (np.full_like(t, fixed), start + t) if fixed_u else (start + t, np.full_like(t, fixed))
    if zone == "eq":
        tt = (U + V) / (2 * n) - 0.5
        z = (V - U) / (1.5 * n)
    else:
        s = U + V
        tp = np.divide(U, s, out=np.zeros_like(s), where=s != 0)
        z = 1 - s * s / (3 * n * n)
        z = -z if zone == "s" else z
        tt = q + tp
    rho = np.sqrt(np.maximum(1 - z * z, 0.0))
    phi = tt * np.pi / 2
    return np.stack([rho * np.cos(phi), rho * np.sin(phi), z], -1)


def _ang2pix(n: int, v, tol) -> int:
    """ang2pix of an mpmath vector with floors within tol of an integer snapped."""
    x, y, z = v
    r = mpmath.sqrt(x * x + y * y + z * z)
    z = z / r
    if mpmath.sqrt(x * x + y * y) / r <= tol:
        tt = mpmath.mpf(0)
        z = mpmath.mpf(1 if z > 0 else -1)
    else:
        tt = mpmath.atan2(y, x) / (mpmath.pi / 2)
        if tt < 0:
            tt += 4
    snap = _snapper(tol)
    tt = mpmath.mpf(snap(tt) % 4) if abs(tt - mpmath.nint(tt)) <= tol else tt
    za = abs(z)
    if abs(za - mpmath.mpf(2) / 3) <= tol:
        za = mpmath.mpf(2) / 3
    if za <= mpmath.mpf(2) / 3:
        jp = snap(n * (0.5 + tt - 0.75 * z))
        jm = snap(n * (0.5 + tt + 0.75 * z))
        ir = n + 1 + jp - jm
        ip = ((jp + jm - n + (1 - ir % 2) + 1) // 2) % (4 * n)
        return 2 * n * (n - 1) + (ir - 1) * 4 * n + ip
    q = int(mpmath.floor(tt))
    tp = tt - q
    t = n * mpmath.sqrt(3 * (1 - za))
    ir = snap(tp * t) + snap((1 - tp) * t) + 1
    ip = min(snap(tt * ir), 4 * ir - 1)
    return 2 * ir * (ir - 1) + ip if z > 0 else 12 * n * n - 2 * ir * (ir + 1) + ip


def _snapper(tol):
    def snap(v) -> int:
        k = mpmath.nint(v)
        return int(k) if abs(v - k) <= tol else int(mpmath.floor(v))

    return snap


def _golden(f, a, b, iters):
    """(t, f(t)) least of golden-section search on [a, b], and the final bracket."""
    g = (mpmath.sqrt(5) - 1) / 2
    c, d = b - g * (b - a), a + g * (b - a)
    fc, fd = f(c), f(d)
    for _ in range(iters):
        if fc < fd:
            b, d, fd = d, c, fc
            c = b - g * (b - a)
            fc = f(c)
        else:
            a, c, fc = c, d, fd
            d = a + g * (b - a)
            fd = f(d)
    return ((c, fc) if fc < fd else (d, fd)), (a, b)


def _least(f, a, b, dps):
    """The least chord^2 along an edge piece [a, b], to about dps digits.

    Golden section to about 1e-12 in t, then Newton on f' (quadratic convergence: a few
    steps reach dps digits where golden section alone needs 3 dps). A minimum at an end of
    the piece is taken where f' points outwards there; a Newton step beyond an end stops
    at that end. Where Newton meets f'' <= 0, does not settle in 40 steps or ends above
    the coarse value, golden section runs to full precision (3 dps steps), as it always
    did."""
    (t, ft), (lo, hi) = _golden(f, a, b, 60)
    near = (hi - lo) * 4
    if t - a <= near and mpmath.diff(f, a, direction=1) >= 0:
        return a, f(a)
    if b - t <= near and mpmath.diff(f, b, direction=-1) <= 0:
        return b, f(b)
    small = mpmath.mpf(10) ** (-(dps // 2) - 8)
    for _ in range(40):
        d2 = mpmath.diff(f, t, 2)
        if not d2 > 0:
            break
        tn = t - mpmath.diff(f, t) / d2
        if not a <= tn <= b:
            end = b if tn > b else a
            if t == end:  # convex here, and the unconstrained least lies beyond this end
                tn = t
            else:
                tn = end
        if abs(tn - t) <= small:
            fn = f(tn)
            if fn <= ft:
                return tn, fn
            break
        t = tn
    return _golden(f, a, b, 3 * dps)[0]


def _pixel_lit(n, p, c_mp, s2_mp, dps) -> bool:
    tol = mpmath.mpf(10) ** (20 - dps)
    if _ang2pix(n, c_mp, tol) == p:
        return True
    best, best_pt = None, None

    def chord(edge, t):
        v = _point(n, edge, t, mpmath)
        return sum((v[i] - c_mp[i]) ** 2 for i in range(3))

    for edge in _edges(n, p):
        k = 24
        ts = [mpmath.mpf(i) / k for i in range(k + 1)]
        fs = [chord(edge, t) for t in ts]
        order = sorted(range(k + 1), key=lambda i: fs[i])[:3]
        cands = [(ts[i], fs[i]) for i in order]
        for i in order:
            a, b = ts[max(i - 1, 0)], ts[min(i + 1, k)]
            cands.append(_least(lambda t, e=edge: chord(e, t), a, b, dps))
        for t, f in cands:
            if best is None or f < best:
                best, best_pt = f, (edge, t)
    assert best is not None and best_pt is not None
    if best < s2_mp - tol:
        return True
    if best > s2_mp + tol:
        return False
    edge, t = best_pt
    if t < tol**0.3:
        t = mpmath.mpf(0)
    elif t > 1 - tol**0.3:
        t = mpmath.mpf(1)
    return _ang2pix(n, _point(n, edge, t, mpmath), tol**0.3) == p


def reference_lit(
    nside: int, x: float, y: float, z: float, g: float, cx: float, dps: int = 50
) -> np.ndarray:
    """Sorted RING indices lit in the eye centred at (cx, 0, 0) by the ball (x, y, z, g)."""
    n = int(nside)
    X = Fraction(x) - Fraction(cx)
    Y, Z, G = Fraction(y), Fraction(z), Fraction(g)
    if X * X + Y * Y + Z * Z <= G * G:
        return np.arange(12 * n * n, dtype=np.int64)
    bits = max(max(abs(q.numerator).bit_length(), q.denominator.bit_length()) for q in (X, Y, Z))
    dps = dps + int(bits * 0.302)
    # tiny caps: enough digits to resolve chord^2 ~ (g / |d|)^2 as well
    ratio = G * G / (X * X + Y * Y + Z * Z)
    dps += max(0, int(math.log10(ratio.denominator) - math.log10(ratio.numerator)))
    # float screening: chord^2 of the pixel centres and dense edge samples
    k = max(abs(X), abs(Y), abs(Z))  # > 0: the eye centre is not in the ball
    dv = np.array([float(X / k), float(Y / k), float(Z / k)])
    c = dv / np.linalg.norm(dv)
    q = float(G / k) / float(np.linalg.norm(dv))
    s2 = 2 * q * q / (1 + math.sqrt(max(1 - q * q, 0.0)))
    alpha = math.asin(min(q, 1.0))
    out = []
    with mpmath.workdps(dps):
        mp = [mpmath.mpf(v.numerator) / v.denominator for v in (X, Y, Z, G)]
        dd = mpmath.sqrt(mp[0] ** 2 + mp[1] ** 2 + mp[2] ** 2)
        c_mp = (mp[0] / dd, mp[1] / dd, mp[2] / dd)
        qq = mp[3] / dd
        s2_mp = 2 * qq * qq / (1 + mpmath.sqrt(1 - qq * qq))
        own = _ang2pix(n, c_mp, mpmath.mpf(10) ** (20 - dps))  # the pixel of the centre
        fcs = ((_centre_vectors(n) - c) ** 2).sum(axis=1)
        for p in range(12 * n * n):
            if p == own:
                out.append(p)
                continue
            fc = float(fcs[p])
            if fc < s2 - 1e-3:
                out.append(p)  # the centre, an interior point, is well inside the cap
                continue
            if 2 * math.asin(min(1.0, math.sqrt(fc) / 2)) > alpha + 2.5 / n:
                continue  # no pixel reaches further than 2.5 / nside from its centre
            ts = np.linspace(0.0, 1.0, 65)
            fmin = min(float(((_points_np(n, e, ts) - c) ** 2).sum(1).min()) for e in _edges(n, p))
            if fmin < s2 - 1e-3:
                out.append(p)
            elif fmin > s2 + 1e-3:
                continue
            elif _pixel_lit(n, p, c_mp, s2_mp, dps):
                out.append(p)
    return np.array(out, dtype=np.int64)
