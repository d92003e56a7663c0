"""``eyes``: the 2 x m ommatidium triangles (Figure 2), lit in the feature's colour.

Runs of equal colour (:attr:`EyeFrame.runs`) become one wedge when a triangle is below a
device pixel; in the main view beside an inset, each eye is a disc of its true radius,
or of a minimum visible radius (the inset says by how much the eyes are magnified).
"""

from __future__ import annotations

import math

import numpy as np
from matplotlib.patches import Circle, Patch, Polygon, Wedge

from eyeviz.render.mpl.canvas import Canvas
from eyeviz.render.mpl.style import EDGE, GREY, INK, SMALL, UNLIT

MIN_EYE_PT = 0.6  # the smallest radius an eye is drawn with, in points


def merges(cv: Canvas) -> bool:
    if cv.merge is not None:
        return bool(cv.merge)
    p = cv.pair
    base = 2 * p.l * math.sin(p.gamma / 2) / cv.eye_units_per_in  # inches
    return base * cv.dpi < 1.0


def _in_view(ax, center: tuple[float, float], rim: np.ndarray) -> np.ndarray:
    """Per cell (triangle centre, rim[i], rim[i + 1]): does its bounding box meet the
    axes' view (expanded by 5 %)?"""
    x0, x1 = sorted(ax.get_xlim())
    y0, y1 = sorted(ax.get_ylim())
    dx, dy = 0.05 * (x1 - x0), 0.05 * (y1 - y0)
    xs = np.column_stack([np.full(len(rim) - 1, center[0]), rim[:-1, 0], rim[1:, 0]])
    ys = np.column_stack([np.full(len(rim) - 1, center[1]), rim[:-1, 1], rim[1:, 1]])
    return (
        (xs.max(axis=1) >= x0 - dx)
        & (xs.min(axis=1) <= x1 + dx)
        & (ys.max(axis=1) >= y0 - dy)
        & (ys.min(axis=1) <= y1 + dy)
    )


def paint(cv: Canvas) -> None:
    p, fr, ax = cv.pair, cv.frame, cv.eye_ax
    merge = merges(cv)
    cv.merged = merge
    base_in = 2 * p.l * math.sin(p.gamma / 2) / cv.eye_units_per_in
    edges = base_in * 72 >= 2.5 and not merge
    fills = [UNLIT] + fr.palette
    gam = p.gamma
    for eye in fr.eyes:
        cx, cy = eye.center
        if merge:
            for s, e, c in zip(*(a.tolist() for a in eye.runs), strict=True):
                patch: Patch
                if e - s == p.m:
                    patch = Circle((cx, cy), p.l)
                else:
                    patch = Wedge((cx, cy), p.l, math.degrees(s * gam), math.degrees(e * gam))
                patch.set(facecolor=fills[c], edgecolor="none", lw=0, zorder=2)
                patch.set_gid(
                    f"ommatidia-{eye.name}-{s}-{e - 1}"
                    if e - s > 1
                    else f"ommatidium-{eye.name}-{s}"
                )
                ax.add_patch(patch)
        else:
            k = np.arange(p.m + 1) * gam
            rim = np.column_stack([cx + p.l * np.cos(k), cy + p.l * np.sin(k)])
            seen = _in_view(ax, (cx, cy), rim)
            for i, c in enumerate(eye.color_index.tolist()):
                if not seen[i]:  # zoomed in on a few cells: the others are not drawn
                    continue
                tri = Polygon(
                    [(cx, cy), rim[i], rim[i + 1]],
                    closed=True,
                    facecolor=fills[c],
                    edgecolor=EDGE if edges else "none",
                    lw=0.3 if edges else 0,
                    joinstyle="round",
                    zorder=2,
                )
                tri.set_gid(f"ommatidium-{eye.name}-{i}")
                ax.add_patch(tri)
        ax.add_patch(
            Circle(
                (cx, cy),
                p.l,
                facecolor="none",
                edgecolor=INK,
                lw=0.5,
                zorder=3,
                gid=f"eye-{eye.name}-rim",
            )
        )
        ax.plot([cx], [cy], marker="o", ms=1.6, color=INK, zorder=4, mew=0)
    if cv.inset is not None:
        # the main view keeps each eye a disc of its true radius (tangent to the BFV
        # edges), never below MIN_EYE_PT so it stays visible; the inset shows the cells
        rad = max(p.l, MIN_EYE_PT / 72 * cv.units_per_in)
        for eye in fr.eyes:
            cv.ax.add_patch(
                Circle(
                    eye.center,
                    rad,
                    facecolor=UNLIT,
                    edgecolor=INK,
                    lw=0.5,
                    zorder=4,
                    gid=f"eye-{eye.name}-main",
                )
            )


def numbers_fit(cv: Canvas) -> bool:
    p = cv.pair
    return 1.28 * p.l * p.gamma / cv.eye_units_per_in * 72 >= 7.5


def numbers(cv: Canvas) -> None:
    """Ommatidium indices around each eye, when there is room."""
    p, ax = cv.pair, cv.eye_ax
    if not numbers_fit(cv):
        return
    arc_in = 1.28 * p.l * p.gamma / cv.eye_units_per_in
    step = 1 if arc_in * 72 >= 9 else 2
    for name, (cx, cy) in zip("AB", p.centers, strict=True):
        for k in range(0, p.m, step):
            a = (k + 0.5) * p.gamma
            ax.text(
                cx + 1.28 * p.l * math.cos(a),
                cy + 1.28 * p.l * math.sin(a),
                str(k),
                ha="center",
                va="center",
                fontsize=SMALL,
                color=GREY,
                zorder=4,
                gid=f"ommatidium-number-{name}-{k}",
            )
