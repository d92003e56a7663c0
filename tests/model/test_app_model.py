"""The app's model driven with plain events and no display (issue 9 item 3): drags as
press/move/release sequences, the wheel, pan, fit, undo/redo, picking, names."""

import pytest
from undo_stack import Undo

from eyeviz.model import camera, interactions
from eyeviz.model.app_model import HANDLE_PX, AppModel, MouseEvent, hit_test
from eyeviz.model.camera import Viewport
from eyeviz.model.scene import Eyes, Feature, Scene, View

VP = Viewport(0.0, 0.0, 1000.0, 700.0)


def make(view=None):
    sc = Scene(
        Eyes(40.0, 20.0, 720),
        [
            Feature("target", 0.0, 1500.0, 50.0, "#D55E00"),
            Feature("other", -1200.0, 3000.0, 200.0, "#0072B2"),
        ],
        view=view or View((0.0, 2300.0), 7000.0),
    )
    m = AppModel(sc)
    return m, Undo(m)


def ev(m, kind, x, y):
    px, py = camera.to_pixel(m.scene.view, VP, x, y)
    return MouseEvent(kind, x, y, px, py)


def gesture(m, points, which="main"):
    """press at points[0], moves through points[1:], release at the last one."""
    g = interactions.press(m, ev(m, "press", *points[0]), which, VP)
    for p in points[1:]:
        try:
            g.send(ev(m, "move", *p))
        except StopIteration:
            pass
    try:
        g.send(ev(m, "release", *points[-1]))
    except StopIteration:
        pass


def test_drag_moves_the_feature_as_one_undo_step_and_undo_restores():
    m, undo = make()
    path = [(0.0, 1500.0)] + [(30.0 * k, 1500.0 + 20.0 * k) for k in range(1, 11)]
    gesture(m, path)
    f = m.scene.features[0]
    assert (f.x, f.y) == pytest.approx((300.0, 1700.0))
    assert [t for _, _, t in undo.steps] == ["Move target"]
    assert not m.live_open
    undo.undo()
    assert (m.scene.features[0].x, m.scene.features[0].y) == (0.0, 1500.0)


def test_a_drag_frame_updates_only_the_moved_row_of_the_state(monkeypatch):
    """Each frame of a drag recomputes the dragged feature alone (eyeviz.core.single), and
    the state it reads equals a whole new one; an undo recomputes it whole."""
    import dataclasses

    import numpy as np

    import eyeviz.model.state as am  # the planar state function (app_model.STATE_FUNCTIONS)
    from eyeviz.model.state import compute_state

    m, undo = make()
    m.scene.layers = ["eyes", "bitmaps", "readout", "features"]
    m._notify("layers")
    assert m.state.n == 2
    whole = []
    monkeypatch.setattr(am, "compute_state", lambda s: whole.append(1) or compute_state(s))
    path = [(0.0, 1500.0)] + [(-130.0 * k, 1500.0 - 90.0 * k) for k in range(1, 12)]
    g = interactions.press(m, ev(m, "press", *path[0]), "main", VP)
    for p in path[1:]:
        g.send(ev(m, "move", *p))
        got, want = m.state, compute_state(m.scene)
        for f in dataclasses.fields(want):
            a, b = getattr(want, f.name), getattr(got, f.name)
            if isinstance(a, np.ndarray):
                np.testing.assert_array_equal(b, a, err_msg=f.name)
    assert whole == []
    with pytest.raises(StopIteration):
        g.send(ev(m, "release", *path[-1]))
    undo.undo()
    assert m.state.x[0] == 0.0 and whole == [1]


def test_moving_another_feature_keeps_the_selected_ones_ambiguity_region():
    m, _ = make()
    m.scene.layers = ["features", "ambiguity"]
    m._notify("layers")
    m.select(0)
    region = m.ambiguity
    assert region is not None
    m.live(1, x=-1100.0)  # the player animating another feature
    assert m.ambiguity is region
    m.live(0, x=10.0)  # the selected one: a new region
    assert m.ambiguity is not region


def test_live_changes_only_position_and_radius():
    m, _ = make()
    with pytest.raises(ValueError, match="x, y or g only, got name"):
        m.live(0, name="x")
    st = m.state
    for bad, match in (({"x": float("inf")}, "x must be finite"), ({"g": 0.0}, "g .* > 0")):
        with pytest.raises(ValueError, match=match):
            m.live(0, **bad)
    assert m.scene.features[0].x == 0.0 and m.scene.features[0].g == 50.0
    assert m.state is st  # refused before anything changed


def test_a_refused_row_update_raises_on_every_read_never_a_stale_state():
    """A state update that fails keeps failing (review: the moved rows were forgotten
    before the update, so the second read returned the old state silently)."""
    m, _ = make()
    _ = m.state
    m.scene.features[0].x = float("nan")  # past live()'s checks, as a bug elsewhere might
    m._notify("feature", 0)
    for _ in range(2):
        with pytest.raises(ValueError, match="non-finite"):
            _ = m.state


def test_click_selects_without_an_undo_step():
    m, undo = make()
    gesture(m, [(-1200.0, 3000.0), (-1199.0, 3000.0)])  # under the drag threshold
    assert m.selected == 1 and undo.steps == []


def test_handle_drag_resizes():
    m, undo = make()
    m.select(1)
    gesture(m, [(-1000.0, 3000.0), (-900.0, 3000.0), (-700.0, 3000.0)])
    assert m.scene.features[1].g == pytest.approx(500.0)
    assert undo.steps[-1][2] == "Resize other"


def test_press_on_empty_space_pans():
    m, undo = make()
    c0 = m.scene.view.center
    u = camera.units_per_px(m.scene.view, VP)
    gesture(m, [(2000.0, 500.0), (2000.0 + 50 * u, 500.0)])
    assert m.scene.view.center == pytest.approx((c0[0] - 50 * u, c0[1]))
    assert undo.steps == []  # a camera move is not an edit


def test_wheel_zooms_about_the_cursor_even_over_a_feature():
    m, undo = make()
    px, py = camera.to_pixel(m.scene.view, VP, 0.0, 1500.0)  # over "target"
    g = m.scene.features[0].g
    for _ in range(4):
        assert interactions.wheel(m, "main", VP, px, py, 1.0, resize=False) == "zoom"
    assert m.scene.features[0].g == g and undo.steps == []
    assert camera.to_model(m.scene.view, VP, px, py) == pytest.approx((0.0, 1500.0))
    assert m.scene.view.width == pytest.approx(7000.0 / 1.15**4)


@pytest.mark.parametrize("steps", [0.0, float("nan"), float("inf"), -float("inf")])
def test_a_wheel_of_no_or_non_finite_notches_does_nothing(steps):
    m, undo = make()
    view = m.scene.view
    px, py = camera.to_pixel(view, VP, 0.0, 1500.0)
    for resize in (False, True):
        assert interactions.wheel(m, "main", VP, px, py, steps, resize=resize) == "none"
    assert m.scene.view == view and m.scene.features[0].g == 50.0 and undo.steps == []


def test_zooming_out_never_resizes_a_feature_drifting_under_the_cursor():
    m, undo = make()
    px, py = camera.to_pixel(m.scene.view, VP, 600.0, 1500.0)  # empty space beside target
    for _ in range(12):
        interactions.wheel(m, "main", VP, px, py, -1.0, resize=False)
    assert m.scene.features[0].g == 50.0 and undo.steps == []


def test_modified_wheel_over_a_feature_resizes_in_one_merged_step():
    m, undo = make()
    steps = []
    m.push = lambda b, a, t, k=None: (steps.append(k), m.set_scene(a))
    px, py = camera.to_pixel(m.scene.view, VP, -1200.0, 3000.0)
    for _ in range(3):
        assert interactions.wheel(m, "main", VP, px, py, 1.0, resize=True) == "resize"
    assert m.scene.features[1].g == pytest.approx(200.0 * 1.08**3)
    assert m.selected == 1 and steps == [("wheel", 1)] * 3  # one merge key: one undo step
    # the modifier over empty space zooms
    qx, qy = camera.to_pixel(m.scene.view, VP, 3000.0, 0.0)
    assert interactions.wheel(m, "main", VP, qx, qy, 1.0, resize=True) == "zoom"


def test_zoomed_out_a_press_on_a_neighbour_never_grabs_the_selected_handle():
    m, _ = make(View((0.0, 2300.0), 1e6))  # 1000 units per px: discs are sub-pixel
    sc = Scene(features=[Feature("a", 0.0, 5000.0, 50.0), Feature("b", 4000.0, 5000.0, 50.0)])
    m.set_scene(sc)
    m.scene.view = View((0.0, 5000.0), 1e6)
    m.select(0)
    u = camera.units_per_px(m.scene.view, VP)
    # the press lands 4 px from a's centre, 4 px from b's centre; a's handle is 0.05 px off
    assert hit_test(m.scene, 0, 4000.0, 5000.0, u) == (1, "body")
    gesture(m, [(4000.0, 5000.0), (4000.0 + 20 * u, 5000.0)])
    assert m.scene.features[0].g == 50.0  # not 101,423
    assert m.scene.features[1].x == pytest.approx(4000.0 + 20 * u)


def test_a_press_on_a_tiny_neighbours_dot_beside_the_handle_grabs_the_neighbour():
    # 10 units per px: a (g = 300) selected, its handle at (300, 0); b (g = 5, half a pixel)
    # drawn as its 11 px centre dot at (340, 0), 4 px past a's handle
    m, _ = make(View((0.0, 0.0), 10.0 * VP.width))
    m.set_scene(Scene(features=[Feature("a", 0.0, 0.0, 300.0), Feature("b", 340.0, 0.0, 5.0)]))
    m.scene.view = View((0.0, 0.0), 10.0 * VP.width)
    m.select(0)
    u = camera.units_per_px(m.scene.view, VP)
    assert u == pytest.approx(10.0)
    for off_px in (2.0, 4.0, 5.5):  # on b's dot, off its centre
        assert hit_test(m.scene, 0, 340.0 - off_px * u, 0.0, u) == (1, "body"), off_px
    # a's handle, pressed clear of b's dot, still resizes a
    assert hit_test(m.scene, 0, 300.0 - 8 * u, 0.0, u) == (0, "handle")


def test_handle_is_grabbable_where_it_is_drawn_apart():
    m, _ = make()
    u = camera.units_per_px(m.scene.view, VP)
    f = m.scene.features[1]
    assert f.g / u >= HANDLE_PX
    assert hit_test(m.scene, 1, f.x + f.g + 2 * u, f.y, u) == (1, "handle")


def test_press_in_the_inset_reaches_a_feature_under_it():
    m, _ = make()
    inset = Viewport(700.0, 0.0, 300.0, 200.0)
    m.inset_view = camera.fit_inset(m.scene.eyes, inset)
    # put "other" under the inset in the main view
    x, y = camera.to_model(m.scene.view, VP, 850.0, 100.0)
    m.scene.features[1].x, m.scene.features[1].y = x, y
    e = MouseEvent("press", 0.0, 0.0, 850.0, 100.0)
    g = interactions.press(m, e, "inset", inset, "left", main_vp=VP)
    g.send(MouseEvent("move", 0, 0, 900.0, 100.0))
    g.send(MouseEvent("move", 0, 0, 950.0, 100.0))
    with pytest.raises(StopIteration):
        g.send(MouseEvent("release", 0, 0, 950.0, 100.0))
    u = camera.units_per_px(m.scene.view, VP)
    assert m.selected == 1 and m.scene.features[1].x == pytest.approx(x + 100 * u)


def test_fit_view_then_undo_redo_of_edits_keep_working():
    m, undo = make()
    interactions.fit_view(m, VP, Viewport(700.0, 0.0, 300.0, 200.0))
    v = m.scene.view
    for f in m.scene.features:
        px, py = camera.to_pixel(v, VP, f.x, f.y)
        assert 0 <= px <= 700 or py >= 200
    m.set_feature(0, x=10.0)
    interactions.toggle_estimator(m, "analytic", True)
    assert m.scene.estimators[-1] == "analytic"
    assert [t for _, _, t in undo.steps] == ["Edit target", "Show analytic predictions"]
    undo.undo()
    assert "analytic" not in m.scene.estimators


def test_set_trajectory_and_bad_kind():
    m, undo = make()
    interactions.set_trajectory(m, "circular")
    assert m.scene.trajectory.kind == "circular" and m.scene.shows("trajectory")
    with pytest.raises(ValueError, match="trajectory kind"):
        interactions.set_trajectory(m, "spiral")


def test_duplicate_names_are_copies_not_numbers():
    m, _ = make()
    m.duplicate_feature(0)
    m.duplicate_feature(0)
    m.duplicate_feature(2)
    names = [f.name for f in m.scene.features]
    assert names[2:] == ["target (copy)", "target (copy 2)", "target (copy 3)"]
    assert m.selected == 4


def test_a_live_move_of_another_feature_updates_that_row_not_the_selected_one():
    """Issue 20 item 7, mutant 1: live(i) with j selected marks row i as moved (the
    player animates a feature that is not the selection); the state then equals a whole
    new one, and listeners hear about row i."""
    import dataclasses

    import numpy as np

    from eyeviz.model.state import compute_state

    m, _ = make()
    m.scene.layers = ["eyes", "bitmaps", "readout", "features"]
    m._notify("layers")
    heard = []
    m.listeners.append(lambda what, i: heard.append((what, i)))
    for selected, moved in ((1, 0), (0, 1), (None, 1)):
        m.select(selected)
        before = m.state
        f = m.scene.features[moved]
        m.live(moved, x=f.x + 700.0, y=f.y - 300.0, g=f.g * 1.5)
        assert heard[-1] == ("feature", moved)
        got, want = m.state, compute_state(m.scene)
        assert got.x[moved] != before.x[moved]
        for fld in dataclasses.fields(want):
            a, b = getattr(want, fld.name), getattr(got, fld.name)
            if isinstance(a, np.ndarray):
                np.testing.assert_array_equal(b, a, err_msg=f"{fld.name}, moved {moved}")


def test_the_ambiguity_region_is_clipped_to_a_square_about_the_view_centre(monkeypatch):
    """The selected feature's region is clipped to a box centred on the view's centre (x
    and y each from their own coordinate), wide enough to hold the feature and the view."""
    import eyeviz.core.ambiguity as amb

    boxes = []
    real = amb.ambiguity_region
    monkeypatch.setattr(
        amb, "ambiguity_region", lambda *a, box: boxes.append(box) or real(*a, box=box)
    )
    m, _ = make(view=View((-800.0, 2600.0), 5000.0))
    m.scene.layers = ["features", "ambiguity"]
    m._notify("layers")
    m.select(0)
    assert m.ambiguity is not None and boxes
    x0, x1, y0, y1 = boxes[-1]
    assert ((x0 + x1) / 2, (y0 + y1) / 2) == pytest.approx((-800.0, 2600.0))
    assert x1 - x0 == pytest.approx(y1 - y0)
    f = m.scene.features[0]
    assert x0 < f.x < x1 and y0 < f.y < y1 and x1 - x0 >= 3 * 5000.0


def test_selecting_another_feature_gives_that_features_region_and_a_camera_move_keeps_it():
    m, _ = make()
    m.scene.layers = ["features", "ambiguity"]
    m._notify("layers")
    m.select(0)
    r0 = m.ambiguity
    m.notify_view("main")
    m.notify_view("inset")
    assert m.ambiguity is r0  # a camera move keeps the region
    m.select(1)
    r1 = m.ambiguity
    assert r1 is not r0 and r1["r_range"] != r0["r_range"]
    f = m.scene.features[1]
    assert r1["r_range"][0] <= (f.x**2 + f.y**2) ** 0.5 <= r1["r_range"][1]


def test_a_camera_move_tells_listeners_which_view_moved():
    m, _ = make()
    heard = []
    m.listeners.append(lambda what, i: heard.append((what, i)))
    m.notify_view("main")
    m.notify_view("inset")
    m.notify_view()
    assert heard == [("view", 0), ("view", 1), ("view", 0)]


def test_hit_test_ignores_a_selection_past_the_last_feature():
    m, _ = make()
    sc = m.scene
    n = len(sc.features)
    f = sc.features[0]
    for sel in (n, n + 3, -1):  # a stale index (the feature was deleted) is no selection
        assert hit_test(sc, sel, f.x, f.y, 1.0) == (0, "body")
        assert hit_test(sc, sel, 9e6, 9e6, 1.0) == (None, None)


def test_moving_the_inset_camera_stops_it_following_the_eyes_the_main_one_does_not():
    m, _ = make()
    assert m.inset_auto
    interactions.set_view(m, "main", View((5.0, 6.0), 900.0))
    assert m.inset_auto and m.scene.view == View((5.0, 6.0), 900.0)
    interactions.set_view(m, "inset", View((1.0, 2.0), 90.0))
    assert not m.inset_auto and m.inset_view == View((1.0, 2.0), 90.0)
    interactions.fit_inset(m, VP)
    assert m.inset_auto


def test_toggle_estimator_hides_one_and_keeps_the_others():
    m, undo = make()
    m.scene.estimators = ["analytic", "bayes"]
    interactions.toggle_estimator(m, "bayes", False)
    assert m.scene.estimators == ["analytic"]
    interactions.toggle_estimator(m, "compact", True)
    interactions.toggle_estimator(m, "compact", True)  # shown once however often
    assert m.scene.estimators == ["analytic", "compact"]
    assert [t for _, _, t in undo.steps][-1] == "Show compact predictions"


def test_set_trajectory_without_a_valid_selection_uses_the_defaults():
    for sel in (None, 2, 9):
        m, _ = make()
        m.selected = sel
        interactions.set_trajectory(m, "vertical")
        t = m.scene.trajectory
        assert (t.kind, t.distance, t.g) == ("vertical", 2000.0, 50.0) and m.scene.shows(
            "trajectory"
        )


def test_set_trajectory_of_the_present_kind_shows_a_hidden_layer_and_keeps_the_path():
    m, _ = make()
    interactions.set_trajectory(m, "circular")
    path = m.scene.trajectory
    m.set_layer("trajectory", False)
    assert not m.scene.shows("trajectory")
    interactions.set_trajectory(m)  # the present kind: the layer comes back, same path
    assert m.scene.shows("trajectory") and m.scene.trajectory == path
    interactions.set_trajectory(m, "circular")
    assert m.scene.shows("trajectory") and m.scene.trajectory == path


def test_set_trajectory_of_another_kind_replaces_the_path_at_the_selected_distance():
    """Asking for the present kind keeps its path even after the feature moved; another
    kind is a new path at the selected feature's distance and radius."""
    m, _ = make()
    m.select(0)
    interactions.set_trajectory(m, "circular")
    path = m.scene.trajectory
    m.set_feature(0, x=0.0, y=2500.0)
    interactions.set_trajectory(m, "circular")
    assert m.scene.trajectory == path and path.distance == pytest.approx(1500.0)
    interactions.set_trajectory(m, "vertical")
    new = m.scene.trajectory
    assert new.kind == "vertical" and new.distance == pytest.approx(2500.0)
