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
    from eyeviz.render.vtk import scene3d, style

    for name in ("EYES_FRACTION", "EDGE_RGB", "EDGES_MAX_NSIDE", "BFV_RGB", "BFV_OPACITY",
                 "CONE_OPACITY", "PLANE_RGB", "EYE_CONE"):  # fmt: skip
        assert getattr(scene3d, name) is getattr(style3d, name), name
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
