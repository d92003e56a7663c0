"""``bfv``: the wedge between the tangents from the origin (Definition 2), psi and theta."""

from __future__ import annotations

import math

from matplotlib.patches import Polygon

from eyeviz.model.frame import clip_wedge
from eyeviz.render.mpl.canvas import (
    PSI_LABEL_IN,
    THETA_LABEL_IN,
    Box,
    Canvas,
    angle_radii,
    psi_label_at,
)
from eyeviz.render.mpl.style import BFV_FILL, BFV_LINE, HALO, SMALL, arc


def paint(cv: Canvas) -> None:
    b = cv.frame.bfv
    if b is None:
        return
    for ax in cv.eye_axes():
        if ax is cv.ax:
            poly, edges = b.polygon, b.edges
        else:  # the inset shows the wedge clipped to its own limits
            rect = (*ax.get_xlim(), *ax.get_ylim())
            poly = clip_wedge(b.psi, rect)
            edges = [None, None]
            for j, ang in enumerate((b.psi, math.pi - b.psi)):
                far = 4 * math.hypot(max(map(abs, rect[:2])), max(map(abs, rect[2:])))
                edges[j] = (0.0, 0.0, far * math.cos(ang), far * math.sin(ang))
        if len(poly) >= 3:
            wedge = Polygon(
                poly,
                closed=True,
                facecolor=BFV_FILL,
                edgecolor="none",
                zorder=0,
                alpha=0.75 if ax is cv.ax else 0.6,
            )
            wedge.set_gid("bfv-wedge" if ax is cv.ax else "bfv-wedge-inset")
            ax.add_patch(wedge)
        for e, name in zip(edges, ("right", "left"), strict=True):
            if e is None:
                continue
            ax.plot([e[0], e[2]], [e[1], e[3]], color=BFV_LINE, lw=0.6, zorder=1, gid=f"bfv-{name}")
    _angles(cv)


def _free(cv: Canvas, x0, y0, x1, y1) -> bool:
    """True when the box (data units) touches no feature disc and is not under the inset."""
    if cv.under_inset(x0, y0, x1, y1):
        return False
    fr = cv.frame
    for x, y, g in zip(fr.x.tolist(), fr.y.tolist(), fr.g.tolist(), strict=True):
        dx = max(x0 - x, 0, x - x1)
        dy = max(y0 - y, 0, y - y1)
        if math.hypot(dx, dy) < g:
            return False
    return True


def _angles(cv: Canvas) -> None:
    """psi and theta (Figures 5-6), where the origin is in the view; theta's label goes to
    the first radius along the bisector where it covers no feature and is not under the
    inset, psi's to the right tangent or, mirrored, the left one by the same rule."""
    b, ax, upi = cv.frame.bfv, cv.ax, cv.units_per_in
    assert b is not None  # paint() returned before when the frame has no BFV
    if not cv.origin_in_view():
        return
    rad, rpsi = angle_radii(cv, cv.inset is not None)
    th1, th2 = math.degrees(b.psi), 180 - math.degrees(b.psi)
    ax.add_patch(arc(rad, th1, th2, BFV_LINE, "bfv-theta-arc"))
    tw, th = THETA_LABEL_IN[0] * upi, THETA_LABEL_IN[1] * upi
    # the first radius where the label covers no feature and is not under the inset; where
    # every one covers a feature, the first not under the inset (over a disc, the haloed
    # label still reads; under the inset it would be hidden)
    fs = (1.04, 0.7, 1.4, 0.45, 1.8)
    boxes = [(-tw / 2, rad * f, tw / 2, rad * f + th) for f in fs]
    ok = [bx for bx in boxes if _free(cv, *bx)]
    ok = ok or [bx for bx in boxes if not cv.under_inset(*bx)]
    ly = (ok or boxes)[0][1]
    cv.label_boxes.append((-tw / 2, ly, tw / 2, ly + th))
    ax.text(
        0,
        ly,
        f"\u03b8 = {math.degrees(b.theta):.0f}\u00b0",
        ha="center",
        va="bottom",
        fontsize=SMALL,
        color=BFV_LINE,
        bbox=HALO,
        zorder=9,  # over a disc where no free place is left (haloed: still read)
        gid="bfv-theta-label",
    )
    # psi between the x-axis and the right tangent, or (the same angle, mirrored) between
    # the left tangent and the negative x-axis when the inset or a feature covers the right
    lw, lh = PSI_LABEL_IN[0] * upi, PSI_LABEL_IN[1] / 2 * upi

    def psi_box(sgn: float) -> Box:
        lx, ly = psi_label_at(cv, rpsi, sgn)
        return (lx, ly - lh, lx + lw, ly + lh) if sgn > 0 else (lx - lw, ly - lh, lx, ly + lh)

    def in_view(b: Box) -> bool:
        return cv.xlim[0] <= b[0] and b[2] <= cv.xlim[1]

    sides = [s for s in (1.0, -1.0) if in_view(psi_box(s))] or [1.0]
    free = [s for s in sides if _free(cv, *psi_box(s))]
    side = (free or [s for s in sides if not cv.under_inset(*psi_box(s))] or sides)[0]
    lx, ly = psi_label_at(cv, rpsi, side)
    ax.plot([0, side * 1.3 * rpsi], [0, 0], color=BFV_LINE, lw=0.4, ls=(0, (1.5, 1.5)), zorder=1)
    a0, a1 = (0.0, th1) if side > 0 else (th2, 180.0)
    ax.add_patch(arc(rpsi, a0, a1, BFV_LINE, "bfv-psi-arc"))
    cv.label_boxes.append(psi_box(side))
    ax.text(
        lx,
        ly,
        f"\u03c8 = {math.degrees(b.psi):.0f}\u00b0",
        ha="left" if side > 0 else "right",
        va="center",
        fontsize=SMALL,
        color=BFV_LINE,
        bbox=HALO,
        zorder=9,  # over a disc where no free place is left (haloed: still read)
        gid="bfv-psi-label",
    )
