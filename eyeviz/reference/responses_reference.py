"""High-precision reference of one facet's graded response to one ball (tests and reports).

Independent of the core's exact responses: written from the definition, in mpmath.

**The response.** A facet has its lens at p, a unit optical axis a and a full acceptance
angle dr; its acceptance kernel K(theta) weighs the directions u by their angle
theta = angle(u, a). A ball (c, g) with |c - p| > g covers, seen from the lens, the
spherical cap of the directions u whose ray p + t u (t >= 0) meets the ball: centre
v / |v| with v = c - p, angular radius beta = asin(g / |v|). The response is the share of
the kernel's weight inside that cap,

    R = (integral over the cap of K dOmega) / (integral over the whole sphere of K dOmega),

so R is in [0, 1], R = 1 when the cap holds every direction the kernel weighs, and a cap
that only touches the kernel's support (tangency) gives 0. The kernels:

- ``flat``: K = 1 for theta <= dr / 2, else 0 (uniform over the acceptance cone);
  the denominator is 2 pi (1 - cos(dr / 2)).
- ``gaussian``: K = exp(-theta^2 / (2 sigma^2)) for theta in [0, pi], with the full width
  at half maximum equal to the acceptance angle, dr = 2 sqrt(2 ln 2) sigma (Snyder's
  convention, as CompoundRay's shader: dr / 2.35482...). Normalised over the whole sphere:
  the denominator is 2 pi times the integral of K(theta) sin(theta) over [0, pi], so a
  wide kernel's tail beyond theta = pi / 2 counts, and R = 1 only for a ball holding the lens.
  This is the acceptance function renderers sample (``support="sphere"``, the default).
  With ``support="cone"`` K is cut at the acceptance cone's edge (theta <= dr / 2) and
  normalised over the cone instead: the response is then > 0 exactly where the ball
  meets the cone, as the binary model's lit set (the eye models' ``gaussian`` kind).

A ball holding the lens strictly inside (|v| < g) covers every direction: R = 1. A ball
whose surface passes through the lens (|v| = g) covers the open half-space of directions
towards its centre: beta = pi / 2.

**The integral.** In polar coordinates (theta, phi) about the facet's axis, the cap with
centre at angle delta from the axis and radius beta holds (theta, phi) iff

    cos(delta) cos(theta) + sin(delta) sin(theta) cos(phi) >= cos(beta),

so at polar angle theta it spans the azimuthal extent w(theta) = 2 acos(clip(C, -1, 1)),
C = (cos(beta) - cos(delta) cos(theta)) / (sin(delta) sin(theta)), in closed form. The
response is the 1-D integral

    R = integral of K(theta) sin(theta) w(theta) d theta / (2 pi integral of K sin),

by tanh-sinh quadrature split at the kinks of w (theta = |delta - beta|, delta + beta,
2 pi - delta - beta) and of K (theta = dr / 2 for ``flat`` and the cut Gaussian). Done at
``dps`` digits and again at ``dps + 15``; the two must agree within 10^-(dps - 8) or a
ValueError is raised, so a returned value carries an error far below 1e-9 (the core's
tolerance).
"""

from __future__ import annotations

import functools
from collections.abc import Sequence

import mpmath

__all__ = [
    "KINDS",
    "FWHM_PER_SIGMA",
    "cap_of_ball",
    "cap_response",
    "reference_response",
    "two_caps_area",
]

KINDS = ("flat", "gaussian")
#: dr / sigma of the Gaussian kernel: 2 sqrt(2 ln 2) = 2.3548200450309493...
FWHM_PER_SIGMA = float(2 * mpmath.sqrt(2 * mpmath.log(2)))


def _mpf(x: object) -> mpmath.mpf:
    return mpmath.mpf(x) if isinstance(x, mpmath.mpf) else mpmath.mpf(float(x))  # type: ignore[arg-type]


def cap_of_ball(
    p: Sequence[float], a: Sequence[float], c: Sequence[float], g: float
) -> tuple[mpmath.mpf, mpmath.mpf] | None:
    """(delta, beta): the angle of the ball's centre from the axis a and the ball's angular
    radius, seen from the lens p, at the current mpmath precision; None when the lens is
    strictly inside the ball (every direction is covered). The axis need not be unit."""
    v = [_mpf(ci) - _mpf(pi) for ci, pi in zip(c, p, strict=True)]
    ax = [_mpf(x) for x in a]
    gm = _mpf(g)
    vn = mpmath.sqrt(sum(x * x for x in v))
    if vn < gm:
        return None
    dot = sum(x * y for x, y in zip(v, ax, strict=True))
    cross = (
        v[1] * ax[2] - v[2] * ax[1],
        v[2] * ax[0] - v[0] * ax[2],
        v[0] * ax[1] - v[1] * ax[0],
    )
    delta = mpmath.atan2(mpmath.sqrt(sum(x * x for x in cross)), dot)
    beta = mpmath.pi / 2 if vn == gm else mpmath.asin(gm / vn)
    return delta, beta


def _extent(theta: mpmath.mpf, delta: mpmath.mpf, beta: mpmath.mpf) -> mpmath.mpf:
    """w(theta): the azimuthal measure of the cap (delta, beta) on the circle at polar angle
    theta about the axis."""
    s = mpmath.sin(delta) * mpmath.sin(theta)
    lhs = mpmath.cos(beta) - mpmath.cos(delta) * mpmath.cos(theta)
    if s == 0:
        return 2 * mpmath.pi if lhs <= 0 else mpmath.mpf(0)
    cc = lhs / s
    if cc <= -1:
        return 2 * mpmath.pi
    if cc >= 1:
        return mpmath.mpf(0)
    return 2 * mpmath.acos(cc)


def _kernel(kind: str, dr: mpmath.mpf, support: str = "sphere"):
    if kind == "flat":
        return lambda t: mpmath.mpf(1), dr / 2
    if kind == "gaussian":
        two_s2 = 2 * (dr / (2 * mpmath.sqrt(2 * mpmath.log(2)))) ** 2
        top = mpmath.pi if support == "sphere" else dr / 2
        return lambda t: mpmath.exp(-(t * t) / two_s2), top
    raise ValueError(f"unknown response kind {kind!r}; known: {', '.join(KINDS)}")


def _points(lo: mpmath.mpf, hi: mpmath.mpf, kinks: Sequence[mpmath.mpf]) -> list[mpmath.mpf]:
    inner = sorted({k for k in kinks if lo < k < hi})
    return [lo, *inner, hi]


@functools.lru_cache(maxsize=64)
def _normaliser(kind: str, dr_text: str, dps: int, support: str) -> mpmath.mpf:
    """The integral of K over its support (cached per kernel and precision)."""
    dr = mpmath.mpf(dr_text)
    if kind == "flat":
        return 2 * mpmath.pi * (1 - mpmath.cos(dr / 2))
    kern, top = _kernel(kind, dr, support)
    pts = [0, dr / 2] if support == "cone" else [0, dr, mpmath.pi]
    return 2 * mpmath.pi * mpmath.quad(lambda t: kern(t) * mpmath.sin(t), pts)


def _response_at(delta, beta, dr, kind: str, support: str) -> mpmath.mpf:
    delta, beta, dr = _mpf(delta), _mpf(beta), _mpf(dr)
    kern, top = _kernel(kind, dr, support)
    pi = mpmath.pi
    kinks = [abs(delta - beta), delta + beta, 2 * pi - delta - beta]
    den = _normaliser(kind, str(dr), mpmath.mp.dps, support)
    # rings below delta - beta and beyond delta + beta (unless the cap wraps the antipode)
    # miss the cap
    lo = max(mpmath.mpf(0), delta - beta)
    hi = top if delta + beta >= pi else min(top, delta + beta)
    if lo >= hi:
        return mpmath.mpf(0)
    num = mpmath.quad(
        lambda t: kern(t) * mpmath.sin(t) * _extent(t, delta, beta), _points(lo, hi, kinks)
    )
    return num / den


def cap_response(
    delta: float | mpmath.mpf,
    beta: float | mpmath.mpf,
    dr: float | mpmath.mpf,
    kind: str = "gaussian",
    dps: int = 30,
    support: str = "sphere",
) -> float:
    """The response of a facet of acceptance angle ``dr`` to a cap of angular radius ``beta``
    whose centre is ``delta`` from the axis (radians; beta = pi covers every direction);
    ``support`` ("sphere" or "cone") is the Gaussian kernel's (module docstring).

    Evaluated at ``dps`` and ``dps + 15`` digits; ValueError if they differ by more than
    10^-(dps - 8) or a parameter is out of range. Returns the value rounded to float64.
    """
    for name, val in (("delta", delta), ("beta", beta), ("dr", dr)):
        if not mpmath.isfinite(_mpf(val)):
            raise ValueError(f"{name} must be finite, got {val!r}")
    if not 0 < _mpf(dr) < mpmath.pi:
        raise ValueError(f"the acceptance angle must be in (0, pi), got {dr!r}")
    if not 0 <= _mpf(delta) <= mpmath.pi or not 0 <= _mpf(beta) <= mpmath.pi:
        raise ValueError(f"delta and beta must be in [0, pi], got {delta!r}, {beta!r}")
    if kind not in KINDS:
        raise ValueError(f"unknown response kind {kind!r}; known: {', '.join(KINDS)}")
    if support not in ("sphere", "cone"):
        raise ValueError(f"support must be 'sphere' or 'cone', got {support!r}")
    with mpmath.workdps(dps):
        r1 = _response_at(delta, beta, dr, kind, support)
    with mpmath.workdps(dps + 15):
        r2 = _response_at(delta, beta, dr, kind, support)
        if abs(r1 - r2) > mpmath.mpf(10) ** (8 - dps):
            raise ValueError(f"quadrature did not settle: {r1} against {r2}")
        return float(r2)


def reference_response(
    p: Sequence[float],
    a: Sequence[float],
    dr: float,
    c: Sequence[float],
    g: float,
    kind: str = "gaussian",
    dps: int = 30,
    support: str = "sphere",
) -> float:
    """The response of the facet (lens ``p``, axis ``a``, acceptance angle ``dr``) to the
    ball (``c``, ``g``), from the float inputs as given (the module's definition)."""
    if not g > 0:
        raise ValueError(f"the ball's radius must be > 0, got {g!r}")
    with mpmath.workdps(dps + 15):
        cap = cap_of_ball(p, a, c, g)
        if cap is None:
            return 1.0
        delta, beta = cap
        return cap_response(delta, beta, dr, kind, dps, support)


def two_caps_area(r1: float, r2: float, d: float) -> float:
    """The area of the intersection of two spherical caps of angular radii r1, r2 (each
    < pi / 2) whose centres are d apart, in closed form (Tovchigrechko and Vakser 2001,
    Eq. 4): an independent check of the ``flat`` quadrature, not used by it."""
    with mpmath.workdps(40):
        r1m, r2m, dm = _mpf(r1), _mpf(r2), _mpf(d)
        if dm >= r1m + r2m:
            return 0.0
        if dm <= abs(r1m - r2m):
            r = min(r1m, r2m)
            return float(2 * mpmath.pi * (1 - mpmath.cos(r)))
        c1, c2, cd = mpmath.cos(r1m), mpmath.cos(r2m), mpmath.cos(dm)
        s1, s2, sd = mpmath.sin(r1m), mpmath.sin(r2m), mpmath.sin(dm)
        area = 2 * (
            mpmath.pi
            - mpmath.acos((cd - c1 * c2) / (s1 * s2))
            - mpmath.acos((c2 - cd * c1) / (sd * s1)) * c1
            - mpmath.acos((c1 - cd * c2) / (sd * s2)) * c2
        )
        return float(area)
