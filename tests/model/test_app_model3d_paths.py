"""Paths through the 3D view's model that the main tests did not pin: the selection after
an undo that removes the selected ball, picking the front surface of a large ball over a
small one behind it, and the drag threshold's edge."""

from __future__ import annotations

import numpy as np
import pytest

from eyeviz.model import app_model3d as m3
from eyeviz.model.camera3d import preset, project, to_pixels
from eyeviz.model.scene import Eyes, Feature, Scene

W, H = 600.0, 400.0


def _model():
    scene = Scene(
        Eyes(40.0, 20.0, nside=8),
        [
            Feature("a", 0.0, 300.0, 60.0, "#D55E00", 0.0),
            Feature("b", 150.0, 250.0, 50.0, "#0072B2", 150.0),
        ],
        ["eyes", "features"],
    )
    m = m3.AppModel3D(scene)
    steps: list = []

    def push(before, after, text, merge_key=None):
        steps.append((before, after, text, merge_key))
        m.set_scene(after)

    m.push = push
    return m, steps


def _px(cam, p):
    xy, _ = project(cam, np.asarray(p, float), W / H)
    c, r = to_pixels(xy, int(W), int(H))
    return float(c), float(r)


def test_add_a_ball_undo_then_delete_the_selection():
    m, steps = _model()
    m.add_ball(0.0, 400.0, 0.0, 30.0)
    assert m.selected == 2
    m.set_scene(steps[-1][0])  # undo: the added (selected) ball is gone
    assert len(m.scene.features) == 2
    assert m.selected == 1  # the last ball left, not an index past the end
    m.delete_ball(m.selected)
    assert [f.name for f in m.scene.features] == ["a"]
    m.set_scene(Scene(m.scene.eyes, [], m.scene.layers))
    assert m.selected is None


def test_pick_takes_the_front_surface_of_a_large_ball_over_a_small_one_behind():
    cam = preset("front", 40.0, 20.0, 600.0)  # from +y: larger y is nearer the camera
    # big: front 100 nearer than the small one's front, back 60 farther than its back
    x, y, z, g = [0.0, 0.0], [300.0, 250.0], [0.0, 0.0], [100.0, 10.0]
    c, r = _px(cam, (0.0, 250.0, 0.0))
    assert m3.pick_ball(cam, m3.Pointer("press", c, r, W, H), x, y, z, g) == 0


@pytest.mark.parametrize(("travel", "dragged"), [(4.0, True), (3.999, False)])
def test_a_move_of_the_threshold_is_a_drag_and_less_is_a_click(travel, dragged):
    assert m3.DRAG_THRESHOLD_PX == 4.0
    m, steps = _model()
    cam = preset("top", 40.0, 20.0, 600.0)
    c, r = _px(cam, (0.0, 300.0, 0.0))
    gen = m3.drag_ball(m, cam, m3.Pointer("press", c, r, W, H), 0)
    next(gen)
    gen.send(m3.Pointer("move", c + travel, r, W, H))
    with pytest.raises(StopIteration):
        gen.send(m3.Pointer("release", c + travel, r, W, H))
    assert len(steps) == (1 if dragged else 0)
    moved = m.scene.features[0].x != 0.0
    assert moved is dragged
