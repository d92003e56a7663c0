"""``bitmaps``: Omega_A and Omega_B as two strips with the lit [L, R] (Section 4), drawn
from the eyes' colour runs (:attr:`EyeFrame.runs`) and :attr:`Frame.intervals`."""

from __future__ import annotations

from matplotlib.patches import Rectangle

from eyeviz.render.mpl.canvas import Canvas
from eyeviz.render.mpl.layout import LABEL_PT, LANE, interval_lanes
from eyeviz.render.mpl.style import FONT, GREY, INK, SMALL, UNLIT, dark, slug, subscripted

STRIP = 0.12
AXIS_H = 0.15


def paint(cv: Canvas) -> None:
    box = cv.lay.bitmaps
    fr = cv.frame
    if box is None or not fr.eyes:
        return
    m, half = fr.pair.m, fr.pair.m // 2
    ax = cv.fig.add_axes(box.frac(cv.lay.width, cv.lay.height))
    ax.set_gid("bitmaps")
    ax.set_xlim(0, m)
    ax.set_ylim(0, box.h)  # y in inches
    ax.axis("off")
    yB = cv.lay.lanes[1] * LANE + 0.01
    yA = yB + STRIP + AXIS_H
    fills = [None] + fr.palette
    for eye, y0 in zip(fr.eyes, (yA, yB), strict=True):
        name = eye.name
        ax.add_patch(
            Rectangle(
                (0, y0),
                half,
                STRIP,
                facecolor=UNLIT,
                edgecolor="none",
                zorder=1,
                gid=f"bitmap-{name}-omega",
            )
        )
        ax.add_patch(
            Rectangle(
                (half, y0),
                m - half,
                STRIP,
                facecolor="#F4F4F4",
                edgecolor="none",
                zorder=1,
                gid=f"bitmap-{name}-rear",
            )
        )
        for s, e, c in zip(*(a.tolist() for a in eye.runs), strict=True):
            if c == 0:
                continue
            ax.add_patch(
                Rectangle(
                    (s, y0),
                    e - s,
                    STRIP,
                    facecolor=fills[c],
                    edgecolor="none",
                    zorder=2,
                    gid=f"bitmap-{name}-lit-{s}-{e - 1}",
                )
            )
        ax.add_patch(
            Rectangle((0, y0), m, STRIP, facecolor="none", edgecolor=GREY, lw=0.4, zorder=3)
        )
        ax.plot(
            [half, half],
            [y0 - 0.012, y0 + STRIP + 0.012],
            color=INK,
            lw=0.7,
            zorder=4,
            solid_capstyle="butt",
        )
        subscripted(
            ax,
            -0.015 * m,
            y0 + STRIP / 2,
            [("\u03a9", False), (name, True)],
            FONT,
            "right",
            INK,
            gid=f"bitmap-{name}-name",
        )
        ax.text(
            0.75 * m,
            y0 + STRIP / 2,
            "rear half: not a network input",
            ha="center",
            va="center",
            fontsize=SMALL,
            color=GREY,
            zorder=3,
        )
        L, R = fr.intervals[name]
        above = name == "A"
        for i, text, centre, lane in interval_lanes(L, R, m, box.w):
            dy = 0.008 + lane * LANE
            ax.text(
                centre,
                y0 + STRIP + dy if above else y0 - dy,
                text,
                ha="center",
                va="bottom" if above else "top",
                fontsize=LABEL_PT,
                color=dark(fr.colors[i]),
                gid=f"bitmap-interval-{name}-{slug(fr.names[i])}",
            )
    ymid = yB + STRIP + AXIS_H / 2
    for k in (0, m // 4, half, 3 * m // 4, m):
        lab = f"{k}" if k != half else f"m/2 = {half}"
        ax.plot([k, k], [yA - 0.015, yA], color=GREY, lw=0.4)
        ax.plot([k, k], [yB + STRIP, yB + STRIP + 0.015], color=GREY, lw=0.4)
        ha = "left" if k == 0 else "right" if k == m else "center"
        ax.text(k, ymid, lab, ha=ha, va="center", fontsize=SMALL, color=GREY)
