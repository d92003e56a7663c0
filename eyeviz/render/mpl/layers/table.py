"""``readout``: the table of r, phi about O, A and B, BFV and visibility per feature, with
each estimator's answer and the ambiguity ranges, all read from the Frame."""

from __future__ import annotations

import math

from eyeviz.model.frame import PredictionFrame
from eyeviz.model.palette import estimator_color
from eyeviz.render.mpl.canvas import Canvas
from eyeviz.render.mpl.style import GREY, LIGHT, OUT_OF_DOMAIN, SMALL, dark, distance, short, slug

# (header, x as a fraction of the table's width, alignment)
COLUMNS = [
    ("feature", 0.0, "left"),
    ("r", 0.29, "right"),
    ("\u03c6", 0.395, "right"),
    ("r", 0.50, "right"),
    ("\u03c6", 0.605, "right"),
    ("r", 0.71, "right"),
    ("\u03c6", 0.815, "right"),
    ("BFV", 0.862, "center"),
    ("seen by", 1.0, "right"),
]


def row_values(fr, i: int) -> list[str]:
    """The table's cells for feature i, from the Frame's readout arrays."""
    seen = " ".join(e for e, v in (("A", fr.vis_a[i]), ("B", fr.vis_b[i])) if v) or "none"
    return [
        short(fr.names[i], 15),
        distance(float(fr.r[i])),
        f"{math.degrees(fr.phi[i]):.1f}\u00b0",
        distance(float(fr.rA[i])),
        f"{math.degrees(fr.phiA[i]):.1f}\u00b0",
        distance(float(fr.rB[i])),
        f"{math.degrees(fr.phiB[i]):.1f}\u00b0",
        "yes" if fr.in_bfv[i] else "no",
        seen,
    ]


def prediction_line(fr, i: int, name: str) -> str:
    if fr.out_of_domain[i]:
        return f"{name}: outside the networks' domain (not in the BFV or not seen by both)"
    pred = fr.predictions.get(name)
    if not isinstance(pred, PredictionFrame):
        return f"{name}: no answer for this eye design"  # never the reason's text (paths)
    r_hat, phi_hat = float(pred.r_hat[i]), float(pred.phi_hat[i])
    if not (math.isfinite(r_hat) and math.isfinite(phi_hat)):
        return f"{name}: no answer for these bitmaps"
    return (
        f"{name}: r\u0302 = {distance(r_hat)} (\u0394r {pred.dr[i]:+.0f}, "
        f"{pred.dr_pct[i]:+.1f} %),  \u03c6\u0302 = {math.degrees(phi_hat):.2f}\u00b0 "
        f"(\u0394\u03c6 {pred.dphi_deg[i]:+.2f}\u00b0)"
    )


def ambiguity_line(fr, i: int) -> str:
    reg = fr.ambiguity.get(i)
    if reg is None:
        return "same bitmaps: covers an eye centre"
    lo, hi = reg["r_range"]
    a0, a1 = reg["phi_range"]
    more = "" if reg["bounded"] else "+ (unbounded)"
    return (
        f"same bitmaps for centres at r \u2208 [{distance(lo)}, {distance(hi)}]{more}, "
        f"\u03c6 \u2208 [{math.degrees(a0):.2f}\u00b0, {math.degrees(a1):.2f}\u00b0]"
    )


def paint(cv: Canvas) -> None:
    box = cv.lay.readout
    if box is None:
        return
    fr = cv.frame
    ax = cv.fig.add_axes(box.frac(cv.lay.width, cv.lay.height))
    ax.set_gid("readout")
    ax.axis("off")
    ax.set_xlim(0, 1)
    ax.set_ylim(0, 1)
    dy = 1.0 / cv.lay.readout_rows
    y = 1 - dy / 2
    for text, x0, x1 in (
        ("about the origin O", 0.215, 0.40),
        ("about eye A", 0.425, 0.61),
        ("about eye B", 0.635, 0.82),
    ):
        ax.text((x0 + x1) / 2, y, text, ha="center", va="center", fontsize=SMALL, color=GREY)
        ax.plot([x0 + 0.01, x1], [y - 0.42 * dy] * 2, color=LIGHT, lw=0.4)
    y -= dy
    for text, x, ha in COLUMNS:
        ax.text(x, y, text, ha=ha, va="center", fontsize=SMALL, color=GREY)
    ax.plot([0, 1], [y - dy / 2, y - dy / 2], color=LIGHT, lw=0.4)
    for i in range(fr.n):
        y -= dy
        col = OUT_OF_DOMAIN if fr.out_of_domain[i] else dark(fr.colors[i])
        for j, ((_, x, ha), v) in enumerate(zip(COLUMNS, row_values(fr, i), strict=True)):
            ax.text(
                x,
                y,
                v,
                ha=ha,
                va="center",
                fontsize=SMALL,
                color=col,
                gid=f"readout-{j}-{i}-{slug(fr.names[i])}",
                parse_math=False,
            )
        if "predictions" in cv.layers:
            for name in fr.predictions:
                y -= dy
                ax.text(
                    0.03,
                    y,
                    prediction_line(fr, i, name),
                    ha="left",
                    va="center",
                    fontsize=SMALL,
                    color=OUT_OF_DOMAIN if fr.out_of_domain[i] else estimator_color(name),
                    gid=f"readout-prediction-{slug(name)}-{i}",
                )
        if "ambiguity" in cv.layers:
            y -= dy
            ax.text(
                0.03,
                y,
                ambiguity_line(fr, i),
                ha="left",
                va="center",
                fontsize=SMALL,
                color=col,
                gid=f"readout-ambiguity-{i}",
            )
