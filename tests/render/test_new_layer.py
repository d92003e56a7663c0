"""A new layer is one entry of the layer table (issue 20 item 1): a toy layer defined here
(a frame part, a matplotlib painter and a VTK painter) registered once is built by
build_frame, drawn by the exported figure and by the app's VTK view, accepted by the scene
file, and costs nothing in a scene that does not show it."""

from __future__ import annotations

import numpy as np
import pytest
import pyvista as pv

from eyeviz.model.frame import build_frame
from eyeviz.model.layers import LayerSpec, register_layer, unregister_layer
from eyeviz.model.scene import Eyes, Feature, Scene, dumps, loads
from eyeviz.model.state import compute_state
from eyeviz.render.mpl import vector
from eyeviz.render.vtk.actors import SceneActors
from eyeviz.render.vtk.overlays import OverlayActors
from eyeviz.render.vtk.primitives import actor

RED = (1.0, 0.0, 0.0)
built: list[int] = []  # features the toy frame builder ran for, call by call


def toy_frame(fr, inp) -> None:
    """The toy part: a mark one radius above each feature's centre."""
    built.append(fr.n)
    fr.parts["toy"] = np.column_stack([inp.state.x, inp.state.y + inp.state.g])


def toy_mpl(cv) -> None:
    pts = cv.frame.parts["toy"]
    cv.ax.plot(pts[:, 0], pts[:, 1], "s", color="red", ms=6, zorder=20, gid="toy-marks")


class ToyVtk:
    """A big red square per mark, in the main view."""

    def __init__(self, main, inset):
        self.mesh = pv.PolyData(np.zeros((1, 3)))
        self.actor = actor(self.mesh, RED)
        prop = self.actor.GetProperty()
        prop.SetRepresentationToPoints()
        prop.SetPointSize(25)
        self.actor.SetVisibility(False)
        main.AddActor(self.actor)

    def draw(self, frame, selected) -> None:
        pts = frame.parts.get("toy")
        shown = "toy" in frame.layers and pts is not None and len(pts) > 0
        self.actor.SetVisibility(shown)
        if shown:
            self.mesh.points = np.column_stack([pts, np.full(len(pts), 5.0)])


@pytest.fixture
def toy():
    built.clear()
    spec = register_layer(
        LayerSpec(
            "toy",
            "a red mark above each feature (a test's layer)",
            needs=frozenset({"readout"}),
            frame=toy_frame,
            mpl=toy_mpl,
            vtk=ToyVtk,
            mpl_order=75,
            vtk_order=35,
        )
    )
    yield spec
    unregister_layer("toy")


def _scene(show_toy: bool) -> Scene:
    fs = [
        Feature("a", 300.0, 2000.0, 120.0, "#0072B2"),
        Feature("b", -500.0, 2600.0, 90.0, "#009E73"),
    ]
    layers = ["eyes", "bfv", "features", "labels"] + (["toy"] if show_toy else [])
    return Scene(Eyes(40.0, 20.0, 720), fs, layers)


def _marks(fig):
    return [ln for ax in fig.axes for ln in ax.get_lines() if ln.get_gid() == "toy-marks"]


def test_the_frame_carries_the_new_part_only_when_shown(toy):
    fr = build_frame(_scene(True))
    np.testing.assert_array_equal(fr.parts["toy"], [[300.0, 2120.0], [-500.0, 2690.0]])
    assert built == [2]
    fr = build_frame(_scene(False))
    assert "toy" not in fr.parts and built == [2]  # nothing built for a hidden layer


def test_the_exported_figure_draws_the_new_layer(toy):
    (line,) = _marks(vector.figure(_scene(True)))
    np.testing.assert_array_equal(line.get_xydata(), [[300.0, 2120.0], [-500.0, 2690.0]])
    assert _marks(vector.figure(_scene(False))) == []


def _red_pixels(pl) -> int:
    pl.render()
    img = np.asarray(pl.screenshot(return_img=True))[..., :3].astype(int)
    return int(((img[..., 0] > 200) & (img[..., 1] < 60) & (img[..., 2] < 60)).sum())


def test_the_vtk_view_draws_the_new_layer(toy):
    pl = pv.Plotter(off_screen=True, window_size=(400, 300))
    try:
        inset = pv.Renderer(pl)
        inset.SetViewport(0.0, 0.0, 0.2, 0.2)
        pl.ren_win.AddRenderer(inset)
        act = SceneActors(pl.renderer, inset)
        painter = act.layer("toy")
        assert isinstance(painter, ToyVtk)
        assert pl.renderer.GetActors().IsItemPresent(painter.actor)
        cam = pl.renderer.GetActiveCamera()
        cam.ParallelProjectionOn()
        cam.SetFocalPoint(0.0, 2300.0, 0.0)
        cam.SetPosition(0.0, 2300.0, 1000.0)
        cam.SetParallelScale(900.0)
        sc = _scene(True)
        act.update(sc, compute_state(sc), 0)
        assert painter.actor.GetVisibility()
        np.testing.assert_array_equal(
            np.asarray(painter.mesh.points)[:, :2], act.frame.parts["toy"]
        )
        assert _red_pixels(pl) > 100  # both marks are on screen
        built.clear()
        sc = _scene(False)
        act.update(sc, compute_state(sc), 0)
        assert built == [] and "toy" not in act.frame.parts
        assert not painter.actor.GetVisibility()
        assert _red_pixels(pl) == 0
    finally:
        pl.close()


def test_an_overlay_stage_layer_is_drawn_by_the_overlays(toy):
    unregister_layer("toy")
    register_layer(
        LayerSpec("toy", "the same, drawn over", frame=toy_frame, vtk=ToyVtk, vtk_stage="overlay")
    )
    pl = pv.Plotter(off_screen=True, window_size=(300, 200))
    try:
        ov = OverlayActors(pl.renderer)
        sc = _scene(True)
        ov.update(sc, compute_state(sc), 0, {}, None, None)
        painter = ov.painters["toy"]
        assert painter.actor.GetVisibility()
        sc = _scene(False)
        ov.update(sc, compute_state(sc), 0, {}, None, None)
        assert not painter.actor.GetVisibility()
    finally:
        pl.close()


def test_the_scene_file_round_trips_the_new_layer(toy):
    sc = _scene(True)
    assert loads(dumps(sc)).layers == sc.layers
