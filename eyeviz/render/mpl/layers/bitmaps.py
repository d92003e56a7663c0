"""``bitmaps``: Omega_A and Omega_B as two strips with the lit [L, R] (Section 4), drawn
from the eyes' colour runs (:attr:`EyeFrame.runs`) and :attr:`Frame.intervals`."""

from __future__ import annotations

from matplotlib.patches import Rectangle

from eyeviz.render.mpl.canvas import Canvas
from eyeviz.render.mpl.layout import LABEL_PT, LANE, interval_lanes, more_text
from eyeviz.render.mpl.style import FONT, GREY, INK, SMALL, UNLIT, dark, slug, subscripted

STRIP = 0.12
AXIS_H = 0.15


# long: a figure's layout, strip after strip in drawing order: matplotlib calls, not logic
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
    k = cv.lay.font_scale  # lanes and the axis between the strips grow with --min-font
    lane_h = LANE * k
    label_pt = cv.lay.pt(LABEL_PT)
    yB = cv.lay.lanes[1] * lane_h + 0.01
    yA = yB + STRIP + AXIS_H * k
    fills = [None] + fr.palette
    rear = "rear half: not a network input"  # shortened where --min-font makes it too wide
    if len(rear) * 0.6 * cv.lay.pt(SMALL) / 72 > 0.95 * box.w * (m - half) / m:
        rear = "rear half: not an input"
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
            rear,
            ha="center",
            va="center",
            fontsize=SMALL,
            color=GREY,
            zorder=3,
        )
        L, R = fr.intervals[name]
        above = name == "A"
        lanes = interval_lanes(L, R, m, box.w, pt=label_pt, max_lanes=cv.lay.max_lanes)
        for i, text, centre, lane in lanes:
            dy = 0.008 + lane * lane_h
            ax.text(
                centre,
                y0 + STRIP + dy if above else y0 - dy,
                text,
                ha="center",
                va="bottom" if above else "top",
                fontsize=label_pt,
                color=dark(fr.colors[i]),
                gid=f"bitmap-interval-{name}-{slug(fr.names[i])}",
            )
        if lanes.dropped:  # one line for the labels no lane could hold
            dy = 0.008 + lanes.used * lane_h
            ax.text(
                m,
                y0 + STRIP + dy if above else y0 - dy,
                more_text(lanes.dropped, "more intervals"),
                ha="right",
                va="bottom" if above else "top",
                fontsize=label_pt,
                color=GREY,
                gid=f"bitmap-interval-{name}-more",
            )
    ymid = yB + STRIP + AXIS_H * k / 2
    for k in (0, m // 4, half, 3 * m // 4, m):
        lab = f"{k}" if k != half else f"m/2 = {half}"
        ax.plot([k, k], [yA - 0.015, yA], color=GREY, lw=0.4)
        ax.plot([k, k], [yB + STRIP, yB + STRIP + 0.015], color=GREY, lw=0.4)
        ha = "left" if k == 0 else "right" if k == m else "center"
        ax.text(k, ymid, lab, ha=ha, va="center", fontsize=SMALL, color=GREY)
