"""The 3D view's VTK painters, off-screen (no display): facets as cells, lit colours
written in place, the LOD of a large nside, layers on and off, the PNG."""

from __future__ import annotations

from pathlib import Path

import matplotlib.image as mpimg
import numpy as np
import pytest

from eyeviz import EyevizError
from eyeviz.core import healpix
from eyeviz.model import shapes3d
from eyeviz.model.camera3d import project, to_pixels
from eyeviz.model.scene import Eyes, Feature, Scene, load
from eyeviz.model.state3d import compute_state3d
from eyeviz.render.vtk.scene3d import (
    Scene3DActors,
    camera_of,
    default_camera,
    png_size,
    render_png3d,
    split_viewports,
)
from eyeviz.render.vtk.style import UNLIT, hex_rgb

pv = pytest.importorskip("pyvista")
SCENES = Path(__file__).resolve().parents[2] / "assets" / "scenes"
LAYERS3D = ["eyes", "features", "bfv", "tangents", "plane", "labels"]


def _scene(nside: int, balls) -> Scene:
    feats = [
        Feature(name, x, y, g, color, z) for name, x, y, z, g, color in balls
    ]  # fmt: skip
    return Scene(Eyes(40.0, 20.0, nside=nside), feats, list(LAYERS3D))


BALLS = [
    ("a", 0.0, 300.0, 0.0, 60.0, "#D55E00"),
    ("b", 150.0, 250.0, 150.0, 50.0, "#0072B2"),
]


@pytest.fixture
def renderers():
    from vtkmodules.vtkRenderingCore import vtkRenderer

    return vtkRenderer(), vtkRenderer()


def _cell_rgb(mesh) -> np.ndarray:
    from vtkmodules.util.numpy_support import vtk_to_numpy

    return vtk_to_numpy(mesh.GetCellData().GetAbstractArray("rgb"))


def test_one_cell_per_facet_coloured_by_the_lit_sets(renderers):
    sc = _scene(8, BALLS)
    st = compute_state3d(sc)
    act = Scene3DActors(*renderers)
    act.update(sc, st, 0)
    assert act.eyes.full and len(act.eyes.meshes) == 2
    for e, mesh in enumerate(map(pv.wrap, act.eyes.meshes)):
        assert mesh.n_cells == healpix.npix(8)
        rgb = _cell_rgb(mesh)
        lit_a, lit_b = st.lit(0, "AB"[e]), st.lit(1, "AB"[e])
        only_a = np.setdiff1d(lit_a, lit_b)
        assert only_a.size and np.all(rgb[only_a] == hex_rgb("#D55E00"))
        assert np.all(rgb[lit_b] == hex_rgb("#0072B2"))  # the last ball wins a shared facet
        unlit = np.setdiff1d(np.arange(mesh.n_cells), np.union1d(lit_a, lit_b))
        assert np.all(rgb[unlit] == UNLIT)
        # cell i is facet i: its centre is facet i's centre on the eye
        pts = np.asarray(mesh.points).reshape(mesh.n_cells, -1, 3)
        cx = (-40.0, 40.0)[e]
        centres = pts.mean(axis=1) - (cx, 0.0, 0.0)
        centres /= np.linalg.norm(centres, axis=1, keepdims=True)
        assert np.allclose(centres, healpix.centers(8), atol=0.05)


def test_a_move_rewrites_the_colours_in_place(renderers):
    sc = _scene(8, BALLS)
    act = Scene3DActors(*renderers)
    act.update(sc, compute_state3d(sc), 0)
    mesh = act.eyes.meshes[0]
    arr = mesh.GetCellData().GetAbstractArray("rgb")
    before = _cell_rgb(mesh).copy()
    mtime = arr.GetMTime()
    sc.features[0].x = -120.0  # a live move
    st = compute_state3d(sc)
    act.update(sc, st, 0)
    assert act.eyes.meshes[0] is mesh and mesh.GetCellData().GetAbstractArray("rgb") is arr
    assert arr.GetMTime() > mtime
    after = _cell_rgb(mesh)
    assert not np.array_equal(before, after)
    assert np.all(after[np.setdiff1d(st.lit(0, "A"), st.lit(1, "A"))] == hex_rgb("#D55E00"))
    # the ball's actor moved by its transform, its mesh untouched
    assert act.balls.ball_actors[0].GetPosition() == pytest.approx((-120.0, 300.0, 0.0))
    # far out: the field's cones and plane reach farther, the eyes and balls are kept
    bfv, ball = act.field.bfv_actor, act.balls.ball_actors[0]
    sc.features[0].y = 3000.0
    act.update(sc, compute_state3d(sc), 0)
    assert act.eyes.meshes[0] is mesh and act.balls.ball_actors[0] is ball
    assert act.field.bfv_actor is not bfv
    assert act.field.plane_actors[1].GetBounds()[3] > 3060.0  # the plane reaches past the ball


def test_large_nside_draws_a_coarse_sphere_and_the_lit_patches(renderers):
    sc = _scene(180, [("t", 0.0, 1500.0, 0.0, 50.0, "#D55E00")])
    st = compute_state3d(sc)
    act = Scene3DActors(*renderers)
    act.update(sc, st, None)
    assert not act.eyes.full and not act.eyes.meshes
    for e in range(2):
        raw, a, pix = act.eyes.patches[e][0]
        mesh = pv.wrap(raw)
        assert np.array_equal(pix, st.lit(0, "AB"[e]))
        assert mesh.n_cells == pix.size > 100
        rgb = np.asarray(mesh.cell_data["rgb"])  # every cell in the ball's colour
        assert (rgb == np.array(hex_rgb("#D55E00"), np.uint8)).all()
    # an unchanged lit set is not rebuilt
    mesh0 = act.eyes.patches[0][0][0]
    mt = mesh0.GetMTime()
    act.update(sc, st, None)
    assert act.eyes.patches[0][0][0].GetMTime() == mt


def test_layers_hide_their_actors(renderers):
    sc = _scene(8, BALLS)
    act = Scene3DActors(*renderers)
    act.update(sc, compute_state3d(sc), 0)
    assert act.balls.cone_actor.GetVisibility() and act.field.bfv_actor.GetVisibility()
    assert all(a.GetVisibility() for a in act.field.plane_actors)
    sc.layers = ["eyes"]
    act.update(sc, compute_state3d(sc), 0)
    assert not act.balls.cone_actor.GetVisibility() and not act.field.bfv_actor.GetVisibility()
    assert not any(a.GetVisibility() for a in act.field.plane_actors + act.balls.ball_actors)
    assert not any(lab.GetVisibility() for lab in act.balls.ball_labels)


def test_cones_touch_their_balls(renderers):
    sc = _scene(8, BALLS)
    st = compute_state3d(sc)
    act = Scene3DActors(*renderers)
    act.update(sc, st, 0)
    pts = np.asarray(pv.wrap(act.balls.cones).points).reshape(4, -1, 3)  # A: a, b; then B: a, b
    for k, (cx, i) in enumerate([(-40.0, 0), (-40.0, 1), (40.0, 0), (40.0, 1)]):
        apex, rim = pts[k, 0], pts[k, 1:]
        assert apex == pytest.approx((cx, 0.0, 0.0))
        c = np.array([st.x[i], st.y[i], st.z[i]])
        # the rim lies on the ball and its lines from the apex are tangent (right angle)
        assert np.allclose(np.linalg.norm(rim - c, axis=1), st.g[i])
        assert np.allclose(((rim - apex) * (rim - c)).sum(axis=1), 0.0, atol=1e-6)


def test_png_shows_the_ball_where_the_camera_projects_it(tmp_path):
    sc = _scene(8, [("a", 0.0, 300.0, 0.0, 60.0, "#D55E00")])
    sc.layers = ["features"]  # the ball alone, in its colour
    st = compute_state3d(sc)
    w, h = 800, 450
    left, right = split_viewports(w, h)
    vw = (right[2] - right[0]) * w
    cam = default_camera(st, "top", vw / h)
    out = render_png3d(sc, tmp_path / "v.png", cam, w, h)
    img = (mpimg.imread(out)[..., :3] * 255).round().astype(int)
    assert img.shape == (h, w, 3)
    xy, _ = project(cam, np.array([0.0, 300.0, 0.0]), vw / h)
    col, row = to_pixels(xy, int(round(vw)), h)
    col += right[0] * w
    patch = img[int(row) - 3 : int(row) + 4, int(col) - 3 : int(col) + 4].reshape(-1, 3)
    assert (np.abs(patch - hex_rgb("#D55E00")).sum(axis=1) < 90).all()  # the ball, lit
    assert np.all(img[5, int(right[0] * w) + 5] == 255)  # white background elsewhere


def test_png_is_refused_in_one_line(tmp_path):
    sc = _scene(8, BALLS)
    with pytest.raises(EyevizError, match=r"\.png"):
        render_png3d(sc, tmp_path / "v.svg")
    with pytest.raises(EyevizError, match="width"):
        render_png3d(sc, tmp_path / "v.png", None, 10, 100)
    with pytest.raises(EyevizError, match="does not exist"):
        render_png3d(sc, tmp_path / "no" / "v.png")
    with pytest.raises(EyevizError, match="8192"):
        png_size(1e5)
    assert png_size(1600) == (1600, 900)


def test_shipped_scenes_render(tmp_path):
    for name in ("sphere_teaching", "sphere_equator"):
        out = render_png3d(load(SCENES / f"{name}.toml"), tmp_path / f"{name}.png", None, 480, 270)
        img = mpimg.imread(out)
        assert len(np.unique((img[..., :3] * 255).astype(int).reshape(-1, 3), axis=0)) > 100


def test_a_scene_without_balls(renderers, tmp_path):
    for nside in (8, 180):
        sc = _scene(nside, [])
        act = Scene3DActors(*renderers)
        act.update(sc, compute_state3d(sc), None)
        assert (
            not act.balls.cone_actor.GetVisibility() and not act.balls.select_actor.GetVisibility()
        )
    assert render_png3d(_scene(8, []), tmp_path / "e.png", None, 200, 120).exists()


def test_camera_round_trip(renderers):
    ren, _ = renderers
    sc = _scene(8, BALLS)
    cam = default_camera(compute_state3d(sc), "side")
    from eyeviz.render.vtk.scene3d import apply_camera

    apply_camera(ren, cam)
    back = camera_of(ren)
    assert back.position == pytest.approx(cam.position)
    assert back.focal_point == pytest.approx(cam.focal_point)
    assert back.view_up == pytest.approx(cam.view_up)


def test_shapes_bounding_ball_holds_everything():
    sc = load(SCENES / "sphere_equator.toml")
    st = compute_state3d(sc)
    c, r = shapes3d.bounding_ball(st)
    for f in sc.features:
        assert np.linalg.norm(np.subtract((f.x, f.y, f.z), c)) + f.g <= r + 1e-9
    for cx in (-40.0, 40.0):
        assert np.linalg.norm(np.subtract((cx, 0, 0), c)) + 20.0 <= r + 1e-9


def test_a_huge_lit_set_is_drawn_on_coarse_facets(monkeypatch):
    from eyeviz.core import healpix as hp

    monkeypatch.setattr(shapes3d, "MAX_PATCH_FACETS", 500)
    sc = _scene(180, [("t", 0.0, 120.0, 0.0, 60.0, "#D55E00")])
    st = compute_state3d(sc)
    pix = st.lit(0, "A")
    assert pix.size > 500
    dn, dpix = shapes3d.patch_facets(180, pix)
    assert dn == shapes3d.PATCH_COARSE_NSIDE and 0 < dpix.size < pix.size
    # every coarse facet drawn holds lit facets: the coarse facet of a lit centre
    v = hp.centers(180, pix)
    owners = set(hp.vec2pix_ring(dn, v[:, 0], v[:, 1], v[:, 2]).tolist())
    assert set(dpix.tolist()) <= owners
    assert shapes3d.patch_facets(180, pix[:400])[0] == 180  # small sets: themselves


def test_tangent_cones_vectorised_equal_one_by_one():
    rng = np.random.default_rng(3)
    apex = rng.normal(size=(7, 3)) * 40
    centre = rng.normal(size=(7, 3)) * 300
    g = rng.uniform(10, 120, size=7)
    centre[3] = apex[3] + [5.0, 0.0, 0.0]  # the apex inside the ball: degenerate
    centre[4] = apex[4] + [0.0, 0.0, 500.0]  # along z (the other reference axis)
    many = shapes3d.tangent_cones(apex, centre, g, 24).reshape(7, 25, 3)
    for k in range(7):
        np.testing.assert_allclose(
            many[k], shapes3d.tangent_cone(apex[k], centre[k], g[k], 24), atol=1e-9
        )
    assert np.all(many[3] == apex[3])


def test_fit_lines_breaks_a_long_title_at_spaces_and_elides_past_two_lines():
    from vtkmodules.vtkRenderingCore import vtkTextProperty, vtkTextRenderer

    from eyeviz.render.vtk.primitives import fit_lines

    tp = vtkTextProperty()
    tp.SetFontSize(22)
    tr = vtkTextRenderer()

    def width(s: str) -> int:
        box = [0, 0, 0, 0]
        assert tr.GetBoundingBox(tp, s, box, 72)
        return box[1] - box[0]

    title = "Spherical eyes, one facet at a time (nside 8)"
    assert fit_lines(tp, title, width(title) + 1) == title  # fits: unchanged
    two = fit_lines(tp, title, 0.7 * width(title))
    assert two.replace("\n", " ") == title and two.count("\n") == 1
    assert all(width(line) <= 0.7 * width(title) for line in two.split("\n"))
    many = fit_lines(tp, title + " and a great deal more to say", 0.4 * width(title))
    assert many.count("\n") == 1 and many.endswith("…")
    assert all(width(line) <= 0.4 * width(title) for line in many.split("\n"))


def test_the_title_fits_the_scene_view(tmp_path):
    """A title wider than the scene's viewport is broken into lines before the render
    (it was cut at the view's edge), and put back whole when the view is wide enough."""
    from eyeviz.render.vtk.scene3d import offscreen_view, shoot

    sc = _scene(8, BALLS)
    sc.title = "Spherical eyes, one facet at a time: a title of some length (nside 8)"
    st = compute_state3d(sc)
    for w, broken in ((1000, True), (3000, False)):
        pl, actors = offscreen_view(w, 360)
        try:
            actors.update(sc, st, None)
            shoot(pl, actors, default_camera(st, aspect=1.5), False)
            text = actors.title.GetInput()
            assert ("\n" in text) is broken and text.replace("\n", " ") == sc.title
            box = [0.0] * 4
            actors.title.GetBoundingBox(actors.scene_ren, box)
            assert box[1] - box[0] <= actors.scene_ren.GetSize()[0]
        finally:
            pl.close()
