"""Graded responses of one acceptance cap to one ball's cap: pure functions on arrays.

A facet whose acceptance is the cap of half-angle ``a`` about its axis u, and a ball whose
directions from the lens form the cap of angular radius ``b`` about w, with
``theta = angle(u, w)`` (docs/responses.md). All angles in radians, arrays broadcast.

* ``flat``: the acceptance is uniform over its cap; the response is the area of the
  intersection of the two caps over the acceptance cap's area, in closed form
  (:func:`lens_area`; the two circular segments cut off by the caps' common chord).
* ``gaussian``: the acceptance weights a direction at angle psi from the axis by
  K(psi) = exp(-psi^2 / (2 sigma^2)) with sigma = FWHM / (2 sqrt(2 ln 2)), FWHM = 2a: the
  half maximum falls on the cap's edge. Two normalisations (:func:`gaussian_response`):
  ``support="cone"`` (the eye models' kind: K restricted to the acceptance cap and
  normalised over it, so the response is the covered share of the cap's weight, > 0
  exactly where the caps meet) and ``support="sphere"`` (K over the whole sphere,
  normalised over the sphere: the acceptance function renderers sample; it never
  vanishes). The integral of K over a region R not holding -u is the flux of
  F = G(psi) / sin(psi) e_psi, G(psi) = int_0^psi K(t) sin t dt, through R's boundary
  (div F = K): an arc of the ball's circle, integrated by Gauss-Legendre in its angle
  (an analytic, non-periodic integrand with no end-point singularity), plus, where the
  acceptance cap cuts the ball, an arc of the cap's edge, G(a) times its length in
  azimuth (closed form).
"""

from __future__ import annotations

import math

import numpy as np

__all__ = [
    "FWHM_TO_SIGMA",
    "cap_area",
    "lens_area",
    "flat_response",
    "gaussian_mass",
    "gaussian_response",
    "kernel_G",
]

#: sigma = FWHM * FWHM_TO_SIGMA, 1 / (2 sqrt(2 ln 2)).
FWHM_TO_SIGMA = 1.0 / (2.0 * math.sqrt(2.0 * math.log(2.0)))
_SERIES_TERMS = 28  # G's power series below psi / sigma = _SERIES_MAX: terms < 1e-19
_SERIES_MAX = 1.6
_NODES = 32  # Gauss-Legendre nodes on an arc; the estimate compares with _NODES // 2
_TOL = 1e-12  # the a-posteriori error estimate each arc must meet (else it is split)


def cap_area(r) -> np.ndarray:
    """Area of a spherical cap of angular radius r: 2 pi (1 - cos r) = 4 pi sin^2(r/2)."""
    s = np.sin(np.asarray(r, dtype=np.float64) / 2)
    return 4 * math.pi * s * s


def _half_angles(a, b, theta) -> tuple[np.ndarray, np.ndarray]:
    """In the spherical triangle of sides a (u-P), b (w-P), theta (u-w): the angles at u
    and at w, by the half-angle formulas (stable at both ends, unlike arccos)."""
    s = (a + b + theta) / 2
    sa, sb, st, ss = np.sin(s - a), np.sin(s - b), np.sin(s - theta), np.sin(s)
    with np.errstate(divide="ignore", invalid="ignore"):
        at_u = 2 * np.arctan(np.sqrt(np.maximum(sa * st, 0) / (ss * sb)))
        at_w = 2 * np.arctan(np.sqrt(np.maximum(sb * st, 0) / (ss * sa)))
    return at_u, at_w


def _segment(r, phi) -> np.ndarray:
    """Area of the part of a cap of radius r beyond the great-circle chord whose ends are
    seen from the cap's centre at +-phi: the sector 2 phi (1 - cos r) less the spherical
    triangle (centre, chord ends) of sides r, r and angle 2 phi, whose excess E has
    tan(E / 2) = t^2 sin(2 phi) / (1 + t^2 cos(2 phi)), t = tan(r / 2) (signed: for
    phi > pi / 2 the triangle is added)."""
    t2 = np.tan(r / 2) ** 2
    sector = 2 * phi * (2 * np.sin(r / 2) ** 2)
    return sector - 2 * np.arctan2(t2 * np.sin(2 * phi), 1 + t2 * np.cos(2 * phi))


def lens_area(a, b, theta) -> np.ndarray:
    """Area of the intersection of caps of radii a, b in (0, pi] whose centres are theta
    apart (theta in [0, pi]): 0 when theta >= a + b, the smaller cap when
    theta <= |a - b|, both caps less the sphere when a + b + theta >= 2 pi, else the two
    circular segments on either side of the common chord (closed form; a cap beyond a
    hemisphere through its complement, cap(a) - lens(a, pi - b, pi - theta))."""
    a, b, theta = np.broadcast_arrays(*(np.asarray(v, dtype=np.float64) for v in (a, b, theta)))
    out = np.zeros(a.shape)
    inner = theta <= np.abs(a - b)
    out[inner] = cap_area(np.minimum(a, b)[inner])
    wrap = ~inner & (a + b + theta >= 2 * math.pi)
    out[wrap] = cap_area(a[wrap]) + cap_area(b[wrap]) - 4 * math.pi
    mid = ~inner & ~wrap & (theta < a + b)
    big_b = mid & (b > math.pi / 2)
    if big_b.any():
        ab, bb, tb = a[big_b], b[big_b], theta[big_b]
        out[big_b] = cap_area(ab) - lens_area(ab, math.pi - bb, math.pi - tb)
    big_a = mid & ~big_b & (a > math.pi / 2)
    if big_a.any():
        ab, bb, tb = a[big_a], b[big_a], theta[big_a]
        out[big_a] = cap_area(bb) - lens_area(math.pi - ab, bb, math.pi - tb)
    mid &= ~big_a & ~big_b
    if mid.any():
        am, bm, tm = a[mid], b[mid], theta[mid]
        phi_a, phi_b = _half_angles(am, bm, tm)
        out[mid] = _segment(am, phi_a) + _segment(bm, phi_b)
    return np.clip(out, 0.0, None)


def flat_response(a, b, theta) -> np.ndarray:
    """The share of the acceptance cap (radius a) inside the ball's cap (radius b, centre
    theta away; b = pi for a ball holding the lens): lens_area / cap_area(a), in [0, 1]."""
    a = np.asarray(a, dtype=np.float64)
    return np.clip(lens_area(a, b, theta) / cap_area(a), 0.0, 1.0)


def _series_coefficients(sigma: np.ndarray) -> np.ndarray:
    """c_n with G(psi) = sum_n c_n psi^(2n+2): the product of the series of
    exp(-t^2 / (2 sigma^2)) and sin t, integrated; every term of c_n has sign (-1)^n."""
    n = _SERIES_TERMS
    e = np.empty((n,) + sigma.shape)
    s = np.empty(n)
    inv = 1.0 / (2 * sigma * sigma)
    e[0] = 1.0
    s[0] = 1.0
    for j in range(1, n):
        e[j] = -e[j - 1] * inv / j
        s[j] = -s[j - 1] / ((2 * j) * (2 * j + 1))
    c = np.zeros((n,) + sigma.shape)
    for k in range(n):
        c[k:] += e[: n - k] * s[k]
    return c / (2 * np.arange(n) + 2).reshape((n,) + (1,) * sigma.ndim)


def kernel_G(psi, sigma) -> np.ndarray:
    """G(psi) = int_0^psi exp(-t^2 / (2 sigma^2)) sin t dt, psi in [0, pi], sigma of
    shape psi.shape[:1] (one per row) or psi's shape: the power series (relative
    accuracy near 0) where psi / sigma <= 1.6, else the closed form
    Im[exp(-sigma^2/2) sigma sqrt(pi/2) (erf((psi - i sigma^2) / (sigma sqrt 2))
    - erf(-i sigma / sqrt 2))] (scipy's complex erf)."""
    psi = np.asarray(psi, np.float64)
    sigma = np.asarray(sigma, np.float64)
    rows = sigma.ndim < psi.ndim
    full = (
        np.broadcast_to(sigma.reshape(sigma.shape + (1,) * (psi.ndim - sigma.ndim)), psi.shape)
        if rows
        else sigma
    )
    out = np.empty(psi.shape)
    small = psi <= _SERIES_MAX * full
    if small.all() and rows:  # the acceptance cap's arcs: one coefficient table per row
        uniq, inv = np.unique(sigma, return_inverse=True)
        c = _series_coefficients(uniq)[:, inv.reshape(sigma.shape)]
        p2 = psi * psi
        acc = np.zeros(p2.shape)
        extra = (slice(None),) * sigma.ndim + (None,) * (psi.ndim - sigma.ndim)
        for k in range(_SERIES_TERMS - 1, -1, -1):
            acc *= p2
            acc += c[k][extra]
        return acc * p2
    sigma = full
    if small.any():
        sg = sigma[small]
        uniq, inv = np.unique(sg, return_inverse=True)
        c = _series_coefficients(uniq)
        p2 = psi[small] ** 2
        acc = np.zeros(p2.shape)
        for k in range(_SERIES_TERMS - 1, -1, -1):
            acc *= p2
            acc += c[k][inv]
        out[small] = acc * p2
    big = ~small
    if big.any():
        sg, ps = sigma[big], psi[big]
        r2 = math.sqrt(2.0)
        z1 = (ps - 1j * sg * sg) / (sg * r2)
        z0 = -1j * sg / r2
        scale = np.exp(-sg * sg / 2) * sg * math.sqrt(math.pi / 2)
        from scipy import special  # here: importing scipy.special costs an app start 0.2 s

        val = scale * (special.erf(z1) - special.erf(z0))
        out[big] = val.imag
    return out


def gaussian_mass(a, support: str = "cone") -> np.ndarray:
    """The normaliser: 2 pi G(a) (``cone``, the kernel of FWHM 2a over the acceptance cap)
    or 2 pi G(pi) (``sphere``)."""
    a = np.asarray(a, dtype=np.float64)
    sigma = 2 * a * FWHM_TO_SIGMA
    top = a if support == "cone" else np.full(a.shape, math.pi)
    return 2 * math.pi * kernel_G(top, sigma)


def _arc_flux(b, theta, sigma, lo, hi, nodes: int) -> np.ndarray:
    """Flux of F out of the ball's cap through its circle (radius b about w), over the
    angle mu in [lo, hi] measured at w from the great circle towards u:
    sin b int G(psi) (sin b cos theta - cos b sin theta cos mu) / sin^2 psi dmu."""
    x, wts = np.polynomial.legendre.leggauss(nodes)
    mid, half = (lo + hi) / 2, (hi - lo) / 2
    mu = mid[..., None] + half[..., None] * x
    sb, cb = np.sin(b)[..., None], np.cos(b)[..., None]
    st, ct = np.sin(theta)[..., None], np.cos(theta)[..., None]
    cm = np.cos(mu)
    px = sb * ct * cm - cb * st  # the point of the circle, u = (0, 0, 1), w in the xz plane
    py = sb * np.sin(mu)
    pz = cb * ct + sb * st * cm
    s2 = px * px + py * py
    psi = np.arctan2(np.sqrt(s2), pz)
    gs = kernel_G(psi, sigma)
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(s2 > 0, gs / s2, 0.5)  # G / sin^2 -> K(0) / 2 = 1/2 at u
    f = ratio * (sb * ct - cb * st * cm)
    return np.sin(b) * half * (f @ wts)


def _ball_flux(b, theta, sigma, top) -> np.ndarray:
    """2 x the flux over mu in [0, top] (the integrand is even in mu), by Gauss-Legendre
    on 1, 2, 4, ... equal pieces until two rules (_NODES and _NODES // 2 nodes) agree
    within _TOL on every piece sum (an a-posteriori estimate; ArithmeticError if 64
    pieces do not)."""
    out = np.zeros(b.shape)
    todo = np.arange(b.size)
    pieces = 1
    while todo.size:
        bt, tt, st, wt = b[todo], theta[todo], sigma[todo], top[todo] / pieces
        fine = np.zeros(todo.size)
        coarse = np.zeros(todo.size)
        for k in range(pieces):
            lo, hi = wt * k, wt * (k + 1)
            fine += _arc_flux(bt, tt, st, lo, hi, _NODES)
            coarse += _arc_flux(bt, tt, st, lo, hi, _NODES // 2)
        out[todo] = 2 * fine
        todo = todo[2 * np.abs(fine - coarse) > _TOL]
        pieces *= 2
        if todo.size and pieces > 64:
            raise ArithmeticError(
                f"graded response: {todo.size} arc(s) did not reach the error estimate {_TOL}"
            )
    return out


def gaussian_response(a, b, theta, support: str = "cone") -> np.ndarray:
    """The Gaussian-weighted share of the acceptance (half-angle a, FWHM 2a) inside the
    ball's cap (radius b, b = pi for a ball holding the lens; centre theta from the
    axis), in [0, 1]. ``support="cone"``: K over the acceptance cap, normalised there
    (0 where the caps do not overlap, 1 where the ball's cap holds the acceptance cap);
    ``"sphere"``: K over the sphere, normalised over the sphere."""
    if support not in ("cone", "sphere"):
        raise ValueError(f"support must be 'cone' or 'sphere', got {support!r}")
    a, b, theta = np.broadcast_arrays(*(np.asarray(v, dtype=np.float64) for v in (a, b, theta)))
    shape = a.shape
    a, b, theta = a.ravel(), b.ravel(), theta.ravel()
    sigma = 2 * a * FWHM_TO_SIGMA
    out = np.zeros(a.shape)
    if support == "cone":
        # a ball's cap beyond a hemisphere: the complement (about -w, pi - theta from u)
        big = (b > math.pi / 2) & (b < math.pi)
        if big.any():
            out[big] = 1 - gaussian_response(a[big], math.pi - b[big], math.pi - theta[big])
            keep = ~big
            rest = gaussian_response(a[keep], b[keep], theta[keep])
            out[keep] = rest
            return out.reshape(shape)
        out[b >= theta + a] = 1.0
        inside = (theta + b <= a) & ~(b >= theta + a)
        part = ~inside & (theta < a + b) & ~(b >= theta + a)
        mass = gaussian_mass(a)
        i = np.flatnonzero(inside)
        if i.size:
            full = np.full(i.size, math.pi)
            out[i] = _ball_flux(b[i], theta[i], sigma[i], full) / mass[i]
        i = np.flatnonzero(part)
        if i.size:
            at_u, at_w = _half_angles(a[i], b[i], theta[i])
            flux = _ball_flux(b[i], theta[i], sigma[i], at_w)
            out[i] = (flux + 2 * at_u * kernel_G(a[i], sigma[i])) / mass[i]
    else:
        out[b >= math.pi] = 1.0
        cap = b < math.pi
        mass = gaussian_mass(a, "sphere")
        # a cap holding -u (the flux's singular point): its complement's flux, subtracted
        anti = cap & (theta + b >= math.pi)
        bb = np.where(anti, math.pi - b, b)
        tt = np.where(anti, math.pi - theta, theta)
        i = np.flatnonzero(cap)
        if i.size:
            full = np.full(i.size, math.pi)
            r = _ball_flux(bb[i], tt[i], sigma[i], full) / mass[i]
            out[i] = np.where(anti[i], 1 - r, r)
    return np.clip(out, 0.0, 1.0).reshape(shape)
