"""The 3D view's model without Qt or VTK: picking through the camera, a drag as one
generator and one undo step, depth drags, keyboard nudges."""

from __future__ import annotations

import math

import numpy as np
import pytest

from eyeviz import EyevizError
from eyeviz.model import app_model3d as m3
from eyeviz.model import state3d
from eyeviz.model.camera3d import Camera3D, basis, preset, project, to_pixels
from eyeviz.model.scene import Eyes, Feature, Scene

W, H = 600.0, 400.0


def _scene() -> Scene:
    return Scene(
        Eyes(40.0, 20.0, nside=8),
        [
            Feature("a", 0.0, 300.0, 60.0, "#D55E00", 0.0),
            Feature("b", 150.0, 250.0, 50.0, "#0072B2", 150.0),
        ],
        ["eyes", "features"],
    )


def _model():
    m = m3.AppModel3D(_scene())
    steps = []

    def push(before, after, text, merge_key=None):
        if steps and merge_key is not None and steps[-1][3] == merge_key:
            steps[-1] = (steps[-1][0], after, text, merge_key)
        else:
            steps.append((before, after, text, merge_key))
        m.set_scene(after)

    m.push = push
    return m, steps


def _px(cam, p):
    xy, _ = project(cam, np.asarray(p, float), W / H)
    c, r = to_pixels(xy, int(W), int(H))
    return float(c), float(r)


def test_ray_goes_through_the_pixel_a_point_projects_to():
    cam = preset("default", 40.0, 20.0, 600.0)
    p = np.array([120.0, 280.0, -40.0])
    c, r = _px(cam, p)
    o, d = m3.ray(cam, m3.Pointer("press", c, r, W, H))
    miss = np.linalg.norm(np.cross(p - o, d))
    assert miss < 1e-6 * np.linalg.norm(p - o)


def test_pick_takes_the_nearest_ball_under_the_pointer():
    cam = preset("front", 40.0, 20.0, 600.0)  # from +y looking back
    x, y, z, g = [0.0, 0.0], [300.0, 200.0], [0.0, 0.0], [60.0, 30.0]
    c, r = _px(cam, (0.0, 300.0, 0.0))
    p = m3.Pointer("press", c, r, W, H)
    assert m3.pick_ball(cam, p, x, y, z, g) == 0  # ball 0 is nearer the camera (y 300)
    # beside both balls, far from them on screen: nothing
    assert m3.pick_ball(cam, m3.Pointer("press", 5.0, 5.0, W, H), x, y, z, g) is None
    assert m3.pick_ball(cam, p, [], [], [], []) is None


def test_drag_moves_in_the_plane_facing_the_camera_as_one_undo_step():
    m, steps = _model()
    cam = preset("top", 40.0, 20.0, 600.0)
    c, r = _px(cam, (0.0, 300.0, 0.0))
    gen = m3.drag_ball(m, cam, m3.Pointer("press", c + 10, r, W, H), 0)
    next(gen)
    for k in range(1, 6):
        gen.send(m3.Pointer("move", c + 10 + 8 * k, r - 5 * k, W, H))
    assert m.live_open and not steps  # during the drag: no step yet
    with pytest.raises(StopIteration):
        gen.send(m3.Pointer("release", c + 50, r - 25, W, H))
    assert len(steps) == 1 and steps[0][2] == "Move a"
    f = m.scene.features[0]
    assert f.z == pytest.approx(0.0, abs=1e-9)  # the top view's plane is z = const
    # the ball's centre is now under where the grab point went (offset kept)
    c1, r1 = _px(cam, (f.x, f.y, f.z))
    assert c1 == pytest.approx(c + 40, abs=1e-6) and r1 == pytest.approx(r - 25, abs=1e-6)
    assert steps[0][0].features[0].x == 0.0  # before: the scene at the press


def test_a_click_selects_without_an_undo_step():
    m, steps = _model()
    cam = preset("top", 40.0, 20.0, 600.0)
    c, r = _px(cam, (150.0, 250.0, 150.0))
    gen = m3.drag_ball(m, cam, m3.Pointer("press", c, r, W, H), 1)
    next(gen)
    gen.send(m3.Pointer("move", c + 1, r, W, H))
    with pytest.raises(StopIteration):
        gen.send(m3.Pointer("release", c + 1, r, W, H))
    assert m.selected == 1 and not steps


def test_depth_drag_moves_along_the_line_of_sight():
    m, steps = _model()
    cam = preset("default", 40.0, 20.0, 600.0)
    c, r = _px(cam, (0.0, 300.0, 0.0))
    gen = m3.drag_ball(m, cam, m3.Pointer("press", c, r, W, H), 0, depth=True)
    next(gen)
    gen.send(m3.Pointer("move", c, r - 100, W, H))
    gen.close()
    f = m.scene.features[0]
    o = np.asarray(cam.position)
    new = np.array([f.x, f.y, f.z])
    old = np.array([0.0, 300.0, 0.0])
    # 100 px up: farther by 100 pixels' span in the screen plane at the ball's depth
    _, _, back = basis(cam)
    span = 100 * 2.0 * float((o - old) @ back) * math.tan(math.radians(cam.view_angle) / 2) / H
    assert np.linalg.norm(new - o) == pytest.approx(np.linalg.norm(old - o) + span)
    assert _px(cam, new) == pytest.approx((c, r), abs=1e-6)  # still under the pointer
    assert len(steps) == 1


def test_nudges_of_one_ball_merge_into_one_step():
    m, steps = _model()
    cam = preset("top", 40.0, 20.0, 600.0)
    right, up, _ = basis(cam)
    for _ in range(3):
        assert m3.nudge(m, cam, H, dx=1)
    m3.nudge(m, cam, H, dy=1)
    assert len(steps) == 1 and steps[0][2] == "Nudge a"
    f = m.scene.features[0]
    c = _px(cam, (f.x, f.y, f.z))
    c0 = _px(cam, (0.0, 300.0, 0.0))
    assert c[0] - c0[0] == pytest.approx(3 * m3.NUDGE_PX, rel=1e-6)
    assert c0[1] - c[1] == pytest.approx(m3.NUDGE_PX, rel=1e-6)
    d0 = np.linalg.norm(np.array([f.x, f.y, f.z]) - cam.position)
    m3.nudge(m, cam, H, dz=1)
    f = m.scene.features[0]
    d1 = np.linalg.norm(np.array([f.x, f.y, f.z]) - cam.position)
    assert d1 == pytest.approx(d0 * math.exp(m3.NUDGE_DEPTH))
    m.select(None)
    assert m3.nudge(m, cam, H, dx=1) is False


def test_live_refuses_what_the_scene_cannot_hold():
    m, _ = _model()
    with pytest.raises(ValueError, match="x must be finite"):
        m.live(0, x=float("nan"))
    with pytest.raises(ValueError, match="live\\(\\) changes"):
        m.live(0, name="z")
    assert m.scene.features[0].x == 0.0


def test_state_follows_the_scene():
    m, _ = _model()
    lit0 = m.state.lit(0, "A").copy()
    m.begin_live("Move a")
    m.live(0, x=-150.0)
    assert not np.array_equal(m.state.lit(0, "A"), lit0)
    m.end_live()


def test_edits_are_undo_steps():
    m, steps = _model()
    m.add_ball(0.0, 500.0, 10.0, 40.0)
    assert m.scene.features[-1].z == 10.0 and m.selected == 2
    m.duplicate_ball(0)
    m.delete_ball(1)
    m.set_layer("tangents", True)
    assert [s[2] for s in steps] == ["Add ball", "Duplicate a", "Delete b", "Show tangents"]
    assert isinstance(preset("side", 40.0, 20.0, 1.0), Camera3D)


def test_hiding_a_layer_removes_it_and_hiding_a_hidden_one_changes_nothing():
    m, steps = _model()
    m.set_layer("features", False)
    assert m.scene.layers == ["eyes"] and steps[-1][2] == "Hide features"
    m.set_layer("tangents", False)  # not shown: the scene keeps its layers
    assert m.scene.layers == ["eyes"] and steps[-1][1].layers == ["eyes"]


def test_lit_sets_beyond_the_view_bound_are_refused_and_nothing_moves(monkeypatch):
    m, steps = _model()
    n0 = sum(int(c[1].size) for c in (m.state.lit_a, m.state.lit_b))
    monkeypatch.setattr(state3d, "MAX_VIEW_LIT", n0 + 10)
    m.begin_live("Move a")
    with pytest.raises(ValueError, match="3D view draws at most"):
        m.live(0, y=60.0)  # next to the eyes: a large cap on each
    assert m.scene.features[0].y == 300.0
    m.end_live()
    after = m.scene.copy()
    after.features[0].y = 60.0
    with pytest.raises(EyevizError, match="3D view draws at most"):
        m.commit(after, "Move a")
    assert not steps and m.scene.features[0].y == 300.0


def test_a_live_move_computes_the_state_once(monkeypatch):
    m, _ = _model()
    calls = []
    real = state3d.compute_state3d
    monkeypatch.setattr(state3d, "compute_state3d", lambda sc: (calls.append(1), real(sc))[1])
    m.begin_live("Move a")
    m.live(0, x=-40.0)
    st = m.state
    assert len(calls) == 1 and st.x[0] == -40.0  # the listener's read is the live one's
    m.end_live()
