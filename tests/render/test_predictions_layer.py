"""The prediction ghosts during a drag (issue 12, drag latency): only the dragged feature's
rings are written; the others' points, the cells, the meshes and the mappers stay as they
were (a new mapper input makes VTK rebuild its shaders: ~1.4 ms a frame at m = 36,000), and
what is drawn is still exactly what a layer built from scratch draws. Counted, not timed:
rebuilds, rings written, object identity and VTK modification times."""

from __future__ import annotations

import math

import numpy as np
import pytest
import pyvista as pv

from eyeviz.model.app_model import AppModel
from eyeviz.model.scene import Eyes, Feature, Scene
from eyeviz.render.vtk.layers.predictions import GHOST_N, PredictionsLayer
from eyeviz.render.vtk.overlays import OverlayActors, overlay_frame

LAYERS = ["eyes", "features", "readout", "predictions"]


def _scene(n: int = 6, est=("analytic", "limit")) -> Scene:
    fs = [
        Feature(f"f{i}", 400.0 * math.cos(a), 2500.0 * math.sin(a), 60.0 + 10 * i)
        for i, a in enumerate(np.linspace(math.radians(70), math.radians(110), n))
    ]
    return Scene(Eyes(40.0, 20.0, 720), fs, list(LAYERS), estimators=list(est))


@pytest.fixture
def rig():
    pl = pv.Plotter(off_screen=True, window_size=(300, 200))
    yield pl, OverlayActors(pl.renderer)
    pl.close()


def _refresh(ov: OverlayActors, model: AppModel):
    sc = model.scene
    return ov.update(sc, model.state, model.selected, model.predictions, None, None)


def _blocks(mesh) -> np.ndarray:
    return np.asarray(mesh.points).reshape(-1, GHOST_N + 2, 3)


def _drawn(layer: PredictionsLayer):
    """Everything the layer hands VTK: points, cells and colours of both meshes."""
    m, c = layer.ghost_mesh, layer.ghost_points
    return (
        np.asarray(m.points).copy(),
        np.asarray(m.lines).copy(),
        np.asarray(m.cell_data["rgb"]).copy(),
        np.asarray(c.points).copy(),
        np.asarray(c.verts).copy(),
        np.asarray(c.point_data["rgb"]).copy(),
    )


def test_a_drag_writes_only_the_dragged_features_rings(rig):
    pl, ov = rig
    model = AppModel(_scene())
    model.select(2)
    _refresh(ov, model)
    pl.render()
    layer = ov.predictions
    assert layer.builds == 1
    k = sum(len(v) for v in layer.written.values())
    assert k == 2 * 6  # both estimators answer for every feature
    mesh, cp = layer.ghost_mesh, layer.ghost_points
    mappers = [a.GetMapper() for a in layer.actors]
    mapper_mtime = [mp.GetMTime() for mp in mappers]
    cells = mesh.GetLines()
    cells_mtime = cells.GetMTime()
    before = _blocks(mesh).copy()
    model.begin_live("drag")
    for step in range(1, 6):
        model.live(2, x=model.scene.features[2].x + 37.0 * step, y=2400.0 - 20.0 * step)
        frame = _refresh(ov, model)
        pl.render()
        # the dragged feature's two rings (one per estimator), nothing else
        assert {n: list(i) for n, i in layer.written.items()} == {"analytic": [2], "limit": [2]}
        assert layer.builds == 1
        assert layer.ghost_mesh is mesh and layer.ghost_points is cp
        assert mesh.GetLines() is cells and cells.GetMTime() == cells_mtime
        assert [mp.GetMTime() for mp in mappers] == mapper_mtime  # inputs never replaced
        assert [a.GetMapper().GetInput() for a in layer.actors] == [mesh, cp]
    after = _blocks(mesh)
    moved = np.zeros(len(after), bool)
    moved[[2, 6 + 2]] = True  # the blocks of feature 2: analytic first, then limit
    np.testing.assert_array_equal(after[~moved], before[~moved])  # bit for bit
    assert not np.allclose(after[moved], before[moved])
    # and the meshes hold what a layer built from scratch for this Frame holds
    fresh = OverlayActors(pl.renderer)
    fresh.draw(frame, model.selected)
    for a, b in zip(_drawn(layer), _drawn(fresh.predictions), strict=True):
        np.testing.assert_array_equal(a, b)
    x_hat = frame.predictions["limit"].x_hat
    np.testing.assert_allclose(after[6 + 2, GHOST_N + 1, 0], x_hat[2])


def test_leaving_the_domain_rebuilds_and_still_draws_the_frame(rig):
    pl, ov = rig
    model = AppModel(_scene(4, ("analytic",)))
    _refresh(ov, model)
    layer = ov.predictions
    model.live(1, x=3000.0, y=200.0)  # out of the BFV: no ring for it
    frame = _refresh(ov, model)
    assert layer.builds == 2
    assert list(layer.written["analytic"]) == [0, 2, 3]
    assert len(_blocks(layer.ghost_mesh)) == 3
    fresh = OverlayActors(pl.renderer)
    fresh.draw(frame, model.selected)
    for a, b in zip(_drawn(layer), _drawn(fresh.predictions), strict=True):
        np.testing.assert_array_equal(a, b)
    # the layer off, then on again: hidden, then rebuilt from the Frame
    model.set_layer("predictions", False)
    _refresh(ov, model)
    assert not any(a.GetVisibility() for a in layer.actors) and layer.ghosts == {}
    model.set_layer("predictions", True)
    _refresh(ov, model)
    assert layer.builds == 3 and all(a.GetVisibility() for a in layer.actors)


def test_the_same_inputs_build_no_new_frame(rig):
    _, ov = rig
    model = AppModel(_scene(3, ("analytic",)))
    first = _refresh(ov, model)
    points_mtime = ov.predictions.ghost_mesh.GetPoints().GetMTime()
    assert _refresh(ov, model) is first  # nothing changed: the Frame drawn is kept
    model.select(1)  # a selection changes the overlays' inputs: a new Frame
    second = _refresh(ov, model)
    assert second is not first
    assert {n: list(i) for n, i in ov.predictions.written.items()} == {"analytic": []}
    assert ov.predictions.ghost_mesh.GetPoints().GetMTime() == points_mtime
    # a Frame drawn from elsewhere is replaced by the next update's own
    sc = model.scene
    injected = overlay_frame(sc, model.state, 1, model.predictions, None, None)
    ov.draw(injected, 1)
    assert _refresh(ov, model) is not injected
