"""The ambiguity region: every point of it reproduces the feature's intervals, it is tight
(just outside each edge the intervals change), it holds every centre that reproduces them,
and the radius range holds exactly the radii for which such a centre exists."""

import math

import numpy as np
import pytest

from eyeviz.core.ambiguity import ambiguity_polygon, ambiguity_radius_range, ambiguity_region
from eyeviz.core.geometry import EyePair

PAIR = EyePair(40.0, 20.0, 720)
FEATURES = [
    (0.0, 1500.0, 50.0),
    (-1400.0, 3800.0, 250.0),
    (1700.0, 2200.0, 120.0),
    (100.0, 300.0, 10.0),
    (50.0, 200.0, 3.0),
    (-900.0, 1200.0, 30.0),
]


def _same(pair, pts, g, iv):
    got = pair.intervals(pts[:, 0], pts[:, 1], g)
    return np.all([got[i] == iv[i] for i in range(4)], axis=0)


def _inside(poly, pts):
    a, b = poly, np.roll(poly, -1, axis=0)
    cross = (b[:, 0] - a[:, 0])[None] * (pts[:, 1:2] - a[:, 1][None]) - (b[:, 1] - a[:, 1])[
        None
    ] * (pts[:, 0:1] - a[:, 0][None])
    return np.all(cross >= 0, axis=1)


@pytest.mark.parametrize("x, y, g", FEATURES)
def test_region_contains_truth_and_reproduces_intervals(x, y, g):
    reg = ambiguity_region(PAIR, x, y, g)
    assert reg.intervals == tuple(int(v) for v in PAIR.intervals(x, y, g))
    assert reg.bounded and len(reg.polygon) >= 3 and reg.area > 0
    assert _inside(reg.polygon, np.array([[x, y]]))[0]
    rng = np.random.default_rng(1)
    interior = rng.dirichlet(np.ones(len(reg.polygon)), 3000) @ reg.polygon
    assert _same(PAIR, interior, g, reg.intervals).all()
    # boundary: vertices and edge points, pulled a hair inside
    c = reg.polygon.mean(axis=0)
    t = np.linspace(0, 1, 9)[:-1]
    a, b = reg.polygon, np.roll(reg.polygon, -1, axis=0)
    edge = (a[:, None] + t[None, :, None] * (b - a)[:, None]).reshape(-1, 2)
    span = np.ptp(reg.polygon, axis=0).max()
    boundary = edge + 1e-9 * span * (c - edge) / np.linalg.norm(c - edge, axis=1)[:, None]
    assert _same(PAIR, boundary, g, reg.intervals).all()
    r0, r1 = reg.distance_range()
    assert r0 <= math.hypot(x, y) <= r1


@pytest.mark.parametrize("x, y, g", FEATURES)
def test_region_is_tight(x, y, g):
    """Just outside the middle of every edge the bitmaps differ: no edge is loose."""
    reg = ambiguity_region(PAIR, x, y, g)
    a, b = reg.polygon, np.roll(reg.polygon, -1, axis=0)
    mid = (a + b) / 2
    d = b - a
    outward = np.column_stack([d[:, 1], -d[:, 0]]) / np.linalg.norm(d, axis=1)[:, None]
    span = np.ptp(reg.polygon, axis=0).max()
    outside = mid + 1e-6 * span * outward
    assert not _same(PAIR, outside, g, reg.intervals).any()


@pytest.mark.parametrize("x, y, g", FEATURES[:4])
def test_region_holds_every_matching_centre(x, y, g):
    """Brute force on a grid around the region: matching centres lie in the polygon."""
    reg = ambiguity_region(PAIR, x, y, g)
    lo, hi = reg.polygon.min(axis=0), reg.polygon.max(axis=0)
    pad = 0.3 * (hi - lo)
    gx, gy = np.meshgrid(
        np.linspace(lo[0] - pad[0], hi[0] + pad[0], 160),
        np.linspace(lo[1] - pad[1], hi[1] + pad[1], 160),
    )
    pts = np.column_stack([gx.ravel(), gy.ravel()])
    same = _same(PAIR, pts, g, reg.intervals)
    assert same.sum() > 50
    inside = _inside(reg.polygon, pts)
    np.testing.assert_array_equal(same, inside)


@pytest.mark.parametrize("x, y, g", FEATURES[:4])
def test_radius_range(x, y, g):
    reg = ambiguity_region(PAIR, x, y, g)
    g0, g1 = ambiguity_radius_range(PAIR, x, y, g)
    assert 0 < g0 <= g <= g1
    box = reg.box
    for gi in np.linspace(g0, g1, 7)[1:-1]:
        poly = ambiguity_polygon(PAIR, reg.intervals, gi, box)
        assert len(poly) >= 3
        c = poly.mean(axis=0)
        assert _same(PAIR, c[None], gi, reg.intervals)[0]
    assert len(ambiguity_polygon(PAIR, reg.intervals, g0 * 0.99, box)) == 0
    assert len(ambiguity_polygon(PAIR, reg.intervals, g1 * 1.01, box)) == 0


def test_far_invisible_feature_is_unbounded():
    reg = ambiguity_region(PAIR, 0.0, 9000.0, 5.0)
    assert reg.intervals[0] == reg.intervals[1]  # one ommatidium per eye: invisible
    assert not reg.bounded
    assert _inside(reg.polygon, np.array([[0.0, 9000.0]]))[0]


def test_small_m_and_feature_covering_an_eye():
    pair = EyePair(40.0, 20.0, 24)
    reg = ambiguity_region(pair, 119.3, 60.9, 20.0)
    assert reg.intervals == (0, 1, 1, 3)
    assert _inside(reg.polygon, np.array([[119.3, 60.9]]))[0]
    with pytest.raises(ValueError, match="covers eye B"):
        ambiguity_region(pair, 45.0, 0.0, 10.0)
