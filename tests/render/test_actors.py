"""SceneActors on real VTK renderers (off-screen): in-place updates, rebuilds, level of detail."""

import math

import numpy as np
import pytest
import pyvista as pv

from eyeviz.model.scene import Eyes, Feature, Scene
from eyeviz.model.state import compute_state
from eyeviz.render.vtk.actors import SceneActors, eye_mesh
from eyeviz.render.vtk.style import UNLIT, hex_rgb


@pytest.fixture
def rig():
    pl = pv.Plotter(off_screen=True, window_size=(400, 300))
    inset = pv.Renderer(pl)
    pl.ren_win.AddRenderer(inset)
    yield pl, SceneActors(pl.renderer, inset)
    pl.close()


def scene(m=720):
    fs = [Feature("a", 0.0, 1500.0, 50.0, "#D55E00"), Feature("b", 30.0, 1500.0, 50.0, "#0072B2")]
    return Scene(Eyes(40.0, 20.0, m), fs, ["eyes", "bfv", "features", "labels"])


def expected_rgb(sc, eye):
    pair = sc.eyes.pair()
    fs = sc.features
    bits = pair.bitmaps([f.x for f in fs], [f.y for f in fs], [f.g for f in fs])[eye]
    owner = np.full(pair.m, -1)
    for i in range(len(fs)):
        owner[bits[i]] = i
    palette = np.vstack([UNLIT] + [hex_rgb(f.color) for f in fs])
    return palette[owner + 1], owner


def test_eye_mesh_is_figure_2():
    mesh = eye_mesh(40.0, 20.0, 8)
    assert mesh.n_cells == 8 and mesh.n_points == 10
    tri = mesh.get_cell(2).points  # ommatidium 2: between 90 and 135 degrees
    np.testing.assert_allclose(tri[0], [40, 0, 0])
    np.testing.assert_allclose(tri[1][:2], [40, 20], atol=1e-12)
    np.testing.assert_allclose(tri[2][:2], [40 - 20 / math.sqrt(2), 20 / math.sqrt(2)])


def test_colours_updated_in_place_and_rebuilt_on_m(rig):
    pl, act = rig
    sc = scene()
    act.update(sc, compute_state(sc), 0)
    meshes = list(act.eye_meshes)
    arrays = [m.cell_data["rgb"] for m in meshes]
    for e in (0, 1):
        np.testing.assert_array_equal(meshes[e].cell_data["rgb"], expected_rgb(sc, e)[0])
    fill = act.fill_mesh
    sc.features[0].x, sc.features[0].y = -900.0, 2000.0
    act.update(sc, compute_state(sc), 0)
    assert act.eye_meshes[0] is meshes[0] and act.fill_mesh is fill  # not rebuilt
    assert np.shares_memory(act.eye_meshes[0].cell_data["rgb"], arrays[0])
    for e in (0, 1):
        np.testing.assert_array_equal(meshes[e].cell_data["rgb"], expected_rgb(sc, e)[0])
    # the selected disc is the live actor, placed by its transform; the merged mesh holds
    # the other disc only and was not rewritten by the move
    x0, x1, y0, y1, _, _ = act.live_fill.GetBounds()
    np.testing.assert_allclose([x0, x1, y0, y1], [-950, -850, 1950, 2050], atol=1e-6)
    assert fill.n_cells == act._fan and act.line_mesh.n_cells == 1
    ring = fill.points.reshape(2, -1, 3)[1]
    np.testing.assert_allclose(np.hypot(ring[:, 0] - 30.0, ring[:, 1] - 1500.0), 50.0)
    sc.features[1].x = 60.0  # not selected: the merged mesh follows
    act.update(sc, compute_state(sc), 0)
    ring = fill.points.reshape(2, -1, 3)[1]
    np.testing.assert_allclose(np.hypot(ring[:, 0] - 60.0, ring[:, 1] - 1500.0), 50.0)
    act.update(sc, compute_state(sc), None)  # nothing selected: both discs merged
    assert fill.n_cells == 2 * act._fan and not act.live_fill.GetVisibility()
    ring = fill.points.reshape(2, -1, 3)[0]
    np.testing.assert_allclose(np.hypot(ring[:, 0] + 900.0, ring[:, 1] - 2000.0), 50.0)
    sc.eyes.m = 36
    act.update(sc, compute_state(sc), 0)
    assert act.eye_meshes[0] is not meshes[0] and act.eye_meshes[0].n_cells == 36
    img = pl.screenshot(return_img=True)
    assert img.std() > 0


def test_level_of_detail_pools_and_keeps_every_lit_ommatidium(rig):
    pl, act = rig
    sc = scene(36000)
    act.update(sc, compute_state(sc), 0)
    act.set_zoom(main_px_per_unit=0.1, inset_px_per_unit=3.0, l=20.0, m=36000)
    k = act._lod_k["main"]
    assert k > 1 and act._lod_k["inset"] > 1 and not act.edges_main
    main_input = act._eye_actors[0].GetMapper().GetInput()
    assert main_input.GetNumberOfCells() == math.ceil(36000 / k)
    rgb, owner = expected_rgb(sc, 0)
    lod = pv.wrap(main_input).cell_data["rgb"]
    lit_bins = np.unique(np.flatnonzero(owner >= 0) // k)
    assert set(np.flatnonzero((lod != UNLIT).any(axis=1))) == set(lit_bins)
    # moving a feature updates the pooled mesh in place too
    sc.features[1].x = 2000.0
    act.update(sc, compute_state(sc), 0)
    rgb, owner = expected_rgb(sc, 0)
    lit_bins = np.unique(np.flatnonzero(owner >= 0) // k)
    assert set(np.flatnonzero((lod != UNLIT).any(axis=1))) == set(lit_bins)
    # zoomed in far enough: the full mesh again, with edges
    act.set_zoom(main_px_per_unit=1e4, inset_px_per_unit=3.0, l=20.0, m=36000)
    assert act._eye_actors[0].GetMapper().GetInput() is act.eye_meshes[0] and act.edges_main


def test_only_named_layers_are_built(rig):
    pl, act = rig
    sc = scene()
    sc.layers = ["features"]
    act.update(sc, compute_state(sc), None)
    assert act.eye_meshes == [] and act.fill_mesh is not None
    sc.layers = ["eyes"]
    act.update(sc, compute_state(sc), None)
    assert act.fill_mesh is None and len(act.eye_meshes) == 2


def test_tangents_touch_the_feature_and_sectors_bound_the_lit_interval(rig):
    pl, act = rig
    sc = Scene(
        Eyes(40.0, 20.0, 24),
        [Feature("f", 119.3, 60.9, 20.0)],
        ["eyes", "features", "tangents", "sectors"],
    )
    st = compute_state(sc)
    act.update(sc, st, 0)
    pts = np.asarray(act.tangent_mesh.points)
    for e, cx in enumerate((-40.0, 40.0)):
        centre, t1, t2 = pts[3 * e], pts[3 * e + 1], pts[3 * e + 2]
        assert centre[0] == cx
        for t in (t1, t2):  # on the circle, and the ray is perpendicular to the radius
            assert math.hypot(t[0] - 119.3, t[1] - 60.9) == pytest.approx(20.0)
            assert np.dot(t[:2] - centre[:2], t[:2] - [119.3, 60.9]) == pytest.approx(0, abs=1e-9)
    sec = np.asarray(act.sector_mesh.points)
    gamma = 2 * math.pi / 24
    slots = len(sec) // 2
    for e, (L, R) in enumerate(((st.LA[0], st.RA[0]), (st.LB[0], st.RB[0]))):
        c = sec[e * slots]
        ends = [p for p in sec[e * slots + 1 : (e + 1) * slots] if np.hypot(*(p - c)[:2]) > 0]
        angles = sorted(math.atan2(p[1] - c[1], p[0] - c[0]) % (2 * math.pi) for p in ends)
        # every boundary ray k*gamma of the lit run, L .. R+1 (Eq. 8, 11)
        assert angles == pytest.approx([(k * gamma) % (2 * math.pi) for k in range(L, R + 2)])
    sc.layers.remove("tangents")
    act.update(sc, compute_state(sc), 0)
    assert not act.tangents.actors[0].GetVisibility()


def test_inset_is_a_small_bottom_left_corner():
    from eyeviz.render.vtk.actors import inset_viewport

    for w, h, most in ((843, 552, 0.12), (1600, 1000, 0.06), (400, 300, 0.3)):
        x0, y0, x1, y1 = inset_viewport(w, h)
        assert (x0, y0) == (0.0, 0.0)
        assert (x1 - x0) * (y1 - y0) <= most  # the old inset took 20 % of the view
        assert 200 <= (x1 - x0) * w <= 340


def test_feature_fill_is_triangle_fans_in_the_feature_colours(rig):
    pl, act = rig
    sc = scene()
    act.update(sc, compute_state(sc), 0)
    assert act.fill_mesh.is_all_triangles
    for i, f in enumerate(sc.features):
        tint = np.round(0.4 * np.array(hex_rgb(f.color)) + 0.6 * 255)
        np.testing.assert_array_equal(act.fill_rgb(i), tint)


def test_bfv_wedge_is_the_frames_clipped_polygon_at_any_distance(rig):
    from eyeviz.model.frame import clip_wedge

    pl, act = rig
    sc = Scene(Eyes(40.0, 20.0, 720), [], ["eyes", "bfv"])
    act.update(sc, compute_state(sc), None)
    for cx, cy, half in ((0.0, 2000.0, 3000.0), (1e7, 1e7, 2e4), (-3e8, 5e8, 1e6)):
        for ren in (pl.renderer, act.inset):
            cam = ren.GetActiveCamera()
            cam.ParallelProjectionOn()
            cam.SetFocalPoint(cx, cy, 0.0)
            cam.SetPosition(cx, cy, 1000.0)
            cam.SetParallelScale(half)
        act.fit_bfv()
        rect = act.visible_rect()
        poly = clip_wedge(sc.eyes.pair().psi, rect)
        pts = np.asarray(act.bfv.mesh.points)[:, :2]
        np.testing.assert_allclose(pts[: len(poly)], poly)
        # the visible centre is inside the drawn wedge's bounds (the old one stopped at 5e6)
        assert pts[:, 1].max() >= cy and pts[:, 0].min() <= cx <= pts[:, 0].max()


def test_eye_colours_written_cell_by_cell_equal_a_full_rewrite(rig):
    """A drag rewrites only the cells whose owner changed (issue 12, drag latency): after
    every move, colour change and zoom, each mesh equals the colours written afresh."""
    pl, act = rig
    sc = scene(3600)
    sc.features.append(Feature("c", -40.0, 1400.0, 120.0, "#009E73"))
    act.update(sc, compute_state(sc), 2)
    act.set_zoom(main_px_per_unit=0.05, inset_px_per_unit=3.0, l=20.0, m=3600)
    k = act._lod_k["main"]
    assert k > 1
    rng = np.random.default_rng(3)
    for step in range(40):
        f = sc.features[step % 3]
        f.x += float(rng.normal(0, 40))
        f.y += float(rng.normal(0, 40))
        if step == 20:
            sc.features[0].color = "#CC79A7"  # a new palette: every cell is rewritten
        act.update(sc, compute_state(sc), step % 3)
        for e in (0, 1):
            rgb, owner = expected_rgb(sc, e)
            np.testing.assert_array_equal(act.eye_meshes[e].cell_data["rgb"], rgb)
            lod = pv.wrap(act._eye_actors[e].GetMapper().GetInput()).cell_data["rgb"]
            pooled = np.maximum.reduceat(owner, np.arange(0, 3600, k))
            palette = np.vstack([UNLIT] + [hex_rgb(f.color) for f in sc.features])
            np.testing.assert_array_equal(lod, palette[pooled + 1])
