"""Exact ties away from the equator: balls resting on the plane y = 0 (their tangent
directions meet the meridians at longitude 0 and pi, HEALPix cell boundaries in every
polar and equatorial ring) or touching the plane x = cx through an eye centre (longitude
pi/2), at high elevation, where the tie tests at z = 0 never look. Each lit set equals
the independent mpmath reference."""

from __future__ import annotations

import numpy as np
import pytest

from eyeviz.core.geometry3d import EyePair3D
from eyeviz.reference.healpix_reference import reference_lit

BALLS = [
    # (x, y, z, g) with y = g: resting on y = 0, above the horizon
    (-27.0, 19.0, 186.0, 19.0),
    (13.0, 7.0, 95.0, 7.0),
    (5.0, 3.0, -120.0, 3.0),
    # touching the vertical plane x = -40 through eye A's centre (|x + 40| = g)
    (-10.0, 55.0, 170.0, 30.0),
]


@pytest.mark.parametrize("nside", [2, 4])
@pytest.mark.parametrize("ball", BALLS)
def test_high_elevation_ties_match_the_reference(nside, ball):
    eyes = EyePair3D(40.0, 20.0, nside)
    la, lb = eyes.lit(*ball)
    assert np.array_equal(la, reference_lit(nside, *ball, -40.0))
    assert np.array_equal(lb, reference_lit(nside, *ball, 40.0))
