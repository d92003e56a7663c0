"""HEALPix RING formulas for any nside: against astropy-healpix where nside is a power of
two, and by their own identities (centres round trip, ring bookkeeping) for the rest."""

from __future__ import annotations

import math

import numpy as np
import pytest

from eyeviz.core import healpix as hp

astropy_healpix = pytest.importorskip("astropy_healpix")


def _astropy(nside):
    return astropy_healpix.HEALPix(nside=nside, order="ring")


def _lonlat_vec(lon, lat):
    lon, lat = np.asarray(lon), np.asarray(lat)
    return np.stack([np.cos(lat) * np.cos(lon), np.cos(lat) * np.sin(lon), np.sin(lat)], -1)


@pytest.mark.parametrize("nside", [1, 2, 4, 8, 64, 1024, 2**20])
def test_ang2pix_matches_astropy(nside):
    import astropy.units as u

    rng = np.random.default_rng(nside)
    z = rng.uniform(-1, 1, 20000)
    phi = rng.uniform(0, 2 * math.pi, 20000)
    # the poles and near them; exact cell boundaries (z = 0 at phi = 0, z = 2/3) are left
    # out: astropy-healpix goes through lat and float x, y, z and may round across them
    z[:4] = [1.0, -1.0, 1 - 1e-12, -1 + 1e-12]
    phi[:2] = [0.0, math.pi]
    ours = hp.ang2pix_ring(nside, z, phi)
    lat = (math.pi / 2 - np.arccos(z)) * u.rad
    theirs = _astropy(nside).lonlat_to_healpix(phi * u.rad, lat)
    assert np.array_equal(ours, theirs)


@pytest.mark.parametrize("nside", [1, 2, 16, 256])
def test_centres_and_boundaries_match_astropy(nside):
    rng = np.random.default_rng(7)
    pix = rng.integers(0, hp.npix(nside), 3000)
    lon, lat = _astropy(nside).healpix_to_lonlat(pix)
    assert np.abs(hp.centers(nside, pix) - _lonlat_vec(lon.value, lat.value)).max() < 1e-14
    blon, blat = _astropy(nside).boundaries_lonlat(pix[:300], 3)
    ours = hp.boundaries(nside, pix[:300], 3)
    assert ours.shape == (300, 12, 3)
    assert np.abs(ours - _lonlat_vec(blon.value, blat.value)).max() < 1e-14


@pytest.mark.parametrize("nside", [2, 6, 12, 180, 1000])
def test_any_nside_round_trips(nside):
    n = nside
    pix = (
        np.arange(hp.npix(n))
        if n <= 180
        else np.random.default_rng(1).integers(0, 12 * n * n, 50000)
    )
    c = hp.centers(n, pix)
    assert np.array_equal(hp.vec2pix_ring(n, c[:, 0], c[:, 1], c[:, 2]), pix)
    ring, first, num, shifted = hp.pix2ring(n, pix)
    assert np.all((pix >= first) & (pix < first + num))
    assert np.allclose(c[:, 2], hp.ring_z(n, ring), atol=1e-14)
    # the ring's first pixel centre: phi = 0 (not shifted) or half a pixel
    phi0 = np.mod(np.arctan2(c[:, 1], c[:, 0]), 2 * math.pi)
    j = pix - first
    expect = (j + np.where(shifted, 0.5, 0.0)) * 2 * math.pi / num
    assert np.allclose(phi0, expect, atol=1e-12)
    # vertices are shared: a point just inside each corner maps to the pixel
    b = hp.boundaries(n, pix[:2000], 1)
    inner = b + 1e-9 * (c[:2000, None, :] - b)
    got = hp.vec2pix_ring(n, inner[..., 0], inner[..., 1], inner[..., 2])
    assert np.array_equal(got, np.repeat(pix[:2000, None], 4, axis=1))


def test_exact_boundaries_follow_the_floors():
    """On a boundary the pixel is the one the floors of Gorski's Eq. 4-9 give: the
    equator vertex at phi = 0 belongs to the equatorial ring's pixel that starts there."""
    n = 2
    eq_first = 2 * n * (n - 1) + 4 * n * n
    assert hp.ang2pix_ring(n, 0.0, 0.0) == eq_first
    assert hp.ang2pix_ring(n, 0.0, math.pi / 2) == eq_first + n
    assert hp.ang2pix_ring(n, 1.0, 0.0) == 0 and hp.ang2pix_ring(n, -1.0, 0.0) == 12 * n * n - 4


def test_ring_bookkeeping():
    n = 6
    first, num, _ = hp.ring_info(n, np.arange(1, 4 * n))
    assert num.sum() == hp.npix(n) and first[0] == 0
    assert np.array_equal(first[1:], np.cumsum(num)[:-1])
    # the equator (ring 2n) starts at 2n(n-1) + 4n^2 (docs/spherical.md)
    assert first[2 * n - 1] == 2 * n * (n - 1) + 4 * n * n
    zlo, zhi = hp.ring_z_range(n, np.array([1, 2 * n, 4 * n - 1]))
    assert zhi[0] == 1.0 and zlo[2] == -1.0 and zlo[1] < 0 < zhi[1]


def test_boundaries_refuses_bad_step():
    with pytest.raises(ValueError, match="step must be an integer >= 1"):
        hp.boundaries(4, [0], 0)


@pytest.mark.parametrize("nside", [1, 2, 4, 8])
def test_xyf2loc_gives_astropys_centres_and_corners(nside):
    """(z, phi) of each pixel's centre and of its four corners, as astropy-healpix's
    healpix_to_lonlat and boundaries_lonlat give them (astropy's nside: powers of two)."""
    pix = np.arange(hp.npix(nside))
    ix, iy, f = hp.pix2xyf(nside, pix)
    z, phi = hp.xyf2loc(nside, ix + 0.5, iy + 0.5, f)
    lon, lat = _astropy(nside).healpix_to_lonlat(pix)
    assert np.abs(z - np.sin(lat.value)).max() < 1e-14
    assert np.abs(np.angle(np.exp(1j * (phi - lon.value)))).max() < 1e-13
    # corners N (1, 1), W (0, 1), S (0, 0), E (1, 0); a pole's longitude is arbitrary
    blon, blat = _astropy(nside).boundaries_lonlat(pix, 1)
    for k, (dx, dy) in enumerate([(1, 1), (0, 1), (0, 0), (1, 0)]):
        zc, pc = hp.xyf2loc(nside, ix + dx, iy + dy, f)
        assert np.abs(zc - np.sin(blat.value[:, k])).max() < 1e-14
        off_pole = np.abs(zc) < 1 - 1e-12
        dphi = np.angle(np.exp(1j * (pc - blon.value[:, k])))
        assert np.abs(dphi[off_pole]).max() < 1e-12
