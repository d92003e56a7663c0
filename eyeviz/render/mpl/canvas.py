"""The figure, its main axes and the magnified inset of the eyes: what painters draw on."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from matplotlib.axes import Axes
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.ticker import FormatStrFormatter, MaxNLocator

from eyeviz.model.frame import Frame
from eyeviz.model.scene import Scene
from eyeviz.render.mpl.layout import Layout, tick_chars, tick_format
from eyeviz.render.mpl.style import (
    FONT,
    GREY,
    HALO,
    INK,
    INSET_BG,
    LIGHT,
    SMALL,
    WHITE,
    pt,
    round_sig,
    short,
)

__all__ = ["Canvas", "make_canvas"]

Box = tuple[float, float, float, float]  # (x0, y0, x1, y1)


@dataclass
class Canvas:
    """A Frame being drawn: the figure, its axes and the scales between them."""

    scene: Scene
    frame: Frame
    lay: Layout
    fig: Figure
    dpi: float
    merge: bool | None
    ax: Axes = field(init=False)  # set by make_canvas
    inset: Axes | None = None
    eye_ax: Axes = field(init=False)  # the inset if there is one, else ax
    xlim: tuple[float, float] = (0.0, 1.0)
    ylim: tuple[float, float] = (0.0, 1.0)
    units_per_in: float = 1.0
    eye_units_per_in: float = 1.0
    label_boxes: list[tuple[float, float, float, float]] = field(default_factory=list)
    merged: bool | None = None
    notes: list[str] = field(default_factory=list)  # "... and N more ..." lines (draw_notes)

    @property
    def layers(self) -> set[str]:
        return self.frame.layers

    @property
    def pair(self):
        return self.frame.pair

    def eye_axes(self) -> list[Axes]:
        return [self.ax] + ([self.inset] if self.inset is not None else [])

    def to_inches(self, x: float, y: float) -> tuple[float, float]:
        lay = self.lay
        fx = (x - self.xlim[0]) / (self.xlim[1] - self.xlim[0])
        fy = (y - self.ylim[0]) / (self.ylim[1] - self.ylim[0])
        return lay.main.x + fx * lay.main.w, lay.main.y + fy * lay.main.h

    def origin_in_view(self) -> bool:
        return self.xlim[0] <= 0 <= self.xlim[1] and self.ylim[0] <= 0 <= self.ylim[1]

    def box_inches(self, x0: float, y0: float, x1: float, y1: float) -> Box:
        """A box in data units of the main view, in figure inches."""
        return (*self.to_inches(x0, y0), *self.to_inches(x1, y1))

    def under_inset(self, x0: float, y0: float, x1: float, y1: float) -> bool:
        """Whether the box (data units of the main view) meets the inset of the eyes."""
        if self.inset is None:
            return False
        b = self.inset.get_position()
        w, h = self.lay.width, self.lay.height
        return boxes_meet(self.box_inches(x0, y0, x1, y1), (b.x0 * w, b.y0 * h, b.x1 * w, b.y1 * h))


def make_canvas(scene: Scene, frame: Frame, lay: Layout, dpi: float, merge, title: bool):
    fig = Figure(figsize=(lay.width, lay.height), dpi=dpi)
    fig.patch.set_facecolor(WHITE)
    cv = Canvas(scene, frame, lay, fig, dpi, merge)
    ax = fig.add_axes(lay.main.frac(lay.width, lay.height))
    x0, x1, y0, y1 = frame.rect
    ax.set_xlim(x0, x1)
    ax.set_ylim(y0, y1)
    ax.set_aspect("equal", adjustable="box")
    ax.set_facecolor(WHITE)
    ax.tick_params(length=2.0)
    # plain tick labels (no offset text to cut off), few enough not to run together
    chars = tick_chars(x0, x1)
    nbins = max(2, int(lay.main.w / (chars * 0.6 * SMALL / 72 + 0.2)))
    ax.xaxis.set_major_locator(MaxNLocator(nbins=min(nbins, 8)))
    ax.yaxis.set_major_locator(MaxNLocator(nbins=min(nbins, 8)))
    for axis in (ax.xaxis, ax.yaxis):
        lo, hi = (x0, x1) if axis is ax.xaxis else (y0, y1)
        axis.set_major_formatter(FormatStrFormatter(tick_format(lo, hi)))
    ax.set_xlabel("x", labelpad=1.0)
    ax.set_ylabel("y", labelpad=1.0)
    for s in ax.spines.values():
        s.set_color(LIGHT)
    ax.set_gid("main")
    cv.ax, cv.eye_ax = ax, ax
    cv.xlim, cv.ylim = (x0, x1), (y0, y1)
    cv.units_per_in = cv.eye_units_per_in = (x1 - x0) / lay.main.w
    if title and scene.title and lay.title_y is not None:
        fig.text(
            0.5,
            lay.title_y / lay.height,
            fit_text(scene.title, FONT + 1.0, lay.width * 72 - 8),
            ha="center",
            va="bottom",
            fontsize=FONT + 1.0,
            color=INK,
            gid="title",
            parse_math=False,
        )
    p = frame.pair
    if p.l / cv.units_per_in < 0.1 and ({"eyes", "tangents", "sectors", "bfv"} & cv.layers):
        _make_inset(cv)
    return cv


def draw_notes(cv: Canvas) -> None:
    """The notes of what was left out ("... and 960 more unlabelled"), one per line, in a
    top corner of the main view the inset leaves free."""
    if not cv.notes:
        return
    right = True
    if cv.inset is not None:
        b = cv.inset.get_position()
        main = cv.lay.main
        right = b.x0 + b.width / 2 < (main.x + main.w / 2) / cv.lay.width
    cv.ax.text(
        0.99 if right else 0.01,
        0.99,
        "\n".join(cv.notes),
        transform=cv.ax.transAxes,
        ha="right" if right else "left",
        va="top",
        fontsize=SMALL,
        color=INK,
        bbox=HALO,
        zorder=10,
        gid="label-more",
        parse_math=False,
    )


def fit_text(text: str, size: float, width_pt: float) -> str:
    """``text`` cut (with an ellipsis) to the longest prefix that is ``width_pt`` wide."""
    from matplotlib.backends.backend_agg import RendererAgg
    from matplotlib.font_manager import FontProperties

    renderer = RendererAgg(10, 10, 72.0)  # 72 dpi: widths in points
    prop = FontProperties(family="DejaVu Sans", size=pt(size))  # as drawn (--min-font)

    def width(t: str) -> float:
        return renderer.get_text_width_height_descent(t, prop, ismath=False)[0]

    text = short(text, 400)
    if width(text) <= width_pt:
        return text
    lo, hi = 1, len(text)
    while lo < hi:
        mid = (lo + hi + 1) // 2
        if width(short(text, mid)) <= width_pt:
            lo = mid
        else:
            hi = mid - 1
    return short(text, lo)


#: The BFV's angle labels (Figures 5-6), width and height in inches: theta's, psi's.
THETA_LABEL_IN = (0.55, 0.12)
PSI_LABEL_IN = (0.45, 0.12)


def boxes_meet(a: Box, b: Box) -> bool:
    """Whether two boxes (x0, y0, x1, y1) overlap (edges that only touch do not)."""
    return a[0] < b[2] and b[0] < a[2] and a[1] < b[3] and b[1] < a[3]


def psi_label_at(cv: Canvas, rpsi: float, side: float) -> tuple[float, float]:
    """Where psi's label starts (data units): beside its arc of radius ``rpsi``, halfway up
    the angle, at the right tangent (side 1) or mirrored at the left one (side -1)."""
    half = cv.pair.psi / 2
    return side * 1.08 * rpsi * math.cos(half), 1.08 * rpsi * math.sin(half)


def angle_radii(cv: Canvas, inset: bool) -> tuple[float, float]:
    """(theta's arc radius, psi's arc radius) in data units: a fifth of the view's height,
    at least 1.5 h where no inset shows the eyes."""
    rad = 0.2 * (cv.ylim[1] - cv.ylim[0])
    if not inset:
        rad = max(rad, 1.5 * cv.pair.h)
    return rad, 0.72 * rad


def _angle_labels_area(cv: Canvas) -> tuple[float, float, float, float] | None:
    """The box (data units) holding theta's label and psi's on either side, None where
    they are not drawn (no bfv layer, or the origin out of the view)."""
    if "bfv" not in cv.layers or not cv.origin_in_view():
        return None
    rad, rpsi = angle_radii(cv, True)
    upi = cv.units_per_in
    half = max(psi_label_at(cv, rpsi, 1.0)[0] + PSI_LABEL_IN[0] * upi, THETA_LABEL_IN[0] * upi / 2)
    return (-half, 0.0, half, 1.04 * rad + THETA_LABEL_IN[1] * upi)


def _crowding(cv: Canvas, bx, by, bw, bh) -> float:
    """How much of the scene an inset at (bx, by) would cover (features, the origin, BFV)."""
    fr = cv.frame
    cost = 0.0
    for x, y, g in zip(fr.x.tolist(), fr.y.tolist(), fr.g.tolist(), strict=True):
        fx, fy = cv.to_inches(x, y)
        rad = g / cv.units_per_in + 0.12
        dx = max(bx - fx, 0, fx - (bx + bw))
        dy = max(by - fy, 0, fy - (by + bh))
        if math.hypot(dx, dy) < rad:
            cost += 1.0
    ox, oy = cv.to_inches(0.0, 0.0)
    if bx - 0.03 <= ox <= bx + bw + 0.03 and by - 0.03 <= oy <= by + bh + 0.03:
        cost += 2.0
    psi = fr.pair.psi
    inside = 0
    for i in range(5):
        for j in range(4):
            xi, yi = bx + bw * i / 4, by + bh * j / 3
            mx = cv.xlim[0] + (xi - cv.lay.main.x) * cv.units_per_in
            my = cv.ylim[0] + (yi - cv.lay.main.y) * cv.units_per_in
            inside += psi <= math.atan2(my, mx) <= math.pi - psi
    area = _angle_labels_area(cv)
    # theta and psi: they can move aside, a feature cannot (half a disc)
    if area is not None and boxes_meet(cv.box_inches(*area), (bx, by, bx + bw, by + bh)):
        cost += 0.5
    return cost + 0.5 * inside / 20


def _make_inset(cv: Canvas) -> None:
    p = cv.pair
    pad = 0.3 * p.l
    x0, x1 = -(p.h + p.l) - pad, p.h + p.l + pad
    y0 = -p.l - (2.6 if "labels" in cv.layers else 1.0) * pad
    y1 = p.l + 2.2 * pad
    main = cv.lay.main
    box_w = min(0.38 * main.w, 1.6)
    box_h = box_w * (y1 - y0) / (x1 - x0)
    fw, fh = cv.lay.width, cv.lay.height
    margin = 0.05
    corners = [
        (main.x + margin, main.y + margin),
        (main.x + main.w - margin - box_w, main.y + margin),
        (main.x + margin, main.y + main.h - margin - box_h),
        (main.x + main.w - margin - box_w, main.y + main.h - margin - box_h),
    ]
    costs = [_crowding(cv, bx, by, box_w, box_h) + 0.01 * i for i, (bx, by) in enumerate(corners)]
    bx, by = corners[costs.index(min(costs))]
    ins = cv.fig.add_axes((bx / fw, by / fh, box_w / fw, box_h / fh))
    ins.set_xlim(x0, x1)
    ins.set_ylim(y0, y1)
    ins.set_aspect("equal", adjustable="box")
    ins.set_facecolor(INSET_BG)
    ins.set_xticks([])
    ins.set_yticks([])
    for s in ins.spines.values():
        s.set_color(GREY)
        s.set_linewidth(0.6)
    ins.set_zorder(5)
    ins.set_gid("inset")
    scale = (x1 - x0) / (cv.units_per_in * box_w)
    ins.text(
        0.02,
        0.96,
        f"eyes \u00d7{round_sig(1 / scale)}",
        transform=ins.transAxes,
        ha="left",
        va="top",
        fontsize=SMALL,
        color=GREY,
        bbox=HALO,
        zorder=8,
    )
    # a leader from the inset to the eyes' true place, drawn only when the origin is in
    # the view, so it never leaves the axes
    ox, oy = cv.to_inches(0.0, 0.0)
    in_box = bx <= ox <= bx + box_w and by <= oy <= by + box_h
    if cv.origin_in_view() and not in_box:
        ex = min(max(ox, bx), bx + box_w)
        ey = by + box_h if oy > by + box_h else (by if oy < by else by + box_h / 2)
        cv.fig.add_artist(
            Line2D(
                [ex / fw, ox / fw],
                [ey / fh, oy / fh],
                color=GREY,
                lw=0.5,
                ls=(0, (2, 1.5)),
                zorder=4,
                gid="inset-leader",
            )
        )
    cv.ax.plot([0], [0], marker="s", ms=2.4, mfc="none", mec=GREY, mew=0.6, zorder=6)
    cv.inset = cv.eye_ax = ins
    cv.eye_units_per_in = (x1 - x0) / box_w
