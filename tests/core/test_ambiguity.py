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


# --- the annulus and the view (issue 13) ---------------------------------------------------

from hypothesis import HealthCheck, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

from eyeviz.core.ambiguity import AmbiguityRegion  # noqa: E402

ISSUE_FEATURE = (9.760288422542875, 40.44349772929664, 50.49839135687297)
PAIRS = [EyePair(40.0, 20.0, 720), EyePair(40.0, 20.0, 24), EyePair(30.0, 10.0, 64)]


def _near_inside(poly, pts, rel=1e-7):
    """Inside the closed polygon up to a relative tolerance (the polygon is rounded)."""
    if len(poly) < 3:
        return np.zeros(len(pts), bool)
    a, b = poly, np.roll(poly, -1, axis=0)
    d = b - a
    cross = d[None, :, 0] * (pts[:, 1:2] - a[None, :, 1]) - d[None, :, 1] * (
        pts[:, 0:1] - a[None, :, 0]
    )
    tol = (
        rel
        * (np.abs(poly).max() + np.abs(pts).max(axis=1, keepdims=True))
        * np.linalg.norm(d, axis=1)[None]
    )
    return np.all(cross >= -tol, axis=1)


@st.composite
def annulus_features(draw):
    """Features whose disc nearly covers an eye: g < r_E < g / cos(gamma/2), plus some
    just outside that annulus and ordinary ones."""
    pair = draw(st.sampled_from(PAIRS))
    kind = draw(st.sampled_from(["annulus", "annulus", "edge", "plain"]))
    g = draw(st.floats(1.0, 400.0))
    cx = draw(st.sampled_from([-pair.h, pair.h]))
    ang = draw(st.floats(0.05, math.pi - 0.05))
    outer = g / math.cos(pair.gamma / 2)
    if kind == "annulus":
        r = g + draw(st.floats(1e-6, 1.0)) * (outer - g)
    elif kind == "edge":
        r = outer * (1 + draw(st.floats(0.0, 1e-3)))
    else:
        r = g * draw(st.floats(1.05, 50.0))
    x, y = cx + r * math.cos(ang), r * math.sin(ang)
    other = -cx
    if math.hypot(x - other, y) <= g:  # covers the other eye: no polygon at all
        y += 3 * g + 2 * pair.h
    return pair, x, y, g


def _region(pair, x, y, g) -> AmbiguityRegion:
    reg = ambiguity_region(pair, x, y, g)
    assert isinstance(reg.exact, bool)
    return reg


def test_issue_example_is_flagged_unknown_and_radius_range_holds_g():
    reg = _region(PAIRS[0], *ISSUE_FEATURE)
    assert not reg.exact and [a[0] for a in reg.annuli] == ["B"]
    name, cx, r_in, r_out = reg.annuli[0]
    r_b = math.hypot(ISSUE_FEATURE[0] - cx, ISSUE_FEATURE[1])
    assert r_in < r_b < r_out  # the feature lies in the flagged annulus
    g0, g1 = ambiguity_radius_range(PAIRS[0], *ISSUE_FEATURE)
    assert g0 <= ISSUE_FEATURE[2] <= g1


@pytest.mark.slow
@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(annulus_features())
def test_feature_in_its_own_region_or_unknown(feat):
    pair, x, y, g = feat
    reg = _region(pair, x, y, g)
    g0, g1 = ambiguity_radius_range(pair, x, y, g)
    assert g0 <= g <= g1
    if reg.exact:
        assert _near_inside(reg.hull, np.array([[x, y]]))[0], reg
        r0, r1 = reg.distance_range()
        assert r0 * (1 - 1e-9) <= math.hypot(x, y) <= r1 * (1 + 1e-9)
    else:
        # the feature is either in the polygon or in one of the flagged annuli
        in_ring = any(
            r_in <= math.hypot(x - cx, y) * (1 + 1e-12) and math.hypot(x - cx, y) <= r_out * 1.0001
            for _, cx, r_in, r_out in reg.annuli
        )
        assert in_ring or _near_inside(reg.hull, np.array([[x, y]]))[0]


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(annulus_features(), st.integers(0, 2**32 - 1))
def test_exact_region_holds_every_matching_centre_nearby(feat, seed):
    """When the region says exact, every centre near the feature that lights the same
    intervals lies in the polygon (samples at several scales around the feature)."""
    pair, x, y, g = feat
    reg = _region(pair, x, y, g)
    if not reg.exact:
        return
    rng = np.random.default_rng(seed)
    scales = np.repeat([1e-6, 1e-3, 1e-2, 1e-1], 200)[:, None] * (g + math.hypot(x, y))
    pts = np.array([x, y]) + rng.normal(size=(len(scales), 2)) * scales
    same = _same(pair, pts, g, reg.intervals)
    assert _near_inside(reg.hull, pts[same], rel=1e-6).all()


@settings(max_examples=100, deadline=None)
@given(
    annulus_features(),
    st.floats(1e-9, 1e7),
    st.floats(-1e4, 1e4),
    st.floats(-1e4, 1e4),
)
def test_ranges_do_not_depend_on_the_box(feat, width, cx, cy):
    pair, x, y, g = feat
    ref = ambiguity_region(pair, x, y, g)
    box = (cx - width, cx + width, cy - width, cy + width)
    reg = ambiguity_region(pair, x, y, g, box=box)
    assert reg.bounded == ref.bounded and reg.exact == ref.exact
    np.testing.assert_array_equal(reg.distance_range(), ref.distance_range())
    np.testing.assert_array_equal(reg.azimuth_range(), ref.azimuth_range())
    assert ambiguity_radius_range(pair, x, y, g, box=box) == ambiguity_radius_range(pair, x, y, g)
    if len(reg.polygon):  # the box only clips the drawing
        assert (reg.polygon[:, 0] >= box[0] - 1e-6 * width).all()
        assert (reg.polygon[:, 0] <= box[1] + 1e-6 * width).all()


def test_tiny_view_does_not_fail_and_gives_the_default_ranges():
    x, y, g = 0.0, 1500.0, 50.0
    full = ambiguity_region(PAIR, x, y, g)
    for w in (10.0, 1e-3, 1e-9):
        box = (x - w, x + w, y - w, y + w)
        reg = ambiguity_region(PAIR, x, y, g, box=box)
        assert reg.bounded and reg.distance_range() == full.distance_range()
        assert ambiguity_radius_range(PAIR, x, y, g, box=box) == ambiguity_radius_range(
            PAIR, x, y, g
        )
    # a view nowhere near the feature: nothing to draw, same ranges
    reg = ambiguity_region(PAIR, x, y, g, box=(1e5, 1e5 + 1, 1e5, 1e5 + 1))
    assert len(reg.polygon) == 0 and reg.distance_range() == full.distance_range()
    lo, hi = full.distance_range()
    assert 1400 < lo < 1500 < hi < 1800
    with pytest.raises(ValueError, match="box must be finite"):
        ambiguity_region(PAIR, x, y, g, box=(0, 0, 1, 1))


def test_unbounded_region_reports_infinite_distance():
    reg = ambiguity_region(PAIR, 0.0, 9000.0, 5.0)
    assert not reg.bounded and len(reg.rays)
    assert reg.distance_range()[1] == math.inf
    lo, hi = reg.azimuth_range()
    assert lo < math.pi / 2 < hi


@pytest.mark.parametrize("x, y, g", [(0.0, 0.0, 1.0), (0.0, 0.1, 5.0), (1.0, 0.0, 2.0)])
def test_a_region_around_the_origin_has_distance_range_from_zero(x, y, g):
    """A feature on the origin (between the eyes): its region holds the origin, so the
    nearest distance is 0 and the feature's own distance lies in the range."""
    r0, r1 = ambiguity_region(PAIR, x, y, g).distance_range()
    assert r0 == 0.0 and r0 <= math.hypot(x, y) <= r1


def _nearest_distance(poly):
    """0 when the convex polygon holds the origin (winding by angles), else the least
    distance from the origin to its edges, sampled finely (an oracle apart from the code)."""
    ang = np.arctan2(poly[:, 1], poly[:, 0])
    turn = np.angle(np.exp(1j * (np.roll(ang, -1) - ang))).sum()
    if abs(turn) > np.pi:
        return 0.0
    t = np.linspace(0.0, 1.0, 2001)[:, None, None]
    pts = poly[None] + t * (np.roll(poly, -1, axis=0) - poly)[None]
    return float(np.hypot(pts[..., 0], pts[..., 1]).min())


@pytest.mark.parametrize("x", [-30.0, -3.0, 0.0, 2.0, 25.0])
@pytest.mark.parametrize("y, g", [(0.0, 1.0), (0.3, 2.0), (1.0, 0.5), (4.0, 6.0), (20.0, 3.0)])
def test_nearest_distance_of_regions_near_the_origin(x, y, g):
    reg = ambiguity_region(PAIR, x, y, g)
    poly = reg.polygon if reg.hull is None else reg.hull
    want = _nearest_distance(poly)
    assert reg.distance_range()[0] == pytest.approx(want, rel=1e-5, abs=1e-6 * (1 + want))
