"""The 3D view's looks, shared by its two painters (issue 22, docs/spherical.md): the VTK
view (:mod:`eyeviz.render.vtk.scene3d`) and its vector twin drawn from the model
(:mod:`eyeviz.render.mpl.perspective3d`, which must not import VTK). Colours are rgb
floats in [0, 1]; no geometry here (that is :mod:`eyeviz.model.shapes3d`'s), no VTK, no
matplotlib.

``tests/render/test_figure3d_vtk.py`` compares the two pictures; the colours the planar
VTK view shares (unlit facets, the close-up's background, ink) are also in
:mod:`eyeviz.render.vtk.style`, checked equal by ``tests/render/test_style3d.py``.
"""

from __future__ import annotations

import math

__all__ = [
    "BALL_LIGHT",
    "BFV_OPACITY",
    "BFV_RGB",
    "CLOUD_PX",
    "CONE_OPACITY",
    "EDGES_MAX_NSIDE",
    "EDGE_RGB",
    "EYES_FRACTION",
    "EYE_CONE",
    "EYE_LIGHT",
    "GHOST_DOT_PX",
    "GHOST_LINE_PX",
    "GHOST_OPACITY",
    "GRID_OPACITY",
    "INK_RGB",
    "INSET_RGB",
    "LINK_OPACITY",
    "PLANE_OPACITY",
    "PLANE_RGB",
    "UNLIT_RGB",
    "field_reach",
    "split_viewports",
]

#: The eyes' close-up takes this fraction of the view's width (left); the scene the rest.
EYES_FRACTION = 0.4
#: Facet edges are drawn up to this nside (at 16 the edges of a ~100 px eye hide its
#: facets), in this colour.
EDGES_MAX_NSIDE = 8
EDGE_RGB = (0.55, 0.55, 0.55)
#: The boundary of the 3D binocular field (layer "bfv"), translucent.
BFV_RGB = (0.80, 0.72, 0.35)
BFV_OPACITY = 0.16
#: The tangent cones (layer "tangents") in their ball's colour at this opacity.
CONE_OPACITY = 0.28
#: The plane z = 0 (layer "plane"): its fill and its grid lines.
PLANE_RGB = (0.55, 0.62, 0.75)
PLANE_OPACITY = 0.10
GRID_OPACITY = 0.6
#: The eyes' close-up draws the tangent cones this many eye radii long.
EYE_CONE = 4.0
#: An unlit facet (225 grey, as the planar view's), the close-up's background, ink.
UNLIT_RGB = (225 / 255, 225 / 255, 225 / 255)
INSET_RGB = (0.965, 0.965, 0.955)
INK_RGB = (0.15, 0.15, 0.15)
#: The predictions layer (issue 23 item 4; colours by estimator, eyeviz.model.palette): a
#: ghost ball's fill opacity, its outline's and the link's width (points in the vector
#: figure, pixels in VTK), its centre dot, the link's opacity, a posterior point's size.
GHOST_OPACITY = 0.22
GHOST_LINE_PX = 2.5
GHOST_DOT_PX = 7.0
LINK_OPACITY = 0.8
CLOUD_PX = 4.0
#: (ambient, diffuse) of the eyes' and the balls' surfaces.
EYE_LIGHT = (0.45, 0.6)
BALL_LIGHT = (0.35, 0.7)


def split_viewports(w: float, h: float) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """(eyes, scene) viewports (xmin, ymin, xmax, ymax), fractions of a ``w`` x ``h`` view:
    the close-up takes :data:`EYES_FRACTION` of the width, half of a tall view."""
    f = EYES_FRACTION if w >= 2.0 * h * EYES_FRACTION else 0.5
    return (0.0, 0.0, f, 1.0), (f, 0.0, 1.0, 1.0)


def field_reach(extent: float) -> float:
    """How far from the origin the views draw the binocular field's cones and the plane
    z = 0 for balls reaching ``extent`` (:func:`eyeviz.model.shapes3d.scene_extent`):
    1.1 ``extent`` rounded up to a step of 2^0.5 (the VTK view rebuilds them only when the
    step changes, not every frame of a drag; the vector view draws them as far)."""
    step = round(2.0 * math.log2(1.1 * extent))
    return 2.0 ** (step / 2.0 + 0.5)
