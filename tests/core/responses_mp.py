"""An independent reference for the graded responses (tests only).

The response as the 1-D integral over the polar angle psi about the facet's axis of the
kernel times the azimuthal arc of the ball's cap at psi, 2 acos((cos b - cos theta
cos psi) / (sin theta sin psi)), by QUADPACK split at the arc's kinks (and every sigma
for the Gaussian); the ball's cap from the lens in 60-digit mpmath on the float inputs. It
shares no formula with :mod:`eyeviz.core.responses_caps` (closed-form segments, a flux
through the boundary).
"""

from __future__ import annotations

import math
import warnings

import mpmath as mp
from scipy import integrate


def _omega(psi: float, b: float, th: float) -> float:
    """Half the azimuth, at polar angle psi about the axis, inside the cap (b, th)."""
    if psi == 0 or th == 0:
        inside = (th <= b) if psi == 0 else (psi <= b)
        return math.pi if inside else 0.0
    c = (math.cos(b) - math.cos(th) * math.cos(psi)) / (math.sin(th) * math.sin(psi))
    return math.acos(min(1.0, max(-1.0, c)))


def cap_response(a, b, th, kind: str = "flat", support: str = "cone") -> float:
    """Response of an acceptance cap of half-angle a to a cap of radius b whose centre
    is th from the axis; kind flat or gaussian (FWHM 2a), support cone or sphere.
    QUADPACK (scipy's quad) split at every kink, tolerances 1e-13."""
    a, b, th = float(a), float(b), float(th)
    if b >= math.pi:
        return 1.0
    sig = 2 * a / (2 * math.sqrt(2 * math.log(2)))

    def kern(p: float) -> float:
        return 1.0 if kind == "flat" else math.exp(-(p**2) / (2 * sig**2))

    # beyond 40 sigma the kernel is below exp(-800): the sphere's integrals stop there
    top = a if support == "cone" else min(math.pi, 40 * sig)
    cuts = (abs(th - b), th + b, 2 * math.pi - th - b)
    pts = sorted({0.0, top, *(p for p in cuts if 0 < p < top)})
    step = sig if kind == "gaussian" else top
    grid = sorted(set(pts) | {k * step for k in range(1, int(top / step) + 1)})
    num = den = 0.0
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", integrate.IntegrationWarning)  # tiny caps: 1e-300
        for lo, hi in zip(grid[:-1], grid[1:], strict=True):
            num += integrate.quad(
                lambda p: kern(p) * math.sin(p) * 2 * _omega(p, b, th),
                lo,
                hi,
                epsabs=1e-15,
                epsrel=1e-13,
                limit=200,
            )[0]
            den += integrate.quad(
                lambda p: kern(p) * math.sin(p) * 2 * math.pi,
                lo,
                hi,
                epsabs=1e-15,
                epsrel=1e-13,
                limit=200,
            )[0]
    return num / den


def ball_angles(c, p, axis, g):
    """(theta, b) of a ball (c, g) seen from a lens p with the given axis, from the float
    inputs taken exactly (60 digits); b = pi when the lens is inside the ball."""
    with mp.workdps(60):
        v = [mp.mpf(float(ci)) - mp.mpf(float(pi)) for ci, pi in zip(c, p, strict=True)]
        ax = [mp.mpf(float(x)) for x in axis]
        d2 = sum(x * x for x in v)
        gg = mp.mpf(float(g))
        b = mp.pi if d2 < gg * gg else mp.asin(gg / mp.sqrt(d2))
        cr = [v[1] * ax[2] - v[2] * ax[1], v[2] * ax[0] - v[0] * ax[2], v[0] * ax[1] - v[1] * ax[0]]
        dot = sum(x * y for x, y in zip(v, ax, strict=True))
        th = mp.atan2(mp.sqrt(sum(x * x for x in cr)), dot)
        return th, b


def healpix_cell_share(nside: int, pix: int, w, b: float) -> float:
    """Share of HEALPix cell ``pix`` inside the cap of radius b about the unit vector w,
    in the face chart (x, y), where HEALPix is equal-area with a constant Jacobian: the
    outer integral over x by QUADPACK, the inner length in y from the sign changes of
    cos(angle to w) - cos b on 257 points, each refined by brentq; where no sample is
    inside but one comes within 1e-6 (the samples, 1/256 apart, miss the maximum by
    less: |d2f/dv2| < 0.1 on a cell), the maximum along the line is searched (Brent,
    bounded) so that a chord narrower than the samples, near the cap's tip, is found."""
    import numpy as np
    from scipy import optimize

    from eyeviz.core import healpix

    ix, iy, face = (int(v[0]) for v in healpix.pix2xyf(nside, np.array([pix])))
    cb = math.cos(b)
    vs = np.linspace(0.0, 1.0, 257)
    wv = np.asarray(w, float)

    def f(u: float, v) -> np.ndarray:
        p = healpix.xyf2vec(nside, ix + u, iy + np.asarray(v, float), face)
        return p @ wv - cb

    def tip(u: float, vals: np.ndarray) -> float:
        """The chord's length where every sample is outside."""
        j = int(np.argmax(vals))
        lo, hi = vs[max(j - 1, 0)], vs[min(j + 1, vs.size - 1)]
        best = optimize.minimize_scalar(
            lambda v: -float(f(u, v)), bounds=(lo, hi), method="bounded", options={"xatol": 1e-14}
        )
        vm = float(best.x)
        if float(f(u, vm)) <= 0:
            return 0.0
        a = optimize.brentq(lambda v: float(f(u, v)), lo, vm, xtol=1e-15)
        return optimize.brentq(lambda v: float(f(u, v)), vm, hi, xtol=1e-15) - a

    def inner(u: float) -> float:
        vals = f(u, vs)
        if vals.max() < 0:
            return tip(u, vals) if vals.max() > -1e-6 else 0.0
        inside = 0.0
        edges = [0.0]
        for j in np.flatnonzero(np.signbit(vals[:-1]) != np.signbit(vals[1:])):
            edges.append(optimize.brentq(lambda v: float(f(u, v)), vs[j], vs[j + 1], xtol=1e-15))
        edges.append(1.0)
        for lo, hi in zip(edges[:-1], edges[1:], strict=True):
            if float(f(u, (lo + hi) / 2)) >= 0:
                inside += hi - lo
        return inside

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", integrate.IntegrationWarning)
        return integrate.quad(inner, 0.0, 1.0, epsabs=1e-12, epsrel=1e-12, limit=400)[0]
