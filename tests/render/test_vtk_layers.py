"""Every VTK layer draws only the Frame (issue 9 item 2): a change injected into a Frame
(as a bug in eyeviz.model.frame would make) shows up in the actors' points and colours,
which a layer computing its own geometry from the scene or the state would not follow."""

import numpy as np
import pytest
import pyvista as pv

from eyeviz.model.frame import TrajectoryPath, rim_points
from eyeviz.model.scene import Eyes, Feature, Scene
from eyeviz.model.state import compute_state
from eyeviz.render.vtk.actors import SceneActors, view_frame
from eyeviz.render.vtk.overlays import OverlayActors, overlay_frame

SHIFT = np.array([7.25, -3.5])


@pytest.fixture
def rig():
    pl = pv.Plotter(off_screen=True, window_size=(400, 300))
    inset = pv.Renderer(pl)
    pl.ren_win.AddRenderer(inset)
    yield pl, SceneActors(pl.renderer, inset), OverlayActors(pl.renderer)
    pl.close()


def _scene(layers):
    fs = [
        Feature("a", 120.0, 900.0, 50.0, "#D55E00"),
        Feature("b", -200.0, 1500.0, 80.0, "#0072B2"),
    ]
    return Scene(Eyes(40.0, 20.0, 72), fs, list(layers))


def _xy(mesh):
    return np.asarray(mesh.points)[:, :2]


def test_eye_triangles_are_the_frames_rim(rig):
    _, act, _ = rig
    sc = _scene(["eyes", "features"])
    fr = view_frame(sc, compute_state(sc), 0)
    eye = fr.eyes[0]
    eye.center = (eye.center[0] + SHIFT[0], eye.center[1] + SHIFT[1])  # injected
    rim = eye.rim
    eye.rim = lambda k=1: rim(k) * 1.01  # a rim that is not the centre's circle of radius l
    act.draw(fr, 0)
    pts = _xy(act.eye_meshes[0])
    np.testing.assert_allclose(pts[0], eye.center)
    np.testing.assert_allclose(pts[1:], eye.rim())
    true_rim = rim_points((-40.0, 0.0), 20.0, 72)
    assert not np.allclose(pts[1:], true_rim)
    # lit cells follow the Frame's owners, not the state's
    eye.owner = np.roll(eye.owner, 5)
    act.draw(fr, 0)
    lit = (act.eye_meshes[0].cell_data["rgb"] != [225, 225, 225]).any(axis=1)
    np.testing.assert_array_equal(lit, eye.owner >= 0)


def test_discs_labels_and_selection_are_the_frames_arrays(rig):
    _, act, _ = rig
    sc = _scene(["eyes", "features", "labels"])
    fr = view_frame(sc, compute_state(sc), 0)
    fr.x = fr.x + SHIFT[0]  # injected into the Frame only
    fr.y = fr.y + SHIFT[1]
    fr.g = fr.g * 1.5
    for lab in fr.labels:
        lab.x += 11.0
    act.draw(fr, 0)
    # the unselected disc (feature 1): a ring of radius g about (x, y)
    ring = _xy(act.fill_mesh).reshape(2, -1, 2)[1]
    d = np.hypot(ring[:, 0] - fr.x[1], ring[:, 1] - fr.y[1])
    np.testing.assert_allclose(d, fr.g[1], rtol=1e-12)
    np.testing.assert_allclose(_xy(act.centers_mesh), [[fr.x[1], fr.y[1]]])
    # the selected disc (feature 0): placed by the live actors' transform
    live = act.live_fill
    np.testing.assert_allclose(live.GetPosition()[:2], [fr.x[0], fr.y[0]])
    np.testing.assert_allclose(live.GetScale()[:2], [fr.g[0], fr.g[0]])
    # labels at the Frame's anchors
    feats = [lab for lab in fr.labels if lab.kind == "feature"]
    got = [t.GetPosition()[:2] for t in act.labels.feature_labels]
    np.testing.assert_allclose(got, [[lab.x, lab.y] for lab in feats])
    # eye labels are built from the Frame too (rebuild with a shifted anchor)
    fr2 = view_frame(sc, compute_state(sc), 0)
    fr2.labels[0].x += 3.0
    act.labels._eyes_key = None
    act.draw(fr2, 0)
    eye_pos = [t.GetPosition()[0] for t in act.labels.main_eye_labels]
    assert eye_pos[0] == pytest.approx(fr2.labels[0].x)


def test_grey_features_are_the_frames_out_of_domain(rig):
    _, act, _ = rig
    sc = _scene(["eyes", "features"])
    fr = view_frame(sc, compute_state(sc), None)
    fr.out_of_domain = np.array([False, True])  # injected: no predictions layer at all
    act.draw(fr, None)
    assert list(act.grey) == [False, True]


def test_tangents_and_sectors_are_the_frames_points(rig):
    _, act, _ = rig
    sc = _scene(["eyes", "features", "tangents", "sectors"])
    fr = view_frame(sc, compute_state(sc), 0)
    assert {t.feature for t in fr.tangents} == {0}  # only the selected feature's
    for t in fr.tangents:
        t.ends = t.ends + SHIFT
    for s in fr.sectors:
        s.ends = s.ends + SHIFT
    act.draw(fr, 0)
    pts = _xy(act.tangent_mesh)
    for e, eye in enumerate("AB"):
        (t,) = [t for t in fr.tangents if t.eye == eye]
        np.testing.assert_allclose(pts[3 * e + 1 : 3 * e + 3], t.ends)
    sec = _xy(act.sector_mesh)
    slots = len(sec) // 2
    for e, eye in enumerate("AB"):
        (s,) = [s for s in fr.sectors if s.eye == eye]
        np.testing.assert_allclose(sec[e * slots + 1 : e * slots + 1 + len(s.ends)], s.ends)


def test_overlays_are_the_frames_predictions_ambiguity_and_path(rig):
    _, _, ov = rig
    sc = _scene(["features", "predictions", "ambiguity", "trajectory"])
    sc.estimators = ["analytic"]
    st = compute_state(sc)
    r, phi = np.hypot(st.x, st.y), np.arctan2(st.y, st.x)
    preds = {"analytic": (r * 1.01, phi)}
    square = np.array([[0.0, 800.0], [300.0, 800.0], [300.0, 1100.0], [0.0, 1100.0]])
    amb = {"polygon": square, "bounded": True}
    xs = np.linspace(-500.0, 500.0, 9)
    path = TrajectoryPath("horizontal", xs, np.full(9, 1200.0), 50.0, xs, "x", {})
    fr = overlay_frame(sc, st, 0, preds, amb, path)
    pf = fr.predictions["analytic"]
    pf.x_hat = pf.x_hat + SHIFT[0]  # injected into the Frame
    pf.y_hat = pf.y_hat + SHIFT[1]
    fr.ambiguity[0] = {"polygon": square + SHIFT, "bounded": True}
    fr.trajectory = TrajectoryPath("horizontal", xs + 1.0, np.full(9, 1201.0), 50.0, xs, "x", {})
    ov.draw(fr, 0)
    np.testing.assert_allclose(_xy(ov.ghost_points), np.column_stack([pf.x_hat, pf.y_hat]))
    np.testing.assert_allclose(ov.ghosts["analytic"], np.column_stack([pf.x_hat, pf.y_hat]))
    np.testing.assert_allclose(ov.amb_polygon, square + SHIFT)
    fill = ov.ambiguity.amb_fill.GetMapper().GetInput()
    np.testing.assert_allclose(_xy(pv.wrap(fill)), square + SHIFT)
    np.testing.assert_allclose(_xy(ov.trajectory.mesh), np.column_stack([xs + 1.0, [1201.0] * 9]))
    # and update() draws the Frame it builds from the same inputs (no injection)
    ov.update(sc, st, 0, preds, amb, path)
    np.testing.assert_allclose(ov.amb_polygon, square)
    np.testing.assert_allclose(ov.ghosts["analytic"][:, 0], r * 1.01 * np.cos(phi))


def test_the_bfv_line_is_the_frames_theta_and_psi(rig):
    _, act, _ = rig
    sc = _scene(["eyes", "bfv", "features", "labels"])
    fr = view_frame(sc, compute_state(sc), None)
    act.draw(fr, None)
    text = act.labels.bfv_text["inset"].GetInput()
    assert text == "m = 72  θ = 120°  ψ = 30°"  # h = 2 l: theta = 120°, psi = 30° (Eq. 15-16)
    assert act.labels.bfv_text["inset"].GetVisibility()
    sc.layers.remove("bfv")  # without the bfv layer: m only, and the line is hidden
    act.draw(view_frame(sc, compute_state(sc), None), None)
    assert act.labels.bfv_text["inset"].GetInput() == "m = 72"
    assert not act.labels.bfv_text["inset"].GetVisibility()
