"""The predictions figure's close-up of the selected ball and its legend (issue 32.13).

At the paper's distances the estimators' answers lie within a few percent of the true
ball, so in the whole view their ghosts are one blob a couple of millimetres wide. The
close-up looks at the true ball from the view's direction, near enough that the ball and
every ghost fill it (as the planar figure magnifies the eyes in an inset); the legend
names each estimator's colour, the true ball's and the limit's posterior points.
"""

from __future__ import annotations

import dataclasses
import math
from typing import cast

import numpy as np
from matplotlib.axes import Axes
from matplotlib.colors import to_rgba
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Patch, Rectangle

from eyeviz.model.camera3d import Camera3D, project
from eyeviz.model.predictions3d import LIMIT, Predictions3D, estimator_color3d
from eyeviz.model.scene import Scene
from eyeviz.model.state3d import SceneState3D
from eyeviz.render.mpl.ghosts3d import draw_ghosts
from eyeviz.render.mpl.perspective3d import draw_view
from eyeviz.render.mpl.style import GREY, INK, SMALL, short
from eyeviz.render.style3d import GHOST_OPACITY

__all__ = ["INSET_FRACTION", "close_camera", "draw_ball_inset"]

#: the close-up's height, a fraction of the scene view's
INSET_FRACTION = 0.46


def close_camera(cam: Camera3D, preds: Predictions3D, margin: float = 1.25) -> Camera3D:
    """``cam``'s direction, aimed at the true ball, near enough that the ball and every
    ghost (radius ``preds.g``) fit a square view with ``margin`` to spare."""
    truth = np.asarray(preds.truth, float)
    pts = np.array([(a.x, a.y, a.z) for a in preds.ghosts()], float).reshape(-1, 3)
    far = float(np.max(np.linalg.norm(pts - truth, axis=1))) if len(pts) else 0.0
    reach = margin * (far + preds.g)
    back = np.asarray(cam.position, float) - truth
    back /= max(float(np.linalg.norm(back)), 1e-300)
    dist = reach / math.tan(math.radians(cam.view_angle) / 2.0) + preds.g
    pos = tuple(float(v) for v in truth + back * dist)
    return Camera3D(pos, tuple(float(v) for v in truth), cam.view_up, cam.view_angle)  # type: ignore[arg-type]


def _corner(scene_ax: Axes, st: SceneState3D, cam: Camera3D, w: float, h: float) -> tuple[int, int]:
    """The top corner (sx: +1 right, -1 left; sy = 1) of the scene view where a
    close-up ``w`` x ``h`` (axes fractions) covers the fewest balls: the top right
    first, the top left (the view's caption) last."""
    pos = scene_ax.get_position()
    fw, fh = cast(Figure, scene_ax.get_figure()).get_size_inches()
    aspect = pos.width * fw / max(pos.height * fh, 1e-9)
    pts = np.column_stack([st.x, st.y, st.z]) if st.n else np.zeros((0, 3))
    xy, depth = project(cam, pts, aspect)
    u = (xy + 1.0) / 2.0  # axes fractions
    u = u[(depth > 0) & np.isfinite(u).all(axis=1)]
    best, best_n = (1, 1), math.inf
    for sx, sy in ((1, 1), (-1, 1)):  # the legend lies along the bottom
        x0 = 1.0 - w if sx > 0 else 0.0
        y0 = 1.0 - h if sy > 0 else 0.0
        n = int(np.sum((u[:, 0] >= x0 - 0.03) & (u[:, 0] <= x0 + w + 0.03)
                       & (u[:, 1] >= y0 - 0.06) & (u[:, 1] <= y0 + h + 0.06)))  # fmt: skip
        if n < best_n:
            best, best_n = (sx, sy), n
    return best


def draw_ball_inset(
    scene_ax: Axes, st: SceneState3D, scene: Scene, preds: Predictions3D, cam: Camera3D
) -> Axes | None:
    """The close-up in the scene view's corner that hides the fewest balls, the legend
    along the view's bottom; returns the close-up's axes (None without a ghost)."""
    if not preds.ghosts() or not 0 <= preds.ball < len(scene.features):
        return None
    fig = cast(Figure, scene_ax.get_figure())
    pos = scene_ax.get_position()
    fw, fh = fig.get_size_inches()
    h = INSET_FRACTION  # axes fractions of the scene view
    w = h * pos.height * fh / (pos.width * fw)  # square
    if w > 0.34:  # a narrow view (one journal column): a smaller close-up
        h, w = h * 0.34 / w, 0.34
    sx, sy = _corner(scene_ax, st, cam, w, h)
    pad = 0.02
    ix = 1.0 - w - pad * 0.5 if sx > 0 else pad * 0.5
    iy = 1.0 - h - pad if sy > 0 else pad
    if sx < 0 and sy > 0:
        iy -= 0.08  # below the view's caption
    ax = fig.add_axes((pos.x0 + ix * pos.width, pos.y0 + iy * pos.height,
                       w * pos.width, h * pos.height))  # fmt: skip
    ax.set_gid("ball-inset")
    ax.add_patch(Rectangle((-1, -1), 2, 2, facecolor="white", edgecolor=GREY, lw=0.6, zorder=-1))
    f = scene.features[preds.ball]
    one = dataclasses.replace(scene, features=[f], layers=["features"])
    ccam = close_camera(cam, preds)
    draw_view(ax, st, one, ccam, 1.0, "scene", ["features"])
    draw_ghosts(ax, preds, ccam, 1.0)
    ax.set_xlim(-1.0, 1.0)
    ax.set_ylim(-1.0, 1.0)
    ax.set_axis_off()
    ax.text(-0.95, 0.95, f"{short(f.name, 16)} close up", fontsize=SMALL, color=INK,
            ha="left", va="top", parse_math=False)  # fmt: skip
    handles: list = [
        Patch(facecolor=f.color, edgecolor="none", label=f"{short(f.name, 16)}: truth")
    ]
    for a in preds.ghosts():
        col = to_rgba(estimator_color3d(a.name))
        handles.append(
            Patch(facecolor=(*col[:3], GHOST_OPACITY), edgecolor=col, lw=0.8, label=a.name)
        )
    if preds.cloud is not None and len(preds.cloud.points):
        handles.append(
            Line2D([], [], ls="none", marker="o", ms=2.5, mew=0,
                   color=estimator_color3d(LIMIT), label=f"{LIMIT}: posterior")
        )  # fmt: skip
    # one row along the view's bottom (two where it is too narrow), over the plane only
    chars = sum(len(str(hd.get_label())) + 4 for hd in handles)
    ncol = len(handles) if chars * 0.6 * SMALL / 72.0 < 0.95 * pos.width * fw else 3
    leg = scene_ax.legend(
        handles=handles, loc="lower center", bbox_to_anchor=(0.5, 0.01), ncol=ncol,
        fontsize=SMALL, frameon=True, framealpha=0.9, edgecolor=GREY, handlelength=1.2,
        borderpad=0.3, labelspacing=0.25, columnspacing=0.8, handletextpad=0.4,
        borderaxespad=0.0,
    )  # fmt: skip
    leg.set_gid("ghost-legend")
    return ax
