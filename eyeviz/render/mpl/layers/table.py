"""``readout``: the table of r, phi about O, A and B, BFV and visibility per feature, with
each estimator's answer and the ambiguity ranges, all read from the Frame."""

from __future__ import annotations

import math

from eyeviz.model.frame import PredictionFrame
from eyeviz.model.palette import estimator_color
from eyeviz.render.mpl.canvas import Canvas, fit_text
from eyeviz.render.mpl.layout import more_text
from eyeviz.render.mpl.style import GREY, LIGHT, OUT_OF_DOMAIN, SMALL, dark, distance, short, slug

# (header, alignment); the x positions follow the widest cell of each column
COLUMNS = [
    ("feature", "left"),
    ("r", "right"),
    ("\u03c6", "right"),
    ("r", "right"),
    ("\u03c6", "right"),
    ("r", "right"),
    ("\u03c6", "right"),
    ("BFV", "center"),
    ("seen by", "right"),
]
# the groups of columns over the header row: (header, short header, first, last column)
GROUPS = (
    ("about the origin O", "origin O", 1, 2),
    ("about eye A", "eye A", 3, 4),
    ("about eye B", "eye B", 5, 6),
)
CHAR_IN = 0.6 * SMALL / 72  # a generous width of one 6 pt character, inches
GAP_IN = 0.1  # at least this much between two cells


def column_x(cells: list[list[str]], width_in: float, gap: float = GAP_IN, name_min: float = 0.55):
    """(x, left, right) of each column as fractions of the table's width (x is the text
    anchor: the right edge for right-aligned columns), from the widest cell; None when the
    columns cannot fit with ``gap`` inches between them."""
    widths = [
        max([len(h)] + [len(row[j]) for row in cells]) * CHAR_IN for j, (h, _) in enumerate(COLUMNS)
    ]
    widths[0] = max(widths[0], name_min)
    need = sum(widths) + gap * (len(widths) - 1)
    if need > width_in:
        return None
    spare = min((width_in - need) / (len(widths) - 1), 0.3)  # compact on a wide figure
    xs, lefts, rights, x = [], [], [], 0.0
    for (_, ha), w in zip(COLUMNS, widths, strict=True):
        xs.append({"left": x, "right": x + w, "center": x + w / 2}[ha] / width_in)
        lefts.append(x / width_in)
        rights.append((x + w) / width_in)
        x += w + gap + spare
    return xs, lefts, rights


def row_values(fr, i: int, compact: bool = False, name_chars: int = 15) -> list[str]:
    """The table's cells for feature i, from the Frame's readout arrays (distances in full,
    or in at most 7 characters when ``compact``; the name cut to ``name_chars``)."""
    dist = distance if compact else _full
    seen = " ".join(e for e, v in (("A", fr.vis_a[i]), ("B", fr.vis_b[i])) if v) or "none"
    return [
        short(fr.names[i], name_chars),
        dist(float(fr.r[i])),
        f"{math.degrees(fr.phi[i]):.1f}\u00b0",
        dist(float(fr.rA[i])),
        f"{math.degrees(fr.phiA[i]):.1f}\u00b0",
        dist(float(fr.rB[i])),
        f"{math.degrees(fr.phiB[i]):.1f}\u00b0",
        "yes" if fr.in_bfv[i] else "no",
        seen,
    ]


def _full(v: float) -> str:
    return f"{v:.0f}" if math.isfinite(v) else "\u2013"


def prediction_line(fr, i: int, name: str) -> str:
    if fr.out_of_domain[i]:
        why = "not in the BFV" if not fr.in_bfv[i] else "not seen by both eyes"
        return f"{name}: outside the networks' domain ({why})"  # fits a single column
    pred = fr.predictions.get(name)
    if not isinstance(pred, PredictionFrame):
        if isinstance(pred, str) and pred.startswith("cannot answer: trained for "):
            return f"{name}: {pred.removeprefix('cannot answer: ')}"  # made for other eyes
        return f"{name}: no answer for this eye design"  # never the reason's text (paths)
    r_hat, phi_hat = float(pred.r_hat[i]), float(pred.phi_hat[i])
    if not (math.isfinite(r_hat) and math.isfinite(phi_hat)):
        return f"{name}: no answer for these bitmaps"
    return (
        f"{name}: r\u0302 = {distance(r_hat)} (\u0394r {pred.dr[i]:+.0f}, "
        f"{pred.dr_pct[i]:+.1f} %),  \u03c6\u0302 = {math.degrees(phi_hat):.2f}\u00b0 "
        f"(\u0394\u03c6 {pred.dphi_deg[i]:+.2f}\u00b0)"
    )


def posterior_line(fr, i: int) -> str:
    """Where the limit's posterior puts the centre, over every g (eyeviz.model.posterior)."""
    post = fr.posterior.get(i)
    if post is None or post.empty:
        return "posterior: none (the prior never makes these bitmaps)"
    lo, hi = post.r_interval(0.9)
    return f"posterior over every g: 90 % at r \u2208 [{distance(lo)}, {distance(hi)}]"


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


# long: the readout table's layout, column after column: matplotlib calls, not logic
def paint(cv: Canvas) -> None:
    box = cv.lay.readout
    if box is None:
        return
    fr = cv.frame
    ood = fr.out_of_domain
    assert ood is not None  # build_frame always sets it
    ax = cv.fig.add_axes(box.frac(cv.lay.width, cv.lay.height))
    ax.set_gid("readout")
    ax.axis("off")
    ax.set_xlim(0, 1)
    ax.set_ylim(0, 1)
    dy = 1.0 / cv.lay.readout_rows
    shown = cv.lay.table_features or fr.n  # the rest are counted in the last row
    k = cv.lay.font_scale  # text raised by --min-font: the same table, k times narrower
    width = box.w / k
    line_pt = 0.97 * box.w * 72  # a prediction or ambiguity line is cut to the table
    # full distances; else 3 significant digits; else shorter names and tighter gaps
    for compact, name_chars, gap, name_min in (
        (False, 15, GAP_IN, 0.55),
        (True, 15, GAP_IN, 0.55),
        (True, 10, 0.05, 0.4),
        (True, 6, 0.03, 0.3),
    ):
        cells = [row_values(fr, i, compact, name_chars) for i in range(shown)]
        cols = column_x(cells, width, gap, name_min)
        if cols is not None:
            break
    if cols is None:
        xs = [0.0, 0.29, 0.395, 0.5, 0.605, 0.71, 0.815, 0.862, 1.0]
        lefts, rights = [x - 0.09 for x in xs], xs
    else:
        xs, lefts, rights = cols
    y = 1 - dy / 2
    # each group's header within its own columns; the short ones (all of them, alike)
    # where a long one would reach its neighbour ("about the origin O" ran into
    # "about eye A" at 3.5 in)
    fits = all(len(t) * CHAR_IN <= (rights[b_] - lefts[a_]) * width for t, _, a_, b_ in GROUPS)
    for long_text, short_text, a, b in GROUPS:
        x0, x1 = lefts[a], rights[b]
        text = long_text if fits else short_text
        ax.text(
            (x0 + x1) / 2,
            y,
            text,
            ha="center",
            va="center",
            fontsize=SMALL,
            color=GREY,
            gid=f"readout-group-{a}",
        )
        ax.plot([x0 + 0.01, x1], [y - 0.42 * dy] * 2, color=LIGHT, lw=0.4)
    y -= dy
    for (text, ha), x in zip(COLUMNS, xs, strict=True):
        ax.text(x, y, text, ha=ha, va="center", fontsize=SMALL, color=GREY)
    ax.plot([0, rights[-1]], [y - dy / 2, y - dy / 2], color=LIGHT, lw=0.4)
    for i in range(shown):
        y -= dy
        col = OUT_OF_DOMAIN if ood[i] else dark(fr.colors[i])
        for j, ((_, ha), x, v) in enumerate(zip(COLUMNS, xs, cells[i], strict=True)):
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
                    fit_text(prediction_line(fr, i, name), SMALL, line_pt),
                    ha="left",
                    va="center",
                    fontsize=SMALL,
                    color=OUT_OF_DOMAIN if ood[i] else estimator_color(name),
                    gid=f"readout-prediction-{slug(name)}-{i}",
                )
        if "ambiguity" in cv.layers:
            y -= dy
            ax.text(
                0.03,
                y,
                fit_text(ambiguity_line(fr, i), SMALL, line_pt),
                ha="left",
                va="center",
                fontsize=SMALL,
                color=col,
                gid=f"readout-ambiguity-{i}",
            )
        if "posterior" in cv.layers:
            y -= dy
            ax.text(
                0.03,
                y,
                posterior_line(fr, i),
                ha="left",
                va="center",
                fontsize=SMALL,
                color=col,
                gid=f"readout-posterior-{i}",
            )
    if shown < fr.n:
        y -= dy
        ax.text(
            0.0,
            y,
            more_text(fr.n - shown, "more features (not listed)"),
            ha="left",
            va="center",
            fontsize=SMALL,
            color=GREY,
            gid="readout-more",
        )
