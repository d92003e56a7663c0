"""The backdrop (eyeviz/render/vtk/backdrop.py) in a plain VTK window: its props drawn
before the main renderer's and kept while unchanged (a hit copies them back), the same
pixels as the props in the main renderer, a new capture when a prop or the camera changes,
and a window that may go first."""

import gc

import numpy as np
import pytest
import pyvista as pv

from eyeviz.render.vtk.backdrop import Backdrop
from eyeviz.render.vtk.primitives import actor


@pytest.fixture
def pl():
    p = pv.Plotter(off_screen=True, window_size=(240, 160))
    p.ren_win.SetMultiSamples(0)
    p.set_background("white")
    p.camera_position = [(0.0, 0.0, 10.0), (0.0, 0.0, 0.0), (0.0, 1.0, 0.0)]
    p.enable_parallel_projection()
    p.renderer.SetUseOIT(False)  # as the app's (eyeviz.app.view.fast_renderer)
    yield p
    p.close()


def _disc(x: float, z: float, color) -> "object":
    mesh = pv.Disc(center=(x, 0.0, z), inner=0.0, outer=1.0, c_res=40)
    return actor(mesh, color)


def _shot(p) -> np.ndarray:
    p.render()
    return np.asarray(p.screenshot(return_img=True)).copy()


def test_kept_props_draw_as_in_the_main_renderer(pl):
    under = _disc(-0.5, 0.0, (1.0, 0.0, 0.0))  # kept
    over = _disc(0.5, 0.5, (0.0, 0.0, 1.0))  # the main renderer's, above the kept one
    low = _disc(0.0, -0.5, (0.0, 0.6, 0.0))  # the main renderer's, under the kept one
    for a in (under, over, low):
        pl.renderer.AddActor(a)
    full = _shot(pl)
    pl.renderer.RemoveActor(under)
    bd = Backdrop(pl.renderer)
    bd.AddActor(under)
    assert bd.active and pl.renderer.GetPreserveColorBuffer()
    first = _shot(pl)
    c, h = bd.captures, bd.hits
    again = _shot(pl)
    assert bd.hits > h and bd.captures == c  # nothing changed: the kept buffers copied
    assert np.array_equal(first, full) and np.array_equal(again, full)
    under.GetProperty().SetColor(1.0, 0.5, 0.0)  # a prop changed: drawn and kept again
    changed = _shot(pl)
    assert bd.captures == c + 1 and not np.array_equal(changed, full)
    pl.camera.zoom(1.5)  # the camera moved: the same
    _shot(pl)
    assert bd.captures == c + 2
    bd.RemoveActor(under)  # nothing held: the main renderer as it was
    assert not bd.active and not pl.renderer.GetPreserveColorBuffer()
    assert not pl.ren_win.GetRenderers().IsItemPresent(bd.ren)


def test_the_window_may_go_before_the_backdrop():
    p = pv.Plotter(off_screen=True, window_size=(120, 80))
    p.renderer.SetUseOIT(False)
    bd = Backdrop(p.renderer)
    bd.AddActor(_disc(0.0, 0.0, (1.0, 0.0, 0.0)))
    p.render()
    p.render()
    assert bd.ren.GetRenderWindow() is not None
    p.close()
    del p
    gc.collect()
    assert bd.ren.GetRenderWindow() is None  # the window let go of it (no dangling pointer)
    del bd
    gc.collect()


def test_a_main_renderer_with_passes_draws_the_props_itself(pl):
    pl.renderer.SetUseOIT(True)  # order-independent translucency: its own passes
    a = _disc(0.0, 0.0, (1.0, 0.0, 0.0))
    bd = Backdrop(pl.renderer)
    bd.AddActor(a)
    assert not bd.active and pl.renderer.GetActors().IsItemPresent(a)
    assert (_shot(pl) == [255, 0, 0]).all(axis=2).any()
    bd.RemoveActor(a)
    assert not pl.renderer.GetActors().IsItemPresent(a)
