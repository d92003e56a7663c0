"""The 3D view's looks live in one place (eyeviz/render/style3d.py) for its two painters:
the VTK view and the vector view drawn from the model."""

from __future__ import annotations

import numpy as np
import pytest

from eyeviz.render import style3d
from eyeviz.render.mpl import perspective3d


def test_the_vector_view_takes_the_shared_looks():
    assert perspective3d.split_viewports is style3d.split_viewports
    assert perspective3d.EDGES_MAX_NSIDE == style3d.EDGES_MAX_NSIDE
    assert perspective3d.EYE_CONE == style3d.EYE_CONE
    assert perspective3d.EDGE_RGBA[:3] == style3d.EDGE_RGB
    assert perspective3d.BFV_RGBA == (*style3d.BFV_RGB, style3d.BFV_OPACITY)
    assert perspective3d.PLANE_RGBA == (*style3d.PLANE_RGB, style3d.PLANE_OPACITY)
    assert perspective3d.CONE_ALPHA == style3d.CONE_OPACITY


def test_the_vtk_view_takes_the_shared_looks():
    pytest.importorskip("pyvista")
    from eyeviz.render.vtk import balls3d, eyes3d, field3d, scene3d, style

    # each painter takes its looks from style3d (the painters of eyeviz.render.vtk.scene3d)
    for mod, names in (
        (scene3d, ("EYES_FRACTION",)),
        (eyes3d, ("EDGE_RGB", "EDGES_MAX_NSIDE")),
        (field3d, ("BFV_RGB", "BFV_OPACITY", "PLANE_RGB")),
        (balls3d, ("CONE_OPACITY", "EYE_CONE")),
    ):
        for name in names:
            assert getattr(mod, name) is getattr(style3d, name), name
    # the colours the planar VTK view shares are the same values
    assert np.allclose(np.asarray(style.UNLIT) / 255.0, style3d.UNLIT_RGB)
    assert np.allclose(style.INSET_BACKGROUND, style3d.INSET_RGB)
    assert np.allclose(style.INK, style3d.INK_RGB)


@pytest.mark.parametrize(
    ("w", "h", "f"), [(1600, 900, style3d.EYES_FRACTION), (400, 900, 0.5), (800, 1000, 0.4)]
)
def test_split_viewports(w, h, f):
    eyes, scene = style3d.split_viewports(w, h)
    assert eyes == (0.0, 0.0, f, 1.0) and scene == (f, 0.0, 1.0, 1.0)


def test_both_views_draw_the_field_and_the_plane_as_far():
    """The VTK view's plane reaches y = field_reach (its far edge); the vector view's too."""
    pytest.importorskip("pyvista")
    from vtkmodules.vtkRenderingCore import vtkRenderer

    from eyeviz.model import shapes3d
    from eyeviz.model.scene import Eyes, Feature, Scene
    from eyeviz.model.state3d import compute_state3d
    from eyeviz.render.vtk.scene3d import Scene3DActors

    for r in (300.0, 1000.0, 4700.0):
        sc = Scene(Eyes(40.0, 20.0, nside=8), [Feature("a", 0.0, r, 30.0, "#D55E00", 0.0)],
                   ["eyes", "features", "bfv", "plane"])  # fmt: skip
        st = compute_state3d(sc)
        reach = style3d.field_reach(shapes3d.scene_extent(st))
        assert 1.1 * shapes3d.scene_extent(st) <= reach * 2**0.25 + 1e-9
        act = Scene3DActors(vtkRenderer(), vtkRenderer())
        act.update(sc, st, None)
        assert act.field.plane_actors[0].GetBounds()[3] == pytest.approx(reach)
        quads = perspective3d._plane(st)[0][0].pts
        assert quads[..., 1].max() == pytest.approx(reach)
