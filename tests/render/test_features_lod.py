"""The discs' level of detail (issue 25): few vertices for discs a few pixels wide, the
same pixels covered as the circle, and levels that follow the zoom."""

import numpy as np
import pytest
import pyvista as pv

from eyeviz.model.scene import Eyes, Feature, Scene, View
from eyeviz.model.state import compute_state
from eyeviz.render.vtk.actors import SceneActors
from eyeviz.render.vtk.layers.features import LOD_ERROR_PX, LOD_LEVELS, disc_vertices
from eyeviz.render.vtk.primitives import CIRCLE_N

W, H = 400, 300
RADII_PX = (3.0, 8.0, 20.0, 45.0, 110.0)


def test_disc_vertices_keep_the_sagitta_within_the_bound():
    r = np.geomspace(0.1, 5000.0, 400)
    c = disc_vertices(r)
    assert set(c) <= set(LOD_LEVELS) and c[0] == LOD_LEVELS[0] and c[-1] == CIRCLE_N
    assert np.all(np.diff(c) >= 0)  # larger discs never get fewer vertices
    fits = r * (1 - np.cos(np.pi / c)) <= LOD_ERROR_PX
    assert np.all(fits | (c == CIRCLE_N))
    # and the level below would not have done
    lower = np.searchsorted(LOD_LEVELS, c) - 1
    ok = lower >= 0
    assert np.all(r[ok] * (1 - np.cos(np.pi / LOD_LEVELS[lower[ok]])) > LOD_ERROR_PX)


@pytest.fixture
def rig():
    pl = pv.Plotter(off_screen=True, window_size=(W, H))
    pl.renderer.SetBackground(1.0, 1.0, 1.0)
    inset = pv.Renderer(pl)
    inset.SetDraw(False)  # a hidden inset: its camera sets no level
    pl.ren_win.AddRenderer(inset)
    yield pl, SceneActors(pl.renderer, inset)
    pl.close()


def _look(pl, cx: float, cy: float, ppu: float) -> None:
    pl.camera_set = True  # pyvista's render leaves this camera alone
    cam = pl.renderer.GetActiveCamera()
    cam.ParallelProjectionOn()
    cam.SetFocalPoint(cx, cy, 0.0)
    cam.SetPosition(cx, cy, 1000.0)
    cam.SetViewUp(0.0, 1.0, 0.0)
    cam.SetParallelScale(H / ppu / 2.0)
    cam.SetClippingRange(1.0, 2000.0)


def test_lod_discs_cover_the_circles_pixels(rig):
    pl, act = rig
    ppu = 0.5  # pixels per model unit
    xs = np.array([-300.0, -240.0, -150.0, 0.0, 230.0])
    g = np.array(RADII_PX) / ppu
    fs = [Feature(f"f{i}", float(xs[i]), 0.0, float(g[i]), "#0072B2") for i in range(len(xs))]
    sc = Scene(Eyes(40.0, 20.0, 72), fs, ["features"], view=View((0.0, 0.0), W / ppu))
    _look(pl, 0.0, 0.0, ppu)
    act.update(sc, compute_state(sc), None)
    verts = act.features.verts
    np.testing.assert_array_equal(verts, disc_vertices(np.array(RADII_PX)))
    assert verts[0] <= 12 and verts[-1] < CIRCLE_N  # coarse where that is invisible
    pl.render()
    img = np.asarray(pl.screenshot(return_img=True))[..., :3].astype(int)
    # pixel centres in model units (rows run downwards)
    col = (np.arange(W) + 0.5 - W / 2) / ppu
    row = (H / 2 - np.arange(H) - 0.5) / ppu
    X, Y = np.meshgrid(col, row)
    painted = (img != 255).any(axis=-1)
    inside_any = np.zeros((H, W), bool)
    near_any = np.zeros((H, W), bool)
    for x, r in zip(xs, RADII_PX, strict=True):
        d_px = np.hypot(X - x, Y) * ppu
        inside = d_px <= r - 1.0
        assert painted[inside].all(), f"a disc of {r} px leaves pixels inside it unpainted"
        inside_any |= inside
        # the 3 px outline and the 11 px centre dot reach a little beyond the circle
        near_any |= d_px <= max(r + 2.5, 6.5)
    assert not painted[~near_any].any(), "a disc paints pixels away from its circle"
    assert inside_any.sum() > 1000


def test_levels_follow_the_zoom(rig):
    pl, act = rig
    sc = Scene(Eyes(40.0, 20.0, 72), [Feature("a", 0.0, 0.0, 10.0, "#0072B2")], ["features"])
    _look(pl, 0.0, 0.0, 0.2)  # the disc 2 px wide
    act.update(sc, compute_state(sc), None)
    mesh = act.fill_mesh
    assert act.features.verts.tolist() == [LOD_LEVELS[0]]
    assert mesh.n_cells == LOD_LEVELS[0] - 2
    _look(pl, 0.0, 0.0, 50.0)  # zoomed in: the disc 500 px wide
    act.set_zoom(50.0, 50.0, 20.0, 72)
    assert act.features.verts.tolist() == [disc_vertices(np.array([500.0]))[0]]
    assert act.fill_mesh is mesh and mesh.n_cells == act.features.verts[0] - 2
    ring = np.asarray(mesh.points)
    np.testing.assert_allclose(np.hypot(ring[:, 0], ring[:, 1]), 10.0, rtol=1e-12)
    _look(pl, 5000.0, 0.0, 50.0)  # the disc off screen: the coarsest again
    act.set_zoom(50.0, 50.0, 20.0, 72)
    assert act.features.verts.tolist() == [LOD_LEVELS[0]]


def test_the_inset_draws_only_the_discs_it_shows(rig):
    pl, act = rig
    inset = act.inset
    inset.SetViewport(0.0, 0.0, 0.3, 0.3)
    inset.SetDraw(True)
    fs = [Feature("near", 0.0, 0.0, 10.0, "#0072B2"), Feature("far", 5000.0, 0.0, 10.0, "#D55E00")]
    sc = Scene(Eyes(40.0, 20.0, 72), fs, ["features"])
    _look(pl, 2500.0, 0.0, 0.05)  # the main view shows both
    cam = inset.GetActiveCamera()
    cam.ParallelProjectionOn()
    cam.SetFocalPoint(0.0, 0.0, 0.0)
    cam.SetPosition(0.0, 0.0, 1000.0)
    cam.SetParallelScale(50.0)  # the inset shows "near" only
    act.update(sc, compute_state(sc), None)
    near = act.features.verts[0]
    assert act.fill_mesh.n_cells == sum(act.features.verts - 2)  # both in the main view
    assert act.features.inset_fill.n_cells == near - 2
    assert act.features.inset_line.n_cells == 1
    # the inset's cells index the near disc's points (the first ones)
    assert np.asarray(act.features.inset_line.lines)[1 : near + 1].tolist() == list(range(near))
    inset.SetDraw(False)  # hidden: it draws no disc
    act.set_zoom(0.05, 0.05, 20.0, 72)
    assert act.features.inset_fill.n_cells == 0 and act.features.inset_line.n_cells == 0
