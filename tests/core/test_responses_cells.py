"""HEALPix ``cell`` responses (eyeviz.core.responses_cells via EyePair3D.responses): the
lit sets, the cap's area recovered from the shares, and single cells against an
independent quadrature in the face chart."""

from __future__ import annotations

import math

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
