"""theta and psi (Definition 2, Figures 5-6) drawn in the app's view as in the exported
figure (issue 24): arcs between the BFV's edges and the x-axis, and their labels, only
where the origin is in view."""

import math

import numpy as np
import pytest
import pyvista as pv

from eyeviz.model.scene import Eyes, Feature, Scene
from eyeviz.model.state import compute_state
from eyeviz.render.vtk.actors import SceneActors, view_frame
from eyeviz.render.vtk.layers.bfv import angle_marks

PSI = math.asin(20.0 / 40.0)  # Eq. 15: psi = arcsin(l / h) = 30 deg


def _angles(arc):
    return np.degrees(np.arctan2(arc[:, 1], arc[:, 0]))


def test_theta_spans_the_wedge_and_psi_the_x_axis_to_the_right_edge():
    m = angle_marks(PSI, 40.0, (-1000.0, 1000.0, -100.0, 1900.0))
    assert m is not None
    th, ps = m["theta"], m["psi"]
    assert _angles(th)[[0, -1]] == pytest.approx([30.0, 150.0])  # theta = 120 deg (Eq. 16)
    assert _angles(ps)[[0, -1]] == pytest.approx([0.0, 30.0])
    r = np.hypot(*th.T)
    assert r == pytest.approx(np.full_like(r, 0.2 * 2000.0))  # a fifth of the view's height
    assert np.hypot(*ps.T) == pytest.approx(np.full(len(ps), 0.72 * 400.0))
    x, y = m["theta_at"]
    assert x == 0.0 and y > r[0]  # theta's label above its arc, on the axis
    px, py = m["psi_at"]
    assert math.degrees(math.atan2(py, px)) == pytest.approx(15.0)  # halfway up psi


def test_close_up_the_arcs_clear_the_eyes_and_far_away_they_are_not_drawn():
    m = angle_marks(PSI, 40.0, (-100.0, 100.0, -10.0, 90.0))
    # both arcs outside the eyes (h + l = 60): theta at 1.5 (h + l), psi at 1.15 (h + l)
    assert m is not None and np.hypot(*m["theta"][0]) == pytest.approx(90.0)
    assert np.hypot(*m["psi"][0]) == pytest.approx(69.0)
    assert angle_marks(PSI, 40.0, (500.0, 900.0, 100.0, 400.0)) is None  # origin not in view


@pytest.fixture
def actors():
    pl = pv.Plotter(off_screen=True, window_size=(400, 300))
    inset = pv.Renderer(pl)
    pl.ren_win.AddRenderer(inset)
    yield pl, SceneActors(pl.renderer, inset)
    pl.close()


def test_the_view_draws_the_labels_with_the_bfv_layer_only(actors):
    pl, act = actors
    sc = Scene(Eyes(40.0, 20.0, 72), [Feature("a", 0.0, 300.0, 20.0)], ["eyes", "bfv"])
    rect = (-400.0, 400.0, -50.0, 550.0)
    act.draw(view_frame(sc, compute_state(sc), 0, rect), 0)
    bfv = act.bfv
    assert bfv.theta_label.GetInput() == "θ = 120°" and bfv.psi_label.GetInput() == "ψ = 30°"
    assert bfv.arc_actor.GetVisibility() and bfv.theta_label.GetVisibility()
    assert pl.renderer.HasViewProp(bfv.theta_label) and pl.renderer.HasViewProp(bfv.arc_actor)
    assert np.hypot(*np.asarray(bfv.arcs.points)[0, :2]) == pytest.approx(0.2 * 600.0)
    sc.layers.remove("bfv")
    act.draw(view_frame(sc, compute_state(sc), 0, rect), 0)
    assert not pl.renderer.HasViewProp(bfv.theta_label)
    assert not pl.renderer.HasViewProp(bfv.arc_actor)


def test_the_labels_step_aside_for_a_feature_and_its_name(actors):
    pl, act = actors
    rect = (-400.0, 400.0, -50.0, 550.0)
    m = angle_marks(PSI, 40.0, rect)
    px, py = m["psi_at"]
    tx, ty = m["theta_at"]
    # a small disc whose name covers psi's place, and a disc on theta's
    feats = [
        Feature("a long feature name", px - 40.0, py - 10.0, 3.0),
        Feature("b", tx, ty + 10.0, 15.0),
    ]
    sc = Scene(Eyes(40.0, 20.0, 72), feats, ["eyes", "bfv", "features", "labels"])
    pl.render()
    act.draw(view_frame(sc, compute_state(sc), 0, rect), 0)
    bfv = act.bfv
    x, y, _ = bfv.psi_label.GetPosition()
    assert x == pytest.approx(-px) and y == pytest.approx(py)  # mirrored to the left edge
    arc = np.asarray(bfv.arcs.points)[49:98, :2]
    assert np.all(arc[:, 0] <= 1e-9)  # psi's arc between the left edge and the -x axis
    _, ty2, _ = bfv.theta_label.GetPosition()
    assert ty2 != pytest.approx(ty)  # theta's label moved off the disc
    # without the features both sit where the figure puts them
    sc.features = []
    act.draw(view_frame(sc, compute_state(sc), None, rect), None)
    assert bfv.psi_label.GetPosition()[0] == pytest.approx(px)
    assert bfv.theta_label.GetPosition()[1] == pytest.approx(ty)
