"""Camera maths without a display: pixel <-> model, zoom about the cursor, pan, fit."""

import math

import pytest

from eyeviz.model import camera
from eyeviz.model.camera import Viewport
from eyeviz.model.scene import Eyes, Feature, Scene, View

VP = Viewport(0.0, 0.0, 1000.0, 600.0)


def test_pixel_model_round_trip_and_centre():
    v = View((10.0, 2000.0), 5000.0)
    assert camera.to_model(v, VP, 500.0, 300.0) == (10.0, 2000.0)
    x, y = camera.to_model(v, VP, 0.0, 0.0)  # top left
    assert (x, y) == pytest.approx((10.0 - 2500.0, 2000.0 + 1500.0))
    for px, py in ((3.0, 7.0), (999.0, 1.0), (250.5, 599.0)):
        assert camera.to_pixel(v, VP, *camera.to_model(v, VP, px, py)) == pytest.approx((px, py))


def test_zoom_keeps_the_point_under_the_cursor():
    v = View((0.0, 2500.0), 8000.0)
    px, py = 830.0, 120.0
    before = camera.to_model(v, VP, px, py)
    z = camera.zoom_about(v, VP, px, py, 1 / 1.15)
    assert z.width == pytest.approx(8000.0 / 1.15)
    assert camera.to_model(z, VP, px, py) == pytest.approx(before)
    with pytest.raises(ValueError, match="zoom factor"):
        camera.zoom_about(v, VP, px, py, 0.0)
    assert camera.zoom_about(v, VP, px, py, 1e30).width == camera.MAX_WIDTH


def test_pan_follows_the_cursor():
    v = View((0.0, 0.0), 1000.0)  # 1 unit per px
    p = camera.pan(v, VP, 10.0, -20.0)
    assert p.center == (-10.0, -20.0)


def test_fit_view_shows_everything_clear_of_the_inset():
    sc = Scene(
        Eyes(40, 20, 720),
        [Feature("a", 0.0, 3000.0, 50.0), Feature("b", 2500.0, 1000.0, 300.0)],
    )
    inset = Viewport(700.0, 0.0, 300.0, 200.0)  # top-right corner
    v = camera.fit_view(sc, VP, inset)
    for f in sc.features:
        for dx, dy in ((f.g, 0), (-f.g, 0), (0, f.g), (0, -f.g)):
            px, py = camera.to_pixel(v, VP, f.x + dx, f.y + dy)
            assert 0 <= px <= VP.width and 0 <= py <= VP.height
            assert not inset.contains(px, py), (f.name, px, py)
    # without an inset the same content fits in a smaller width
    assert camera.fit_view(sc, VP).width <= v.width


def test_fit_view_keeps_the_title_band_and_the_label_band_free():
    sc = Scene(
        Eyes(40, 20, 720),
        [Feature("far", -1400.0, 3800.0, 250.0), Feature("side", 1700.0, 2200.0, 120.0)],
    )
    inset = Viewport(0.0, 400.0, 300.0, 200.0)  # bottom-left corner
    v = camera.fit_view(sc, VP, inset, top=48.0, right=120.0)
    for f in sc.features:
        for dx, dy in ((f.g, 0), (-f.g, 0), (0, f.g), (0, -f.g)):
            px, py = camera.to_pixel(v, VP, f.x + dx, f.y + dy)
            assert py >= 48.0, (f.name, py)  # not under the title
            assert px <= VP.width - 120.0, (f.name, px)  # room for its label
            assert not inset.contains(px, py)
    assert camera.fit_view(sc, VP, inset).width <= v.width


def test_fit_inset_shows_both_eyes():
    e = Eyes(40, 20, 720)
    vp = Viewport(700.0, 0.0, 300.0, 200.0)
    v = camera.fit_inset(e, vp)
    for x in (-(e.h + e.l), e.h + e.l):
        px, py = camera.to_pixel(v, vp, x, 0.0)
        assert vp.contains(px, py)
    assert math.isfinite(v.width) and v.width > 2 * (e.h + e.l)


def test_discs_meet_one_disc_as_many():
    """The plain-float path for a few discs (a drag frame) answers as the array path."""
    import numpy as np

    rng = np.random.default_rng(3)
    view, vp = View((100.0, 2000.0), 5000.0), Viewport(0.0, 0.0, 900.0, 600.0)
    rect = Viewport(0.0, 420.0, 270.0, 180.0)
    far = ([1e7] * 4, [1e7] * 4, [1.0] * 4)  # four discs nowhere near: forces the array path
    xs = list(rng.uniform(-3000, 3000, 400)) + [np.inf, -np.inf, np.nan, 0.0]
    ys = list(rng.uniform(-1000, 5000, 400)) + [0.0, 1.0, 2.0, np.inf]
    gs = list(rng.uniform(1, 800, 400)) + [5.0, 5.0, 5.0, 5.0]
    hits = 0
    for x, y, g in zip(xs, ys, gs, strict=True):
        for min_px in (0.0, 6.0):
            one = camera.discs_meet(view, vp, [x], [y], [g], rect, min_px)
            many = camera.discs_meet(
                view, vp, [x, *far[0]], [y, *far[1]], [g, *far[2]], rect, min_px
            )
            assert one == many, (x, y, g, min_px)
            hits += one
    assert 0 < hits < 800  # both answers occur


def test_fit_view_ignores_a_hidden_inset_of_zero_size():
    """An inset of zero width or height (hidden) leaves the whole viewport to the scene."""
    sc = Scene(
        Eyes(40, 20, 720),
        [Feature("a", 0.0, 3000.0, 50.0), Feature("b", 2500.0, 1000.0, 300.0)],
    )
    free = camera.fit_view(sc, VP)
    for hidden in (Viewport(700.0, 0.0, 0.0, 200.0), Viewport(700.0, 0.0, 300.0, 0.0)):
        assert camera.fit_view(sc, VP, hidden) == free


def test_fit_view_puts_a_wide_scene_below_a_top_corner_inset_full_width():
    """A wide, flat scene gets the full-width band below the inset (the larger picture),
    not the narrower full-height band beside it."""
    sc = Scene(
        Eyes(40, 20, 720),
        [Feature("a", -6000.0, 1200.0, 50.0), Feature("b", 6000.0, 1500.0, 50.0)],
    )
    inset = Viewport(700.0, 0.0, 300.0, 200.0)
    v = camera.fit_view(sc, VP, inset)
    px = [camera.to_pixel(v, VP, f.x, f.y) for f in sc.features]
    assert max(p[0] for p in px) > inset.left  # wider than the band beside the inset
    assert all(p[1] > inset.top + inset.height for p in px)  # and below it
