"""HEALPix ``cell`` responses (eyeviz.core.responses_cells via EyePair3D.responses): the
lit sets, the cap's area recovered from the shares, and single cells against an
independent quadrature in the face chart."""

from __future__ import annotations

import math

import mpmath as mp
import numpy as np
import pytest

from eyeviz import EyevizError
from eyeviz.core import healpix
from eyeviz.core.geometry3d import EyePair3D
from eyeviz.core.responses_cells import cell_fraction

from .responses_mp import healpix_cell_share

TOL = 1e-9


def _cap(eyes, x, y, z, g, cx):
    d = math.sqrt((x - cx) ** 2 + y * y + z * z)
    return math.pi if d < g else math.asin(g / d)


@pytest.fixture(scope="module")
def eyes():
    return EyePair3D(40.0, 20.0, 8)


def test_shares_sum_to_the_cap_and_lit_sets_agree(eyes):
    rng = np.random.default_rng(34)
    x, y, z = rng.uniform(-150, 150, (3, 6))
    g = rng.uniform(2, 60, 6)
    x[0], y[0], z[0], g[0] = -38.0, 1.0, 0.5, 5.0  # holds eye A's centre: every cell, 1
    x[1], y[1], z[1], g[1] = 0.0, 0.0, 0.0, 40.0  # through both centres: hemispheres
    x[2], y[2], z[2], g[2] = -40.0, 300.0, 7.0, 1e-6  # tiny
    resp = eyes.responses(x, y, z, g)
    area = 4 * math.pi / eyes.npix
    for (ptr, idx, vals), (lp, li), cx in zip(
        resp, eyes.lit_csr(x, y, z, g), (-40.0, 40.0), strict=True
    ):
        np.testing.assert_array_equal(ptr, lp)
        np.testing.assert_array_equal(idx, li)
        assert ((vals >= 0) & (vals <= 1)).all()
        for k in range(x.size):
            b = _cap(eyes, x[k], y[k], z[k], g[k], cx)
            cap = 4 * math.pi if b == math.pi else 4 * math.pi * math.sin(b / 2) ** 2
            assert abs(vals[ptr[k] : ptr[k + 1]].sum() * area - cap) <= 1e-12 * max(cap, area)
    (ptr, _, vals), _ = resp
    assert (vals[ptr[0] : ptr[1]] == 1.0).all() and ptr[1] - ptr[0] == eyes.npix


@pytest.mark.parametrize(
    "pix,w,b",
    [
        # a polar cell, the cap's edge through it (the reference takes ~17 s there)
        pytest.param(5, (0.3, 0.2, 0.93), 0.25, marks=pytest.mark.slow),
        (300, (0.9, 0.1, 0.1), 0.12),  # equatorial
        (130, (0.5, 0.5, 0.3), 0.4),  # across the zone boundary |z| = 2/3
        pytest.param(0, (0.0, 0.0, 1.0), 0.05, marks=pytest.mark.slow),  # the pole in the cap
        (700, (0.2, -0.3, -0.9), 0.3),  # south
    ],
)
def test_single_cells_match_quadrature(pix, w, b):
    nside = 8
    w = np.asarray(w) / np.linalg.norm(w)
    theta, phi = math.acos(w[2]), math.atan2(w[1], w[0]) % (2 * math.pi)
    # the cap moved so that its edge crosses the cell: the cell's centre at b * 0.9
    c = healpix.centers(nside, np.array([pix]))[0]
    axis = np.cross(c, w)
    if np.linalg.norm(axis) < 1e-12:
        axis = np.cross(c, [1.0, 0, 0])
    axis /= np.linalg.norm(axis)
    ang = 0.9 * b
    wc = c * math.cos(ang) + np.cross(axis, c) * math.sin(ang)
    theta, phi = math.acos(wc[2]), math.atan2(wc[1], wc[0]) % (2 * math.pi)
    got = float(cell_fraction(nside, pix, theta, phi, b))
    want = healpix_cell_share(nside, pix, wc, b)
    assert 0 < want < 1
    assert abs(got - want) <= TOL, (got, want)


def test_whole_cell_and_kinds(eyes):
    assert cell_fraction(8, 100, 0.3, 1.0, math.pi) == pytest.approx(1.0, abs=1e-13)
    with pytest.raises(EyevizError, match="spherical eyes answer responses of kind 'cell'"):
        eyes.responses(0.0, 100.0, 0.0, 5.0, kind="flat")


def _rotate(v: np.ndarray, towards: np.ndarray, ang: float) -> np.ndarray:
    """v turned by ang on the great circle from v through ``towards`` (unit vectors)."""
    t = towards - (towards @ v) * v
    t /= np.linalg.norm(t)
    return v * math.cos(ang) + t * math.sin(ang)


def _angles(w: np.ndarray) -> tuple[float, float]:
    return math.acos(float(np.clip(w[2], -1, 1))), math.atan2(w[1], w[0]) % (2 * math.pi)


# slow: four face-chart quadratures a cell, 5-7 s of CPU (the tip searches of the caps'
# narrow chords); cell 300 is equatorial, 130 lies across |z| = 2/3
@pytest.mark.slow
@pytest.mark.parametrize("pix", [300, 130])
def test_tangent_enclosing_and_tiny_caps_match_quadrature(pix):
    """Done-when of issue 34 for the HEALPix ``cell`` kind: caps tangent to an edge of the
    cell from outside (a sliver) and from inside, one holding it with its edge a hair
    beyond the farthest vertex (enclosing: 1; exactly 1 once the inside test decides it),
    against the face-chart quadrature; a tiny cap inside the cell against its exact area
    2 pi (1 - cos b) in 50 digits."""
    nside = 8
    c = healpix.centers(nside, np.array([pix]))[0]
    ix, iy, face = healpix.pix2xyf(nside, np.array([pix]))
    corners = healpix.xyf2vec(nside, ix + np.array([0, 1, 0, 1]), iy + np.array([0, 0, 1, 1]), face)
    far = max(math.acos(float(np.clip(c @ v, -1, 1))) for v in corners)
    b = 0.15
    # tangent from outside: the cap's edge through the midpoint of the cell's edge y = iy,
    # its centre beyond it (the curved edge leaves a sliver inside); from inside: a small
    # cap in the cell touching that point
    mid = healpix.xyf2vec(nside, ix + 0.5, iy, face)[0]
    w = _rotate(mid, -c, b)
    got = float(cell_fraction(nside, pix, *_angles(w), b))
    want = healpix_cell_share(nside, pix, w, b)
    assert abs(got - want) <= TOL and 0 <= got < 0.05, (got, want)
    w = _rotate(mid, c, 0.01)
    got = float(cell_fraction(nside, pix, *_angles(w), 0.01))
    want = healpix_cell_share(nside, pix, w, 0.01)
    assert abs(got - want) <= TOL and 0 < got < 0.05, (got, want)
    # enclosing: about the cell's centre, reaching 1e-6 beyond its farthest vertex
    got = float(cell_fraction(nside, pix, *_angles(c), far + 1e-6))
    want = healpix_cell_share(nside, pix, c, far + 1e-6)
    assert abs(got - 1.0) <= TOL and abs(want - 1.0) <= TOL
    assert float(cell_fraction(nside, pix, *_angles(c), far + 0.05)) == 1.0  # decided whole
    # tiny: 1e-7 rad about a point inside the cell, a share of ~2e-13
    with mp.workdps(50):
        bt = mp.mpf(1e-7)
        exact = float(2 * mp.pi * (1 - mp.cos(bt)) / (4 * mp.pi / healpix.npix(nside)))
    w = _rotate(c, corners[0], 0.2 * far)
    got = float(cell_fraction(nside, pix, *_angles(w), 1e-7))
    assert abs(got - exact) <= 1e-6 * exact
