"""HEALPix's zone-boundary and wrap conventions, pinned against astropy-healpix (issue 37).

Two places where a float convention decides the pixel:

* |z| = fl(2/3), the float nearest the boundary between the polar caps and the
  equatorial zone (0.666...63, just below 2/3): the equatorial formula takes it
  (``|z| <= 2/3``), and at a ring-n corner (phi = k pi / 2n) its floors round to the
  pixel of ring n, as astropy-healpix (and healpy) answer;
* phi = -1e-17 in a polar ring: phi / (pi/2) mod 4 rounds to 4.0, which wraps to 0: the
  ring's first pixel, as astropy-healpix answers, although the real angle lies in the last.

The float paths (``healpix.ang2pix_ring``, ``vec2pix_ring`` and the compiled kernel's
``_ang2pix``) follow these conventions for every nside parity. The exact path
(``exact3d.ang2pix_snap`` on the rationals the floats denote, and so ``EyePair3D.facet``)
answers the pixel of the real point instead: the one astropy-healpix gives for a point
moved off the boundary along the same meridian (below fl(2/3) at the corner, just under
2 pi for the wrap). A point exactly on the boundary (snapped in the exact path) takes the
float convention.
"""

from __future__ import annotations

import math
from fractions import Fraction

import mpmath
import numpy as np
import pytest

from eyeviz.core import exact3d
from eyeviz.core import healpix as hp
from eyeviz.core.geometry3d import EyePair3D
from eyeviz.core.kernels import healpix_lit

astropy_healpix = pytest.importorskip("astropy_healpix")
u = pytest.importorskip("astropy.units")

Z23 = 2.0 / 3.0  # fl(2/3) < 2/3
NSIDES = [*range(1, 18), 64, 65, 1024, 1025]  # every parity, small and large


def _astropy(n: int, z, phi) -> np.ndarray:
    """astropy-healpix's RING pixel of (z, phi) given as longitude and latitude."""
    z, phi = np.broadcast_arrays(np.asarray(z, float), np.asarray(phi, float))
    lat = np.arcsin(z)
    assert np.array_equal(np.sin(lat), z)  # the latitude denotes the same z
    return astropy_healpix.core.lonlat_to_healpix(phi * u.rad, lat * u.rad, n, order="ring")


def _kernel(n: int, z, phi) -> np.ndarray:
    pairs = zip(z, phi, strict=True)
    return np.array([healpix_lit._ang2pix(n, float(a), float(b)) for a, b in pairs])


def _exact(n: int, z: float, phi: float, tol: float = 2.0**-150) -> int:
    """ang2pix of the exact point (sin theta cos phi, sin theta sin phi, z) at 300 bits."""
    with mpmath.workprec(300):
        zz, ph = mpmath.mpf(z), mpmath.mpf(phi)
        s = mpmath.sqrt(1 - zz * zz)
        v = (s * mpmath.cos(ph), s * mpmath.sin(ph), zz)
        return exact3d.ang2pix_snap(n, v, mpmath.mpf(tol))


@pytest.mark.parametrize("n", NSIDES)
def test_float_paths_put_fl_two_thirds_where_astropy_does(n):
    """phi = 0 is the one ring-n corner a float holds exactly (at the others the answer
    is a rounding of phi, which no two libraries share); the pixel centres, a generic phi
    and the wrap (-1e-17) complete the row."""
    mids = (np.arange(4 * n) + 0.5) * (math.pi / (2 * n))
    phi = np.concatenate([[0.0, -1e-17, 0.123, 6.0], mids])
    for z in (Z23, -Z23):
        want = _astropy(n, z, phi)
        zz = np.full_like(phi, z)
        assert np.array_equal(hp.ang2pix_ring(n, zz, phi), want), (n, z)
        assert np.array_equal(_kernel(n, zz, phi), want), (n, z)
    # at the corner phi = 0 the pixel is ring n's first (the north one) or ring 3n's
    # first (the south one): the equatorial formula, floors rounded as astropy's
    assert hp.ang2pix_ring(n, Z23, 0.0) == 2 * n * (n - 1)
    assert hp.ang2pix_ring(n, -Z23, 0.0) == 2 * n * (n - 1) + 2 * n * 4 * n


@pytest.mark.parametrize("n", NSIDES)
def test_float_paths_wrap_minus_1e_17_to_the_first_pixel_of_a_polar_ring(n):
    z = np.array([0.9, -0.9, 0.999, -0.75, 1 - 1e-9, Z23 + 1e-3])
    phi = np.full(z.shape, -1e-17)
    want = _astropy(n, z, phi)
    assert np.array_equal(hp.ang2pix_ring(n, z, phi), want)
    assert np.array_equal(_kernel(n, z, phi), want)
    s = np.sqrt((1 - z) * (1 + z))
    assert np.array_equal(hp.vec2pix_ring(n, s, -1e-17 * s, z), want)
    ring, first, _, _ = hp.pix2ring(n, want)
    assert np.array_equal(want, first)  # the first pixel of its ring (phi taken as 0)
    assert np.all((ring <= n) | (ring >= 3 * n))  # rings of the polar caps


@pytest.mark.parametrize("n", range(1, 10))
def test_exact_path_gives_the_real_points_pixel_at_the_zone_boundary(n):
    """fl(2/3) is below 2/3: at a ring-n corner the real point lies in the ring below
    (the cell whose top vertex the corner is), as astropy-healpix says of a point 1e-9
    further down the same meridian; -fl(2/3) likewise in the ring above."""
    phi = np.array([0.0, 0.123, math.pi / (4 * n)])  # the corner at 0, inside, a centre
    for z in (Z23, -Z23):
        inward = z - math.copysign(1e-9, z)
        want = _astropy(n, inward, phi)
        got = [_exact(n, z, p) for p in phi]
        assert got == want.tolist(), (n, z)
    # on the boundary itself (2/3 exactly) and within the snap tolerance of it, on either
    # side and at either pole's zone, the exact path takes the float rule at the corner
    for sign in (1, -1):
        want = int(_astropy(n, sign * Z23, 0.0))
        for dz in (0, 1, -1):
            with mpmath.workprec(300):
                zz = sign * (mpmath.mpf(2) / 3 + dz * mpmath.ldexp(1, -200))
                v = (mpmath.sqrt(1 - zz * zz), mpmath.mpf(0), zz)
                assert exact3d.ang2pix_snap(n, v, mpmath.ldexp(1, -150)) == want, (sign, dz)


@pytest.mark.parametrize("n", range(1, 10))
def test_exact_path_puts_minus_1e_17_in_the_last_pixel_of_a_polar_ring(n):
    z = [0.9, -0.9, 0.999, -0.75]
    want = _astropy(n, z, 2 * math.pi - 1e-9)  # just under 2 pi: the ring's last pixel
    got = [_exact(n, a, -1e-17) for a in z]
    assert got == want.tolist()
    ring, first, num, _ = hp.pix2ring(n, want)
    assert np.array_equal(want, first + num - 1)
    # snapped (tolerance far above 1e-17): the float convention, the first pixel
    assert [_exact(n, a, -1e-17, tol=1e-12) for a in z] == hp.ang2pix_ring(n, z, 0.0).tolist()


@pytest.mark.parametrize("n", [2, 4, 6, 8, 10])
def test_facet_of_the_pair_is_the_real_points_pixel_at_both_conventions(n):
    """EyePair3D.facet (the fast path, the tiny-ball lit set, then mpmath) on float points
    whose direction from eye B lies within rounding of ring n's corner at z = 2/3 (phi = 0)
    and of phi = 0 in a polar ring, on the negative side: the pixel of the real point,
    where the float formulas answer the first pixel of the ring."""
    pair = EyePair3D(40.0, 20.0, n)
    dx = 40.0 + math.sqrt(5.0) * 256.0  # direction (dx, 0, 512): |z| within 1e-16 of 2/3
    real = Fraction(dx) - 40  # the facet takes the exact difference
    below = real * real > 5 * 256**2  # the real z = 512 / |d| is below 2/3
    step = -1e-9 if below else 1e-9
    got = pair.facet(np.array([dx, dx]), np.zeros(2), np.array([512.0, -512.0]), "B")
    want = [int(_astropy(n, Z23 + step, 0.0)), int(_astropy(n, -Z23 - step, 0.0))]
    assert got.tolist() == want
    # (0.9 r, y = -1e-14): the real phi is just below 2 pi, the ring's last pixel
    s = math.sqrt(1 - 0.81) * 1000.0
    x, y, z = np.array([40.0 + s] * 2), np.array([-1e-14] * 2), np.array([900.0, -900.0])
    got = pair.facet(x, y, z, "B")
    ring, first, num, _ = hp.pix2ring(n, got)
    assert np.array_equal(got, first + num - 1)
    assert np.array_equal(hp.vec2pix_ring(n, x - 40.0, y, z), first)  # the float rule
