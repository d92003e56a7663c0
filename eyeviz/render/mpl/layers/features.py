"""``features``: the discs; ``labels``: feature names, eyes A/B, origin O, indices."""

from __future__ import annotations

import math

import numpy as np
from matplotlib.patches import Circle

from eyeviz.render.mpl.canvas import Canvas, boxes_meet
from eyeviz.render.mpl.layers import eyes
from eyeviz.render.mpl.layout import MAX_LABELS, more_text
from eyeviz.render.mpl.style import (
    FONT,
    HALO,
    INK,
    OUT_OF_DOMAIN,
    SMALL,
    dark,
    mix,
    pt,
    short,
    slug,
)


def color_of(cv: Canvas, i: int) -> str:
    ood = cv.frame.out_of_domain
    assert ood is not None  # build_frame always sets it
    return OUT_OF_DOMAIN if ood[i] else cv.frame.colors[i]


def paint(cv: Canvas) -> None:
    fr, ax = cv.frame, cv.ax
    minimum = 1.2 * cv.units_per_in / 72  # keep a point-sized feature visible
    labelled = unlabelled = 0
    dots: dict[str, tuple[list[float], list[float]]] = {}  # colour -> a point per small disc
    for i, name in enumerate(fr.names):
        col = color_of(cv, i)
        x, y, g = float(fr.x[i]), float(fr.y[i]), float(fr.g[i])
        disc = Circle((x, y), g, facecolor=mix(col, 0.45), edgecolor=col, lw=0.8, zorder=8)
        disc.set_gid(f"feature-{slug(name)}")
        ax.add_artist(disc)  # the view is fixed: add_patch's data limits cost 0.9 ms a disc
        if g < minimum:
            xs, ys = dots.setdefault(col, ([], []))
            xs.append(x)
            ys.append(y)
        in_view = cv.xlim[0] - g <= x <= cv.xlim[1] + g and cv.ylim[0] - g <= y <= cv.ylim[1] + g
        if "labels" in cv.layers and in_view:  # no label for a feature out of the view
            if labelled < MAX_LABELS:  # the first MAX_LABELS in the view, in scene order
                _feature_label(cv, i, col)
                labelled += 1
            else:
                unlabelled += 1
    for col, (xs, ys) in dots.items():  # one line per colour, not one per feature
        ax.plot(xs, ys, ls="none", marker="o", ms=2.4, color=col, zorder=8, mew=0)
    if unlabelled:
        cv.notes.append(more_text(unlabelled, "more unlabelled"))


def _feature_label(cv: Canvas, i: int, col: str) -> None:
    """Name beside the disc, in the free direction among eight (inside the view)."""
    fr, upi = cv.frame, cv.units_per_in
    text = short(fr.names[i])
    x, y, g = float(fr.x[i]), float(fr.y[i]), float(fr.g[i])
    tw = (len(text) * 0.6 * pt(FONT) / 72 + 0.02) * upi
    th = pt(FONT) / 72 * upi
    gap = 0.04 * upi
    best, best_cost = (x, y), math.inf
    for j, deg in enumerate((30, -30, 150, -150, 0, 180, 90, -90)):
        a = math.radians(deg)
        ux, uy = math.cos(a), math.sin(a)
        ax_, ay_ = x + (g + gap) * ux, y + (g + gap) * uy
        x0 = ax_ - (tw if ux < -0.3 else tw / 2 if abs(ux) <= 0.3 else 0)
        y0 = ay_ - (th if uy < -0.3 else th / 2 if abs(uy) <= 0.3 else 0)
        cost = 0.02 * j
        if x0 < cv.xlim[0] or x0 + tw > cv.xlim[1]:
            cost += 5
        if y0 < cv.ylim[0] or y0 + th > cv.ylim[1]:
            cost += 5
        # the discs the label would cover, all at once (one numpy pass per direction)
        dx = np.maximum(np.maximum(x0 - fr.x, 0), fr.x - (x0 + tw))
        dy = np.maximum(np.maximum(y0 - fr.y, 0), fr.y - (y0 + th))
        cost += 2 * int(np.count_nonzero(np.hypot(dx, dy) < fr.g + 0.3 * gap))
        for box in cv.label_boxes:
            if boxes_meet(box, (x0, y0, x0 + tw, y0 + th)):
                cost += 3
        if cost < best_cost:
            best, best_cost = (x0, y0), cost
    x0, y0 = best
    cv.label_boxes.append((x0, y0, x0 + tw, y0 + th))
    cv.ax.text(
        x0,
        y0 + th / 2,
        text,
        ha="left",
        va="center",
        fontsize=FONT,
        color=dark(col),
        bbox=HALO,
        zorder=9,
        gid=f"label-{slug(fr.names[i])}",
        clip_on=True,
        parse_math=False,
    )


def labels(cv: Canvas) -> None:
    p, ax = cv.pair, cv.eye_ax
    numbered = "eyes" in cv.layers and eyes.numbers_fit(cv)
    for name, (cx, cy) in zip("AB", p.centers, strict=True):
        ax.text(
            cx,
            cy - p.l * (1.55 if numbered else 1.12),
            name,
            ha="center",
            va="top",
            fontsize=FONT + 0.5,
            color=INK,
            zorder=6,
            gid=f"label-eye-{name}",
            bbox=HALO,
        )
    ax.plot([0], [0], marker="+", ms=4, color=INK, mew=0.6, zorder=6)
    ax.text(
        0,
        -0.12 * p.l,
        "O",
        ha="center",
        va="top",
        fontsize=SMALL,
        color=INK,
        zorder=6,
        gid="label-origin",
        bbox=HALO,
    )
    if "eyes" in cv.layers:
        eyes.numbers(cv)
