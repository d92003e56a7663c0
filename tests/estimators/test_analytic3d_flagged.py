"""Rows whose two lit caps' rays do not meet in front of the eyes: analytic3d flags them
and answers, as its docstring says, r_max along the mean of the two directions."""

from __future__ import annotations

import math

import numpy as np
import pytest

from eyeviz.core.domain import Domain3D
from eyeviz.core.geometry3d import EyePair3D
from eyeviz.estimators import load

DOM = Domain3D(h=40.0, l=20.0, nside=8, r_min=100.0, r_max=5000.0, g_max=500.0, el_max=0.5)


def _bitmap(eyes: EyePair3D, eye: str, direction) -> np.ndarray:
    """The facets lit in ``eye`` by a small ball far along ``direction`` from its centre."""
    cx = -eyes.h if eye == "A" else eyes.h
    d = np.asarray(direction, float) / np.linalg.norm(direction)
    c = np.array([cx, 0.0, 0.0]) + 1000.0 * d
    lit = eyes.lit(*c, 60.0)[0 if eye == "A" else 1]
    out = np.zeros(eyes.npix, bool)
    out[lit] = True
    return out


@pytest.mark.parametrize(
    ("dir_a", "dir_b"),
    [
        ((-1.0, 1.0, 0.0), (1.0, 1.0, 0.0)),  # diverging: A looks left, B right
        ((0.0, 1.0, 0.3), (0.0, 1.0, 0.3)),  # parallel
    ],
)
def test_rays_that_do_not_meet_in_front_answer_r_max_along_their_mean(dir_a, dir_b):
    eyes = EyePair3D(DOM.h, DOM.l, DOM.nside)
    est = load("analytic3d", domain=DOM)
    oa, ob = _bitmap(eyes, "A", dir_a), _bitmap(eyes, "B", dir_b)
    pred = est.predict(oa[None], ob[None])
    assert bool(pred.flagged[0])
    assert float(pred[0][0]) == DOM.r_max
    mean = np.asarray(dir_a) / np.linalg.norm(dir_a) + np.asarray(dir_b) / np.linalg.norm(dir_b)
    want_az = math.atan2(mean[1], mean[0])
    want_el = math.asin(mean[2] / np.linalg.norm(mean))
    # the lit caps' centres are the directions to within a facet (nside 8: ~7 degrees)
    assert abs(float(pred[1][0]) - want_az) < 0.15
    assert abs(float(pred[2][0]) - want_el) < 0.15
