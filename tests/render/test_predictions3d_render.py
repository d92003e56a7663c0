"""The 3D predictions layer drawn (issue 23 item 4): the VTK ghosts (off-screen, EGL)
and the vector figure's, at the estimators' answers projected through the camera."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from eyeviz.model import predictions3d as p3
from eyeviz.model.camera3d import project, to_pixels
from eyeviz.model.scene import load
from eyeviz.model.state3d import compute_state3d
from eyeviz.render.vtk.style import hex_rgb

SCENES = Path(__file__).resolve().parents[2] / "assets" / "scenes"


@pytest.fixture(scope="module")
def scene_preds():
    sc = load(SCENES / "sphere_predictions.toml")
    st = compute_state3d(sc)
    preds = p3.scene_predictions3d(sc, st, 0, p3.Predictor3D())
    assert preds is not None and len(preds.ghosts()) == 3
    return sc, st, preds


def _pixel(cam, point, w, h):
    from eyeviz.render.style3d import split_viewports

    _, (x0, _y0, x1, _y1) = split_viewports(w, h)
    vw = (x1 - x0) * w
    xy, _ = project(cam, np.asarray(point, float), vw / h)
    c, r = to_pixels(xy, int(round(vw)), h)
    return int(round(c + x0 * w)), int(round(r))


def test_vtk_ghosts_are_drawn_at_the_answers(scene_preds):
    from eyeviz.render.vtk.scene3d import default_camera, offscreen_view, shoot, split_viewports

    sc, st, preds = scene_preds
    w, h = 960, 540
    pl, actors = offscreen_view(w, h)
    try:
        actors.update(sc, st, 0)
        actors.draw_predictions(preds)
        g = actors.ghosts
        assert g is not None
        for a in preds.ghosts():
            assert g.centres[a.name] == (a.x, a.y, a.z)
            assert g.ghosts[a.name].ball.GetPosition() == pytest.approx((a.x, a.y, a.z))
            assert g.ghosts[a.name].ball.GetScale() == pytest.approx((preds.g,) * 3)
        assert preds.cloud is not None and g.cloud_n == len(preds.cloud.points) > 0
        # zoomed on the ball: analytic3d's centre dot (its answer is the farthest from the
        # others here) shows in its colour where the camera projects its answer
        _, sv = split_viewports(w, h)
        cam = default_camera(st, aspect=(sv[2] - sv[0]) * w / h)
        lim = preds.answers["analytic3d"]
        assert isinstance(lim, p3.Answer3D)
        centre = np.array([lim.x, lim.y, lim.z])
        pos = np.asarray(cam.position)
        close = type(cam)(tuple(centre + (pos - centre) * 8 * preds.g / np.linalg.norm(
            pos - centre)), tuple(centre), cam.view_up, cam.view_angle)  # fmt: skip
        img = shoot(pl, actors, close, False)
        c, r = _pixel(close, centre, w, h)
        got = img[r - 1 : r + 2, c - 1 : c + 2, :3].reshape(-1, 3).astype(int)
        want = np.array(hex_rgb(p3.estimator_color3d("analytic3d")))
        assert np.abs(got - want).sum(axis=1).min() < 60
        actors.draw_predictions(None)  # the layer off: nothing there
        pl.render()  # (pyvista renders by itself only for its first screenshot)
        img = shoot(pl, actors, close, False)
        got = img[r - 1 : r + 2, c - 1 : c + 2, :3].reshape(-1, 3).astype(int)
        assert np.abs(got - want).sum(axis=1).min() > 60
        assert not any(gh.ball.GetVisibility() for gh in g.ghosts.values())
    finally:
        pl.close()


def test_vector_ghosts_at_the_projected_answers(scene_preds, tmp_path):
    import matplotlib

    matplotlib.use("Agg")
    from eyeviz.render.mpl.figure3d import export3d, figure3d

    sc, st, preds = scene_preds
    fig = figure3d(sc, st, bitmaps=False, predictions=preds)
    ax = next(a for a in fig.axes if a.get_gid() == "perspective-scene")
    bbox = ax.get_position()
    aspect = bbox.width * fig.get_figwidth() / (bbox.height * fig.get_figheight())
    from eyeviz.render.mpl.perspective3d import framed_camera

    # the figure's camera: the preset, framed for the balls' names (as the app's)
    w_pt, h_pt = 72 * bbox.width * fig.get_figwidth(), 72 * bbox.height * fig.get_figheight()
    cam = framed_camera(st, sc, "default", w_pt, h_pt, predictions=preds)
    for a in preds.ghosts():
        patch = next(p for p in ax.patches if p.get_gid() == f"ghost-{a.name}")
        xy = patch.get_xy()
        centre, _ = project(cam, np.array([a.x, a.y, a.z]), aspect)
        assert xy.mean(axis=0) == pytest.approx(centre, abs=2e-3)
    assert any(c.get_gid() == "posterior-cloud" for c in ax.collections)
    assert any(a.get_gid() == "predictions" for a in fig.axes)  # the readout's rows
    # the layer off: no ghost
    off = sc.copy()
    off.layers.remove("predictions")
    fig2 = figure3d(off, bitmaps=False)
    ax2 = next(a for a in fig2.axes if a.get_gid() == "perspective-scene")
    assert not [p for p in ax2.patches if str(p.get_gid()).startswith("ghost-")]
    out = export3d(sc, tmp_path / "p.svg", bitmaps=False, predictions=preds)
    text = out.read_text()
    for name in ("analytic3d", "learned3d", "limit3d"):
        assert f'id="ghost-{name}' in text
