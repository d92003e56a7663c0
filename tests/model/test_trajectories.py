"""Section 6 trajectory generators: inside the BFV, on the right curve, evenly spaced."""

import math

import numpy as np
import pytest

from eyeviz.core.geometry import EyePair
from eyeviz.model.trajectories import circular, horizontal, paper_count, vertical

EYES = EyePair(40.0, 20.0, 720)


@pytest.mark.parametrize("g", [5.0, 50.0, 500.0])
@pytest.mark.parametrize("r", [1000.0, 5000.0, 10000.0])
def test_horizontal_inside_bfv_and_spans_it(r, g):
    x, y = horizontal(r, g, 200)
    assert x.shape == y.shape == (200,)
    assert np.all(y == r)
    assert np.all(EYES.in_bfv(x, y, g))
    # symmetric, evenly spaced, and the whole chord is used: one more cell leaves the BFV
    np.testing.assert_allclose(x, -x[::-1], atol=1e-9 * r)
    step = np.diff(x)
    np.testing.assert_allclose(step, step[0])
    assert not EYES.in_bfv(x[-1] + step[0], r, g)
    # Section 6: the chord is about 2 tan(60 deg) r long for small g
    if g == 5.0:
        assert x[-1] - x[0] + step[0] == pytest.approx(2 * math.tan(math.radians(60)) * r, rel=0.01)


@pytest.mark.parametrize("g", [5.0, 50.0, 500.0])
@pytest.mark.parametrize("r", [1000.0, 4000.0, 10000.0])
def test_circular_inside_bfv_on_circle(r, g):
    x, y = circular(r, g, 150)
    np.testing.assert_allclose(np.hypot(x, y), r)
    assert np.all(EYES.in_bfv(x, y, g))
    ang = np.arctan2(y, x)
    np.testing.assert_allclose(np.diff(ang), np.diff(ang)[0], rtol=1e-9)
    out = np.array([ang[0] - np.diff(ang)[0]])
    assert not EYES.in_bfv(r * np.cos(out), r * np.sin(out), g)[0]
    if g == 5.0:  # arc ~ 2 pi r 120/360
        arc = (ang[-1] - ang[0]) * r * 150 / 149
        assert arc == pytest.approx(2 * math.pi * r / 3, rel=0.01)


@pytest.mark.parametrize("g", [5.0, 50.0, 500.0, 5000.0])
def test_vertical_axis(g):
    x, y = vertical(g, 90)
    assert np.all(x == 0)
    assert np.all(EYES.in_bfv(x, y, g))
    assert y.min() > 1000 and y.max() < 10000
    np.testing.assert_allclose(np.diff(y), np.diff(y)[0])


def test_paper_counts_and_bad_input():
    assert paper_count("horizontal", 5, 1000) == 300
    assert paper_count("circular", 50, 5000) == 100
    assert paper_count("vertical", 500) == 9
    assert paper_count("vertical", 500, lo=20) == 20
    assert paper_count("horizontal", 5, 10000, hi=1000) == 1000
    with pytest.raises(ValueError, match="kind"):
        paper_count("spiral", 5, 1000)
    with pytest.raises(ValueError, match="g"):
        horizontal(1000, -1, 10)
    with pytest.raises(ValueError, match="n"):
        circular(1000, 5, 0)
    with pytest.raises(ValueError, match="never lies in the BFV"):
        horizontal(100, 500, 10)
    with pytest.raises(ValueError, match="stop"):
        vertical(5, 10, start=5000, stop=1000)


def test_one_point_is_a_trajectory():
    for make in (horizontal, circular):
        x, y = make(2000.0, 50.0, 1)
        assert x.shape == y.shape == (1,) and EYES.in_bfv(x, y, 50.0).all()


def test_a_circle_no_larger_than_the_feature_is_refused_by_name():
    for g in (100.0, 150.0):  # g = r included
        with pytest.raises(ValueError, match="g must be < r"):
            circular(100.0, g, 10)
