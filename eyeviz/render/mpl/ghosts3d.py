"""The predictions layer of the 3D vector figure: each estimator's ghost ball and the
limit's posterior cloud, drawn over the scene through the camera as the VTK overlay
(:mod:`eyeviz.render.vtk.ghosts3d`) draws them; used by
:func:`eyeviz.render.mpl.perspective3d.draw_panel`."""

from __future__ import annotations

import math

import numpy as np
from matplotlib.axes import Axes
from matplotlib.colors import to_rgba

from eyeviz.model.camera3d import Camera3D, basis, project
from eyeviz.model.predictions3d import LIMIT, Predictions3D, estimator_color3d
from eyeviz.render.style3d import (
    CLOUD_PX,
    GHOST_DOT_PX,
    GHOST_LINE_PX,
    GHOST_OPACITY,
    LINK_OPACITY,
)

__all__ = ["GHOST_RING_N", "PX_TO_PT", "draw_ghosts", "ghost_outline"]

#: Points per ghost outline; the VTK layer's pixel sizes scaled to points of the figure.
GHOST_RING_N = 96
PX_TO_PT = 0.4


def ghost_outline(cam: Camera3D, centre, g: float, n: int = GHOST_RING_N) -> np.ndarray:
    """(n, 3) points of the circle of radius ``g`` about ``centre`` facing the camera (the
    VTK layer's outline, a follower of the same circle)."""
    right, up, _ = basis(cam)
    t = np.linspace(0.0, 2.0 * math.pi, n, endpoint=False)
    c = np.asarray(centre, np.float64)
    return c + g * (np.cos(t)[:, None] * right + np.sin(t)[:, None] * up)


def draw_ghosts(ax: Axes, preds: Predictions3D | None, cam: Camera3D, aspect: float) -> None:
    """The predictions layer over the scene (as the VTK overlay: above everything): per
    estimator a translucent disc with its outline (the ghost ball seen through ``cam``),
    its centre and a line from the true centre; the limit's posterior as points."""
    if preds is None:
        return
    near = 0.0
    for a in preds.ghosts():
        col = to_rgba(estimator_color3d(a.name))
        ring, depth = project(cam, ghost_outline(cam, (a.x, a.y, a.z), preds.g), aspect)
        if not np.all(depth > near):
            continue
        ax.fill(ring[:, 0], ring[:, 1], facecolor=(*col[:3], GHOST_OPACITY), edgecolor=col,
                lw=GHOST_LINE_PX * PX_TO_PT, gid=f"ghost-{a.name}", zorder=5)  # fmt: skip
        link, d = project(cam, np.array([preds.truth, (a.x, a.y, a.z)]), aspect)
        if np.all(d > near):
            ax.plot(link[:, 0], link[:, 1], color=col, alpha=LINK_OPACITY,
                    lw=0.6 * GHOST_LINE_PX * PX_TO_PT, zorder=5)  # fmt: skip
            ax.plot([link[1, 0]], [link[1, 1]], marker="o", ms=GHOST_DOT_PX * PX_TO_PT,
                    mew=0, color=col, zorder=6)  # fmt: skip
    cloud = preds.cloud
    if cloud is not None and len(cloud.points):
        xy, d = project(cam, cloud.points, aspect)
        ok = d > near
        rgba = np.tile(to_rgba(estimator_color3d(LIMIT)), (int(ok.sum()), 1))
        rgba[:, 3] = cloud.alpha[ok]
        ax.scatter(xy[ok, 0], xy[ok, 1], s=(CLOUD_PX * PX_TO_PT) ** 2, c=rgba, lw=0,
                   zorder=6, gid="posterior-cloud")  # fmt: skip
