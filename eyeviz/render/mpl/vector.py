"""Scene -> a matplotlib figure for papers: true vectors, drawn from the scene model.

Everything comes from :class:`eyeviz.model.scene.Scene`
and its :class:`eyeviz.model.state.SceneState`
(never from VTK), so SVG and PDF hold one path per ommatidium (Figure 2), feature disc and
the BFV wedge (Definition 2), with text kept as text. Styled like the app (white ground,
beige BFV, grey unlit ommatidia lit in the feature's colour, a magnified inset of the
eyes when they are tiny next to the view), sized for a printed column (3.5 in wide,
7 pt text). Only the scene's layers are drawn:

- ``eyes``: the 2 x m ommatidium triangles; runs of unlit (or same-coloured lit)
  ommatidia are merged into one path when a triangle is below a device pixel;
- ``bfv``: the wedge between the tangents from the origin, with psi and theta (Eq. 15-16);
- ``features``: the discs; ``labels``: names, eyes A/B, origin O, ommatidium numbers;
- ``tangents``: the tangent rays from each eye centre and arcsin(g/r_E) (Prop. 2, Fig. 3b);
- ``sectors``: the ommatidium boundaries around each lit interval (Eq. 8, 11);
- ``bitmaps``: Omega_A and Omega_B as two strips with the lit [L, R] (Section 4);
- ``readout``: r, phi, r_A, phi_A, r_B, phi_B, BFV and visibility per feature;
- ``predictions``: each estimator's (r_hat, phi_hat) as a ghost joined to the truth;
- ``ambiguity``: the centres giving the same bitmaps (:mod:`eyeviz.core.ambiguity`);
- ``trajectory``: the Figure 14 path.

matplotlib is imported when this module is; callers that must stay light import it late.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Circle, Polygon, Rectangle, Wedge

from eyeviz import EyevizError
from eyeviz.model.scene import Scene
from eyeviz.model.state import SceneState, compute_state

__all__ = ["BASE_DPI", "VECTOR_DPI", "RC", "figure", "eye_runs", "estimator_colors"]

BASE_DPI = 300.0  # PNG pixels per inch at scale 1
VECTOR_DPI = 600.0  # the print resolution vector output is judged at (merging runs)
WIDTH_IN = 3.5  # one printed column
FONT = 7.0
SMALL = 6.0

WHITE = "#FFFFFF"
INK = "#262626"
GREY = "#7A7A7A"
LIGHT = "#B8B8B8"
UNLIT = "#E1E1E1"
EDGE = "#8A8A8A"
INSET_BG = "#F6F6F3"
BFV_FILL = "#EDE8CC"
BFV_LINE = "#736B4D"
OUT_OF_DOMAIN = "#A6A6A6"
# Okabe-Ito colours for estimators, in an order that differs from the features' default
ESTIMATOR_COLORS = ("#CC79A7", "#56B4E9", "#E69F00", "#009E73", "#0072B2", "#D55E00", "#000000")

RC = {
    "svg.fonttype": "none",
    "pdf.fonttype": 42,
    "ps.fonttype": 42,
    "font.size": FONT,
    "font.family": "DejaVu Sans",
    "mathtext.fontset": "dejavusans",
    "mathtext.default": "regular",
    "axes.linewidth": 0.5,
    "axes.edgecolor": GREY,
    "axes.labelcolor": INK,
    "axes.labelsize": FONT,
    "xtick.color": GREY,
    "ytick.color": GREY,
    "xtick.labelcolor": INK,
    "ytick.labelcolor": INK,
    "xtick.labelsize": SMALL,
    "ytick.labelsize": SMALL,
    "xtick.major.width": 0.5,
    "ytick.major.width": 0.5,
    "xtick.major.size": 2.0,
    "ytick.major.size": 2.0,
    "xtick.major.pad": 1.5,
    "ytick.major.pad": 1.5,
    "lines.solid_capstyle": "round",
    "path.simplify": False,
    "svg.hashsalt": "eyeviz",
    "svg.id": "eyeviz",
}

# a soft white ground behind labels (a path-effect halo would turn SVG text into outlines)
_HALO = {"boxstyle": "round,pad=0.08", "facecolor": "white", "edgecolor": "none", "alpha": 0.75}


def estimator_colors(names) -> dict[str, str]:
    """A distinct Okabe-Ito colour per estimator name, in order."""
    return {n: ESTIMATOR_COLORS[i % len(ESTIMATOR_COLORS)] for i, n in enumerate(names)}


# --- layout ------------------------------------------------------------------------------


@dataclass
class _Box:
    """An axes rectangle in inches from the figure's bottom-left corner."""

    x: float
    y: float
    w: float
    h: float

    def frac(self, fw: float, fh: float) -> tuple[float, float, float, float]:
        return (self.x / fw, self.y / fh, self.w / fw, self.h / fh)


@dataclass
class _Layout:
    width: float
    height: float
    main: _Box
    bitmaps: _Box | None
    readout: _Box | None
    readout_rows: int
    title_y: float | None
    lanes: tuple[int, int] = (2, 2)


_TEXT_ROW = 0.118  # inches per readout row at 6 pt


def _readout_rows(scene: Scene) -> int:
    if "readout" not in scene.layers or not scene.features:
        return 0
    rows = 2 + len(scene.features)
    if "predictions" in scene.layers:
        rows += len(scene.features) * len(scene.estimators)
    if "ambiguity" in scene.layers:
        rows += len(scene.features)
    return rows


_ROW = 7.0 / 72  # one interval-label lane above/below a bitmap strip, inches
_LABEL_PT = SMALL - 0.5


def interval_lanes(L, R, m: int, strip_in: float) -> list[tuple[int, str, float, int]]:
    """Place the [L, R] labels of one strip: (feature index, text, centre, lane) each.

    Labels go over their run; one that would overlap an earlier label moves to the
    next lane out, so none collide.
    """
    idx_per_in = m / strip_in
    placed: list[tuple[int, str, float, int, float]] = []
    for i in sorted(range(len(L)), key=lambda j: int(L[j])):
        lo, hi = int(L[i]), int(R[i])
        text = "whole eye" if hi - lo >= m - 1 else f"[{lo}, {hi % m}]"
        wid = (len(text) * 0.56 * _LABEL_PT / 72 + 0.04) * idx_per_in
        centre = min(max(((lo + hi + 1) / 2) % m, wid / 2), m - wid / 2)
        lane = 0
        while any(abs(centre - c) < (wid + w) / 2 and ln == lane for _, _, c, ln, w in placed):
            lane += 1
        placed.append((i, text, centre, lane, wid))
    return [(i, t, c, ln) for i, t, c, ln, _ in placed]


def _lanes_needed(scene: Scene, state: SceneState | None, strip_in: float) -> tuple[int, int]:
    if state is None or state.LA is None:
        return (1, 1)
    m = state.pair.m
    a = interval_lanes(state.LA, state.RA, m, strip_in)
    b = interval_lanes(state.LB, state.RB, m, strip_in)
    return (1 + max(ln for *_, ln in a), 1 + max(ln for *_, ln in b))


def _layout(scene: Scene, width: float, state: SceneState | None = None) -> _Layout:
    left, right = 0.42, 0.08
    main_w = width - left - right
    lanes = _lanes_needed(scene, state, main_w) if scene.features else (0, 0)
    main_h = round(main_w * 0.86, 3)
    rows = _readout_rows(scene)
    readout_h = rows * _TEXT_ROW + (0.06 if rows else 0.0)
    shows_bitmaps = "bitmaps" in scene.layers and scene.features
    bitmaps_h = sum(lanes) * _ROW + 0.02 + 0.12 * 2 + 0.13 if shows_bitmaps else 0.0
    title_h = 0.2 if scene.title else 0.05
    bottom = 0.06
    y = bottom
    readout = _Box(0.1, y, width - 0.18, readout_h) if rows else None
    y += readout_h
    bitmaps = _Box(left, y, main_w, bitmaps_h) if bitmaps_h else None
    y += bitmaps_h + (0.05 if bitmaps_h else 0.0) + 0.3  # the main axes' x tick labels
    main = _Box(left, y, main_w, main_h)
    y += main_h
    title_y = y + 0.06 if scene.title else None
    # whole hundredths of an inch: the PNG's pixel size then scales exactly with --scale
    height = math.ceil((y + title_h) * 100 - 1e-9) / 100
    return _Layout(width, height, main, bitmaps, readout, rows, title_y, lanes)


# --- eyes --------------------------------------------------------------------------------


def eye_runs(colors: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Maximal runs of equal values: (starts, stops) with stops exclusive."""
    n = len(colors)
    if n == 0:
        return np.zeros(0, np.int64), np.zeros(0, np.int64)
    change = np.flatnonzero(colors[1:] != colors[:-1]) + 1
    starts = np.concatenate([[0], change])
    stops = np.concatenate([change, [n]])
    return starts.astype(np.int64), stops.astype(np.int64)


def _owner_colors(owner: np.ndarray, palette: list[str]) -> np.ndarray:
    """Colour index per ommatidium: 0 unlit, else 1 + index of the colour in ``palette``."""
    uniq = {c: i + 1 for i, c in enumerate(dict.fromkeys(palette))}
    lut = np.array([0] + [uniq[c] for c in palette], dtype=np.int64)
    return lut[owner + 1]


class _Painter:
    """Draws one scene into a figure; each method is one layer."""

    def __init__(
        self,
        scene: Scene,
        state: SceneState,
        dpi: float,
        merge: bool | None,
        predictions: dict | None,
        width: float,
    ):
        self.scene = scene
        self.st = state
        self.pair = state.pair
        self.dpi = dpi
        self.merge = merge
        self.pred_in = predictions
        self.layers = set(scene.layers)
        self.lay = _layout(scene, width, state)
        self.fig = Figure(figsize=(self.lay.width, self.lay.height), dpi=dpi)
        self.fig.patch.set_facecolor(WHITE)
        self.colors = [f.color for f in scene.features]
        self.domain = None
        self.preds: dict[str, tuple[np.ndarray, np.ndarray]] = {}
        self._label_boxes: list[tuple[float, float, float, float]] = []

    # --- axes ------------------------------------------------------------------------
    def axes(self) -> None:
        lay, sc = self.lay, self.scene
        ax = self.fig.add_axes(lay.main.frac(lay.width, lay.height))
        cx, cy = sc.view.center
        w = sc.view.width
        h = w * lay.main.h / lay.main.w
        ax.set_xlim(cx - w / 2, cx + w / 2)
        ax.set_ylim(cy - h / 2, cy + h / 2)
        ax.set_aspect("equal", adjustable="box")
        ax.set_facecolor(WHITE)
        ax.tick_params(length=2.0)
        ax.set_xlabel("x", labelpad=1.0)
        ax.set_ylabel("y", labelpad=1.0)
        for s in ax.spines.values():
            s.set_color(LIGHT)
        ax.set_gid("main")
        self.ax = ax
        self.xlim, self.ylim = (cx - w / 2, cx + w / 2), (cy - h / 2, cy + h / 2)
        self.units_per_in = w / lay.main.w
        if sc.title and lay.title_y is not None:
            self.fig.text(
                0.5,
                lay.title_y / lay.height,
                sc.title,
                ha="center",
                va="bottom",
                fontsize=FONT + 1.0,
                color=INK,
                gid="title",
            )
        self.inset = None
        self.eye_ax = ax
        self.eye_units_per_in = self.units_per_in
        if self.pair.l / self.units_per_in < 0.1 and (
            {"eyes", "tangents", "sectors", "bfv"} & self.layers
        ):
            self._make_inset()

    def _make_inset(self) -> None:
        p = self.pair
        pad = 0.3 * p.l
        x0, x1 = -(p.h + p.l) - pad, p.h + p.l + pad
        y0 = -p.l - (2.6 if "labels" in self.layers else 1.0) * pad
        y1 = p.l + 2.2 * pad
        box_w = 0.38 * self.lay.main.w
        box_h = box_w * (y1 - y0) / (x1 - x0)
        fw, fh = self.lay.width, self.lay.height
        mx, my = self.lay.main.x, self.lay.main.y
        margin = 0.05
        corners = {
            "lower left": (mx + margin, my + margin),
            "lower right": (mx + self.lay.main.w - margin - box_w, my + margin),
            "upper left": (mx + margin, my + self.lay.main.h - margin - box_h),
            "upper right": (
                mx + self.lay.main.w - margin - box_w,
                my + self.lay.main.h - margin - box_h,
            ),
        }
        best, best_cost = None, math.inf
        for i, (bx, by) in enumerate(corners.values()):
            cost = self._crowding(bx, by, box_w, box_h) + 0.01 * i
            if cost < best_cost:
                best, best_cost = (bx, by), cost
        bx, by = best
        ins = self.fig.add_axes((bx / fw, by / fh, box_w / fw, box_h / fh))
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
        scale = (x1 - x0) / (self.units_per_in * box_w)
        ins.text(
            0.02,
            0.96,
            f"eyes \u00d7{_round_sig(1 / scale)}",
            transform=ins.transAxes,
            ha="left",
            va="top",
            fontsize=SMALL - 0.5,
            color=GREY,
            bbox=_HALO,
            zorder=8,
        )
        # a leader from the inset to the eyes' true place (the origin) in the main view
        ox, oy = self._to_inches(0.0, 0.0)
        cx_, cy_ = bx + box_w / 2, by + box_h / 2
        ex = min(max(ox, bx), bx + box_w)
        ey = by + box_h if oy > by + box_h else (by if oy < by else cy_)
        if bx <= ox <= bx + box_w and by <= oy <= by + box_h:
            ex, ey = cx_, cy_
        if not (bx <= ox <= bx + box_w and by <= oy <= by + box_h):
            self.fig.add_artist(
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
        self.ax.plot([0], [0], marker="s", ms=2.4, mfc="none", mec=GREY, mew=0.6, zorder=6)
        self.inset = ins
        self.eye_ax = ins
        self.eye_units_per_in = (x1 - x0) / box_w

    def _to_inches(self, x: float, y: float) -> tuple[float, float]:
        lay = self.lay
        fx = (x - self.xlim[0]) / (self.xlim[1] - self.xlim[0])
        fy = (y - self.ylim[0]) / (self.ylim[1] - self.ylim[0])
        return lay.main.x + fx * lay.main.w, lay.main.y + fy * lay.main.h

    def _crowding(self, bx, by, bw, bh) -> float:
        """How much of the scene an inset at (bx, by) would cover (features, the origin)."""
        cost = 0.0
        for f in self.scene.features:
            fx, fy = self._to_inches(f.x, f.y)
            rad = f.g / self.units_per_in + 0.12
            dx = max(bx - fx, 0, fx - (bx + bw))
            dy = max(by - fy, 0, fy - (by + bh))
            if math.hypot(dx, dy) < rad:
                cost += 1.0
        ox, oy = self._to_inches(0.0, 0.0)
        if bx - 0.03 <= ox <= bx + bw + 0.03 and by - 0.03 <= oy <= by + bh + 0.03:
            cost += 2.0
        # the BFV wedge: prefer corners outside it (sample the box)
        psi = self.pair.psi
        xs = np.linspace(bx, bx + bw, 5)
        ys = np.linspace(by, by + bh, 4)
        inside = 0
        for xi in xs:
            for yi in ys:
                mx = self.xlim[0] + (xi - self.lay.main.x) * self.units_per_in
                my = self.ylim[0] + (yi - self.lay.main.y) * self.units_per_in
                ang = math.atan2(my, mx)
                inside += psi <= ang <= math.pi - psi
        return cost + 0.5 * inside / (len(xs) * len(ys))

    # --- layers ----------------------------------------------------------------------
    def bfv(self) -> None:
        p = self.pair
        psi = p.psi
        xs = [*self.xlim, *self.xlim]
        ys = [self.ylim[0], self.ylim[0], self.ylim[1], self.ylim[1]]
        far = 1.5 * max(math.hypot(x, y) for x, y in zip(xs, ys, strict=True)) + 10 * p.h
        arc = np.linspace(psi, math.pi - psi, 17)
        pts = [(0.0, 0.0), *zip(far * np.cos(arc), far * np.sin(arc), strict=True)]
        axes = [self.ax] + ([self.inset] if self.inset is not None else [])
        for ax in axes:
            wedge = Polygon(
                pts,
                closed=True,
                facecolor=BFV_FILL,
                edgecolor="none",
                zorder=0,
                alpha=0.75 if ax is self.ax else 0.6,
            )
            wedge.set_gid("bfv-wedge" if ax is self.ax else "bfv-wedge-inset")
            ax.add_patch(wedge)
            for sgn, name in ((1, "right"), (-1, "left")):
                ang = psi if sgn == 1 else math.pi - psi
                ax.plot(
                    [0, far * math.cos(ang)],
                    [0, far * math.sin(ang)],
                    color=BFV_LINE,
                    lw=0.6,
                    zorder=1,
                    gid=f"bfv-{name}",
                )
        # psi and theta (Figures 5-6), on the axes where the origin reads best
        ax = self.ax
        vh = self.ylim[1] - self.ylim[0]
        o_in = self.xlim[0] <= 0 <= self.xlim[1] and self.ylim[0] <= 0 <= self.ylim[1]
        if not o_in:
            return
        rad = 0.2 * vh
        if self.inset is None:
            rad = max(rad, 1.5 * p.h)
        th1, th2 = math.degrees(psi), 180 - math.degrees(psi)
        ax.add_patch(_arc(rad, th1, th2, BFV_LINE, "bfv-theta-arc"))
        upi = self.units_per_in
        self._label_boxes.append((-0.3 * upi, rad * 1.04, 0.3 * upi, rad * 1.04 + 0.12 * upi))
        ax.text(
            0,
            rad * 1.04,
            f"\u03b8 = {math.degrees(p.theta):.0f}\u00b0",
            ha="center",
            va="bottom",
            fontsize=SMALL,
            color=BFV_LINE,
            bbox=_HALO,
            zorder=7,
            gid="bfv-theta-label",
        )
        rpsi = 0.72 * rad
        ax.plot([0, 1.3 * rpsi], [0, 0], color=BFV_LINE, lw=0.4, ls=(0, (1.5, 1.5)), zorder=1)
        ax.add_patch(_arc(rpsi, 0, th1, BFV_LINE, "bfv-psi-arc"))
        mid = math.radians(th1 / 2)
        lx, ly = 1.08 * rpsi * math.cos(mid), 1.08 * rpsi * math.sin(mid)
        self._label_boxes.append((lx, ly - 0.06 * upi, lx + 0.45 * upi, ly + 0.06 * upi))
        ax.text(
            1.08 * rpsi * math.cos(mid),
            1.08 * rpsi * math.sin(mid),
            f"\u03c8 = {math.degrees(psi):.0f}\u00b0",
            ha="left",
            va="center",
            fontsize=SMALL,
            color=BFV_LINE,
            bbox=_HALO,
            zorder=7,
            gid="bfv-psi-label",
        )

    def _merge_eyes(self) -> bool:
        if self.merge is not None:
            return bool(self.merge)
        p = self.pair
        base = 2 * p.l * math.sin(p.gamma / 2) / self.eye_units_per_in  # inches
        return base * self.dpi < 1.0

    def eyes(self) -> None:
        p, st, ax = self.pair, self.st, self.eye_ax
        merge = self._merge_eyes()
        self.merged = merge
        base_in = 2 * p.l * math.sin(p.gamma / 2) / self.eye_units_per_in
        edges = base_in * 72 >= 2.5 and not merge
        palette = self.colors
        gam = p.gamma
        for name, (cx, cy), owner in (
            ("A", p.centers[0], st.owner_a),
            ("B", p.centers[1], st.owner_b),
        ):
            owner = np.full(p.m, -1, np.int64) if owner is None else owner
            cidx = _owner_colors(owner, palette) if palette else np.zeros(p.m, np.int64)
            uniq = list(dict.fromkeys(palette))
            fills = [UNLIT] + uniq
            if merge:
                starts, stops = eye_runs(cidx)
                for s, e in zip(starts.tolist(), stops.tolist(), strict=True):
                    col = fills[cidx[s]]
                    if e - s == p.m:
                        patch = Circle((cx, cy), p.l)
                    else:
                        patch = Wedge((cx, cy), p.l, math.degrees(s * gam), math.degrees(e * gam))
                    patch.set(facecolor=col, edgecolor="none", lw=0, zorder=2)
                    patch.set_gid(
                        f"ommatidia-{name}-{s}-{e - 1}" if e - s > 1 else f"ommatidium-{name}-{s}"
                    )
                    ax.add_patch(patch)
            else:
                k = np.arange(p.m + 1) * gam
                rim = np.column_stack([cx + p.l * np.cos(k), cy + p.l * np.sin(k)])
                for i in range(p.m):
                    tri = Polygon(
                        [(cx, cy), rim[i], rim[i + 1]],
                        closed=True,
                        facecolor=fills[cidx[i]],
                        edgecolor=EDGE if edges else "none",
                        lw=0.3 if edges else 0,
                        joinstyle="round",
                        zorder=2,
                    )
                    tri.set_gid(f"ommatidium-{name}-{i}")
                    ax.add_patch(tri)
            ax.add_patch(
                Circle(
                    (cx, cy),
                    p.l,
                    facecolor="none",
                    edgecolor=INK,
                    lw=0.5,
                    zorder=3,
                    gid=f"eye-{name}-rim",
                )
            )
            ax.plot([cx], [cy], marker="o", ms=1.6, color=INK, zorder=4, mew=0)
        if self.inset is not None:
            for cx, cy in p.centers:
                self.ax.plot([cx], [cy], marker="o", ms=1.2, color=INK, zorder=4, mew=0)

    def _numbers_fit(self) -> bool:
        p = self.pair
        return 1.28 * p.l * p.gamma / self.eye_units_per_in * 72 >= 7.5

    def ommatidium_numbers(self) -> None:
        p, ax = self.pair, self.eye_ax
        arc_in = 1.28 * p.l * p.gamma / self.eye_units_per_in
        if not self._numbers_fit():
            return
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
                    fontsize=SMALL - 1,
                    color=GREY,
                    zorder=4,
                    gid=f"ommatidium-number-{name}-{k}",
                )

    def features(self) -> None:
        ax, st = self.ax, self.st
        grey = self._out_of_domain()
        for i, f in enumerate(self.scene.features):
            col = OUT_OF_DOMAIN if grey[i] else f.color
            disc = Circle(
                (f.x, f.y), f.g, facecolor=_mix(col, 0.45), edgecolor=col, lw=0.8, zorder=8
            )
            disc.set_gid(f"feature-{_slug(f.name)}")
            ax.add_patch(disc)
            minimum = 1.2 * self.units_per_in / 72  # keep a point-sized feature visible
            if f.g < minimum:
                ax.plot([f.x], [f.y], marker="o", ms=2.4, color=col, zorder=8, mew=0)
            if "labels" in self.layers:
                self._feature_label(f, col)
        del st

    def _feature_label(self, f, col) -> None:
        """Name beside the disc, in the free direction among eight (inside the view)."""
        upi = self.units_per_in
        tw = (len(f.name) * 0.56 * FONT / 72 + 0.02) * upi
        th = FONT / 72 * upi
        gap = 0.04 * upi
        best, best_cost = None, math.inf
        for j, deg in enumerate((30, -30, 150, -150, 0, 180, 90, -90)):
            a = math.radians(deg)
            ux, uy = math.cos(a), math.sin(a)
            ax_, ay_ = f.x + (f.g + gap) * ux, f.y + (f.g + gap) * uy
            # the text box anchored on the side facing the disc
            x0 = ax_ - (tw if ux < -0.3 else tw / 2 if abs(ux) <= 0.3 else 0)
            y0 = ay_ - (th if uy < -0.3 else th / 2 if abs(uy) <= 0.3 else 0)
            cost = 0.02 * j
            if x0 < self.xlim[0] or x0 + tw > self.xlim[1]:
                cost += 5
            if y0 < self.ylim[0] or y0 + th > self.ylim[1]:
                cost += 5
            for o in self.scene.features:
                dx = max(x0 - o.x, 0, o.x - (x0 + tw))
                dy = max(y0 - o.y, 0, o.y - (y0 + th))
                if math.hypot(dx, dy) < o.g + 0.3 * gap:
                    cost += 2
            for bx0, by0, bx1, by1 in self._label_boxes:
                if x0 < bx1 and bx0 < x0 + tw and y0 < by1 and by0 < y0 + th:
                    cost += 3
            if cost < best_cost:
                best, best_cost = (x0, y0), cost
        x0, y0 = best
        self._label_boxes.append((x0, y0, x0 + tw, y0 + th))
        self.ax.text(
            x0,
            y0 + th / 2,
            f.name,
            ha="left",
            va="center",
            fontsize=FONT,
            color=_dark(col),
            bbox=_HALO,
            zorder=9,
            gid=f"label-{_slug(f.name)}",
            clip_on=True,
        )

    def labels(self) -> None:
        p, ax = self.pair, self.eye_ax
        numbered = "eyes" in self.layers and self._numbers_fit()
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
                bbox=_HALO,
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
            bbox=_HALO,
        )
        if "eyes" in self.layers:
            self.ommatidium_numbers()

    def tangents(self) -> None:
        st, p = self.st, self.pair
        axes = [self.ax] + ([self.inset] if self.inset is not None else [])
        for i, f in enumerate(self.scene.features):
            for name, (cx, cy), rE, phE in (
                ("A", p.centers[0], st.rA[i], st.phiA[i]),
                ("B", p.centers[1], st.rB[i], st.phiB[i]),
            ):
                if rE <= f.g:
                    continue
                alpha = math.asin(f.g / rE)
                t = math.sqrt(rE * rE - f.g * f.g)
                for ax in axes:
                    thin = ax is self.ax and self.inset is not None
                    for sgn in (-1, 1):
                        a = phE + sgn * alpha
                        ax.plot(
                            [cx, cx + 1.04 * t * math.cos(a)],
                            [cy, cy + 1.04 * t * math.sin(a)],
                            color=_dark(f.color),
                            lw=0.35 if thin else 0.55,
                            alpha=0.8 if thin else 1.0,
                            zorder=7,
                            gid=f"tangent-{name}-{_slug(f.name)}",
                        )
                    if not thin:
                        ax.plot(
                            [cx, f.x],
                            [cy, f.y],
                            color=_dark(f.color),
                            lw=0.4,
                            ls=(0, (3, 2)),
                            zorder=7,
                        )
                # the angle arcsin(g/r_E) (Figure 3b) for the nearer eye, where it reads
                if (name == "A") != (st.rA[i] < st.rB[i]):
                    continue
                eax = self.eye_ax
                upi = self.eye_units_per_in
                rad = min(0.5 * (rE - f.g), 0.6 * upi)
                if alpha * rad / upi * 72 < 4:
                    continue
                eax.add_patch(
                    _arc(
                        rad,
                        math.degrees(phE),
                        math.degrees(phE + alpha),
                        _dark(f.color),
                        f"tangent-angle-{name}-{_slug(f.name)}",
                        center=(cx, cy),
                    )
                )
                mid = phE + alpha / 2
                lx, ly = cx + 1.1 * rad * math.cos(mid), cy + 1.1 * rad * math.sin(mid)
                _subscripted(
                    eax,
                    lx,
                    ly,
                    [
                        ("arcsin(g / r", False),
                        (name, True),
                        (f") = {math.degrees(alpha):.1f}\u00b0", False),
                    ],
                    SMALL,
                    "right" if math.cos(mid) < 0 else "left",
                    _dark(f.color),
                    gid=f"tangent-angle-label-{name}-{_slug(f.name)}",
                    zorder=9,
                    bbox=_HALO,
                )

    def sectors(self) -> None:
        st, p = self.st, self.pair
        axes = [self.ax] + ([self.inset] if self.inset is not None else [])
        for i, f in enumerate(self.scene.features):
            for name, (cx, cy), L, R, rE in (
                ("A", p.centers[0], st.LA[i], st.RA[i], st.rA[i]),
                ("B", p.centers[1], st.LB[i], st.RB[i], st.rB[i]),
            ):
                L, R = int(L), int(R)
                if R - L >= p.m - 1:
                    continue
                reach = rE + 1.6 * f.g
                th1, th2 = math.degrees(L * p.gamma), math.degrees((R + 1) * p.gamma)
                ks = range(L, R + 2) if R - L < 24 else (L, R + 1)
                for ax in axes:
                    fan = Wedge(
                        (cx, cy),
                        reach,
                        th1,
                        th2,
                        facecolor=f.color,
                        alpha=0.06,
                        edgecolor="none",
                        zorder=1,
                    )
                    fan.set_gid(f"sector-fan-{name}-{_slug(f.name)}")
                    ax.add_patch(fan)
                    for k in ks:
                        a = k * p.gamma
                        ax.plot(
                            [cx, cx + reach * math.cos(a)],
                            [cy, cy + reach * math.sin(a)],
                            color=GREY,
                            lw=0.35,
                            ls=(0, (2.5, 1.5)),
                            zorder=1.5,
                            gid=f"sector-{name}-{k % p.m}",
                        )
                self._sector_numbers(name, cx, cy, L, R, f)

    def _sector_numbers(self, name, cx, cy, L, R, f) -> None:
        """Number the lit ommatidia along their sectors when there is room (Figure 3b)."""
        p, ax, upi = self.pair, self.eye_ax, self.eye_units_per_in
        rad = 1.3 * p.l
        if R - L > 12 or rad * p.gamma / upi * 72 < 5.5:
            return
        for k in range(L, R + 1):
            a = (k + 0.5) * p.gamma
            ax.text(
                cx + rad * math.cos(a),
                cy + rad * math.sin(a),
                str(k % p.m),
                ha="center",
                va="center",
                fontsize=SMALL - 0.5,
                color=_dark(f.color),
                zorder=6,
                bbox=_HALO,
                gid=f"sector-number-{name}-{k % p.m}",
            )

    def _out_of_domain(self) -> np.ndarray:
        n = len(self.scene.features)
        if "predictions" not in self.layers or n == 0:
            return np.zeros(n, bool)
        return ~self.st.in_domain()

    def predictions(self) -> None:
        sc, st = self.scene, self.st
        if not sc.features:
            return
        grey = self._out_of_domain()
        if self.pred_in is not None:
            preds = self.pred_in
        else:
            preds = predict_scene(sc, st)
        self.preds = preds
        cols = estimator_colors(sc.estimators)
        handles = []
        for name in sc.estimators:
            if not isinstance(preds.get(name), tuple | list):
                continue
            r_hat, phi_hat = (np.asarray(v, dtype=np.float64) for v in preds[name])
            col = cols[name]
            for i, f in enumerate(sc.features):
                if grey[i] or not (np.isfinite(r_hat[i]) and np.isfinite(phi_hat[i])):
                    continue
                px, py = r_hat[i] * math.cos(phi_hat[i]), r_hat[i] * math.sin(phi_hat[i])
                self.ax.plot(
                    [f.x, px],
                    [f.y, py],
                    color=col,
                    lw=0.7,
                    zorder=9,
                    gid=f"prediction-link-{_slug(name)}-{_slug(f.name)}",
                )
                ghost = Circle(
                    (px, py),
                    f.g,
                    facecolor="none",
                    edgecolor=col,
                    lw=0.9,
                    ls=(0, (2.2, 1.2)),
                    zorder=9,
                )
                ghost.set_gid(f"prediction-{_slug(name)}-{_slug(f.name)}")
                self.ax.add_patch(ghost)
                self.ax.plot([px], [py], marker="x", ms=3, mew=0.7, color=col, zorder=9)
            handles.append(
                Line2D(
                    [],
                    [],
                    color=col,
                    lw=0.9,
                    ls=(0, (2.2, 1.2)),
                    marker="x",
                    ms=3,
                    mew=0.7,
                    label=f"{name} (predicted)",
                )
            )
        if grey.any():
            handles.append(
                Line2D(
                    [],
                    [],
                    color=OUT_OF_DOMAIN,
                    lw=0,
                    marker="o",
                    ms=4,
                    label="outside the networks' domain",
                )
            )
        if handles:
            leg = self.ax.legend(
                handles=handles,
                loc="upper right",
                fontsize=SMALL,
                frameon=True,
                framealpha=0.9,
                edgecolor=LIGHT,
                handlelength=2.2,
                borderpad=0.4,
                labelspacing=0.3,
            )
            leg.set_zorder(12)
            leg.get_frame().set_linewidth(0.4)

    def ambiguity(self) -> None:
        from eyeviz.core.ambiguity import ambiguity_region

        p = self.pair
        w = self.xlim[1] - self.xlim[0]
        box = (self.xlim[0] - w, self.xlim[1] + w, self.ylim[0] - w, self.ylim[1] + w)
        self.regions = {}
        for f in self.scene.features:
            try:
                reg = ambiguity_region(p, f.x, f.y, f.g, box=box)
            except ValueError:
                continue
            self.regions[f.name] = reg
            if len(reg.polygon) < 3:
                continue
            poly = Polygon(
                reg.polygon,
                closed=True,
                facecolor=_mix(f.color, 0.3),
                edgecolor=_dark(f.color),
                lw=0.6,
                hatch="//////",
                zorder=8.5,
                alpha=0.85,
            )
            poly.set_gid(f"ambiguity-{_slug(f.name)}")
            self.ax.add_patch(poly)
            self.ax.plot([f.x], [f.y], marker="+", ms=3.5, mew=0.6, color=INK, zorder=8.7)

    def trajectory(self) -> None:
        t = self.scene.trajectory
        if t is None:
            return
        from eyeviz.model import trajectories as tr

        p = self.pair
        try:
            if t.kind == "horizontal":
                x, y = tr.horizontal(t.distance, t.g, 400, h=p.h, l=p.l)
            elif t.kind == "circular":
                x, y = tr.circular(t.distance, t.g, 400, h=p.h, l=p.l)
            else:
                stop = max(t.distance, self.ylim[1])
                x, y = tr.vertical(t.g, 400, start=t.distance, stop=stop, h=p.h, l=p.l)
        except ValueError:
            return
        self.ax.plot(
            x, y, color=INK, lw=0.7, ls=(0, (4, 2)), zorder=6.5, gid=f"trajectory-{t.kind}"
        )
        self.ax.annotate(
            "",
            xy=(x[-1], y[-1]),
            xytext=(x[-8], y[-8]),
            arrowprops=dict(arrowstyle="-|>", lw=0.7, color=INK, mutation_scale=6),
            zorder=6.5,
        )

    # --- panels ----------------------------------------------------------------------
    def bitmaps(self) -> None:
        box = self.lay.bitmaps
        if box is None:
            return
        p, st = self.pair, self.st
        m, half = p.m, p.m // 2
        ax = self.fig.add_axes(box.frac(self.lay.width, self.lay.height))
        ax.set_gid("bitmaps")
        ax.set_xlim(0, m)
        ax.set_ylim(0, box.h)  # y in inches
        ax.axis("off")
        row = _ROW
        strip = 0.12
        axis_h = 0.13
        yB = self.lay.lanes[1] * row + 0.01
        yA = yB + strip + axis_h
        palette = self.colors
        fills = [None] + list(dict.fromkeys(palette))
        for name, y0, owner, Ls, Rs in (
            ("A", yA, st.owner_a, st.LA, st.RA),
            ("B", yB, st.owner_b, st.LB, st.RB),
        ):
            if owner is None:
                from eyeviz.model.state import owners

                owner = owners(Ls, Rs, m)
            ax.add_patch(
                Rectangle(
                    (0, y0),
                    half,
                    strip,
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
                    strip,
                    facecolor="#F4F4F4",
                    edgecolor="none",
                    zorder=1,
                    gid=f"bitmap-{name}-rear",
                )
            )
            cidx = _owner_colors(owner, palette)
            starts, stops = eye_runs(cidx)
            for s_, e in zip(starts.tolist(), stops.tolist(), strict=True):
                if cidx[s_] == 0:
                    continue
                ax.add_patch(
                    Rectangle(
                        (s_, y0),
                        e - s_,
                        strip,
                        facecolor=fills[cidx[s_]],
                        edgecolor="none",
                        zorder=2,
                        gid=f"bitmap-{name}-lit-{s_}-{e - 1}",
                    )
                )
            ax.add_patch(
                Rectangle((0, y0), m, strip, facecolor="none", edgecolor=GREY, lw=0.4, zorder=3)
            )
            ax.plot(
                [half, half],
                [y0 - 0.012, y0 + strip + 0.012],
                color=INK,
                lw=0.7,
                zorder=4,
                solid_capstyle="butt",
            )
            _subscripted(
                ax,
                -0.015 * m,
                y0 + strip / 2,
                [("\u03a9", False), (name, True)],
                FONT,
                "right",
                INK,
                gid=f"bitmap-{name}-name",
            )
            ax.text(
                0.75 * m,
                y0 + strip / 2,
                "rear half: not a network input",
                ha="center",
                va="center",
                fontsize=SMALL - 1.5,
                color=GREY,
                zorder=3,
            )
            self._interval_labels(ax, name, y0, strip, Ls, Rs, row)
        ymid = yB + strip + axis_h / 2
        for k in (0, m // 4, half, 3 * m // 4, m):
            lab = f"{k}" if k != half else f"m/2 = {half}"
            ax.plot([k, k], [yA - 0.015, yA], color=GREY, lw=0.4)
            ax.plot([k, k], [yB + strip, yB + strip + 0.015], color=GREY, lw=0.4)
            ha = "left" if k == 0 else "right" if k == m else "center"
            ax.text(k, ymid, lab, ha=ha, va="center", fontsize=SMALL - 0.5, color=GREY)

    def _interval_labels(self, ax, name, y0, strip, Ls, Rs, row) -> None:
        above = name == "A"
        for i, text, centre, lane in interval_lanes(Ls, Rs, self.pair.m, self.lay.bitmaps.w):
            f = self.scene.features[i]
            dy = 0.008 + lane * row
            y = y0 + strip + dy if above else y0 - dy
            ax.text(
                centre,
                y,
                text,
                ha="center",
                va="bottom" if above else "top",
                fontsize=_LABEL_PT,
                color=_dark(f.color),
                gid=f"bitmap-interval-{name}-{_slug(f.name)}",
            )

    def readout(self) -> None:
        box = self.lay.readout
        if box is None:
            return
        sc, st = self.scene, self.st
        ax = self.fig.add_axes(box.frac(self.lay.width, self.lay.height))
        ax.set_gid("readout")
        ax.axis("off")
        ax.set_xlim(0, 1)
        ax.set_ylim(0, 1)
        rows = self.lay.readout_rows
        dy = 1.0 / rows
        cols = [
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
        # two header rows: where the polar coordinates are centred, then r and phi
        y = 1 - dy / 2
        for text, x0, x1 in (
            ("about the origin O", 0.215, 0.40),
            ("about eye A", 0.425, 0.61),
            ("about eye B", 0.635, 0.82),
        ):
            ax.text(
                (x0 + x1) / 2, y, text, ha="center", va="center", fontsize=SMALL - 0.5, color=GREY
            )
            ax.plot([x0 + 0.01, x1], [y - 0.42 * dy] * 2, color=LIGHT, lw=0.4)
        y -= dy
        for text, x, ha in cols:
            ax.text(x, y, text, ha=ha, va="center", fontsize=SMALL, color=GREY)
        ax.plot([0, 1], [y - dy / 2, y - dy / 2], color=LIGHT, lw=0.4)
        grey = self._out_of_domain()
        cnames = estimator_colors(sc.estimators)
        for i, f in enumerate(sc.features):
            y -= dy
            col = OUT_OF_DOMAIN if grey[i] else _dark(f.color)
            seen = " ".join(e for e, v in (("A", st.vis_a[i]), ("B", st.vis_b[i])) if v)
            seen = seen or "none"
            vals = [
                _short(f.name, 15),
                f"{st.r[i]:.0f}",
                f"{math.degrees(st.phi[i]):.1f}\u00b0",
                f"{st.rA[i]:.0f}",
                f"{math.degrees(st.phiA[i]):.1f}\u00b0",
                f"{st.rB[i]:.0f}",
                f"{math.degrees(st.phiB[i]):.1f}\u00b0",
                "yes" if st.in_bfv[i] else "no",
                seen,
            ]
            for (_, x, ha), v in zip(cols, vals, strict=True):
                ax.text(
                    x,
                    y,
                    v,
                    ha=ha,
                    va="center",
                    fontsize=SMALL,
                    color=col,
                    gid=f"readout-{_slug(f.name)}" if x == 0 else None,
                )
            if "predictions" in self.layers:
                for name in sc.estimators:
                    y -= dy
                    ax.text(
                        0.03,
                        y,
                        self._prediction_line(i, name, grey[i]),
                        ha="left",
                        va="center",
                        fontsize=SMALL - 0.5,
                        color=OUT_OF_DOMAIN if grey[i] else cnames[name],
                    )
            if "ambiguity" in self.layers:
                y -= dy
                ax.text(
                    0.03,
                    y,
                    self._ambiguity_line(f),
                    ha="left",
                    va="center",
                    fontsize=SMALL - 0.5,
                    color=col,
                )

    def _prediction_line(self, i: int, name: str, outside: bool) -> str:
        if outside:
            return f"{name}: outside the networks' domain (not in the BFV or not seen by both)"
        if name not in self.preds:
            return f"{name}: no prediction"
        if isinstance(self.preds[name], str):
            return f"{name}: {self.preds[name]}"
        r_hat, phi_hat = (float(np.asarray(v)[i]) for v in self.preds[name])
        if not (math.isfinite(r_hat) and math.isfinite(phi_hat)):
            return f"{name}: no answer for these bitmaps"
        r, phi = float(self.st.r[i]), float(self.st.phi[i])
        dr = r_hat - r
        dphi = math.degrees(math.remainder(phi_hat - phi, 2 * math.pi))
        return (
            f"{name}: r\u0302 = {r_hat:.0f} (\u0394r {dr:+.0f}, {100 * dr / r:+.1f} %),  "
            f"\u03c6\u0302 = {math.degrees(phi_hat):.2f}\u00b0 "
            f"(\u0394\u03c6 {dphi:+.2f}\u00b0)"
        )

    def _ambiguity_line(self, f) -> str:
        reg = getattr(self, "regions", {}).get(f.name)
        if reg is None:
            return "same bitmaps: covers an eye centre"
        lo, hi = reg.distance_range()
        a0, a1 = reg.azimuth_range()
        more = "" if reg.bounded else "+ (unbounded)"
        return (
            f"same bitmaps for centres at r \u2208 [{lo:.0f}, {hi:.0f}]{more}, "
            f"\u03c6 \u2208 [{math.degrees(a0):.2f}\u00b0, {math.degrees(a1):.2f}\u00b0]"
        )


def _arc(radius, th1, th2, color, gid, center=(0.0, 0.0)):
    from matplotlib.patches import Arc

    a = Arc(center, 2 * radius, 2 * radius, theta1=th1, theta2=th2, color=color, lw=0.6, zorder=6)
    a.set_gid(gid)
    return a


def _subscripted(ax, x, y, parts, size, ha, color, **kw) -> None:
    """Text with subscripts as plain text objects (no mathtext: every SVG viewer reads it).

    ``parts`` is a list of (text, is_subscript); vertically centred on (x, y) in data units.
    """
    from matplotlib.textpath import TextPath
    from matplotlib.transforms import offset_copy

    sub_size = 0.72 * size
    widths = [
        TextPath((0, 0), t, size=sub_size if sub else size).get_extents().width
        + (0.6 if sub else 0.0)
        for t, sub in parts
    ]
    total = sum(widths)
    start = {"left": 0.0, "center": -total / 2, "right": -total}[ha]
    fig = ax.figure
    gid = kw.pop("gid", None)
    x_pt = start
    for (t, sub), w in zip(parts, widths, strict=True):
        tr = offset_copy(
            ax.transData, fig=fig, x=x_pt, y=-0.3 * size if sub else 0.0, units="points"
        )
        txt = ax.text(
            x,
            y,
            t,
            transform=tr,
            ha="left",
            va="center",
            fontsize=sub_size if sub else size,
            color=color,
            **kw,
        )
        if gid:
            txt.set_gid(f"{gid}-{len(ax.texts)}")
        x_pt += w


def _slug(name: str) -> str:
    out = "".join(c if c.isalnum() or c in "-_" else "-" for c in name.strip())
    return out or "feature"


def _short(s: str, n: int) -> str:
    return s if len(s) <= n else s[: n - 1] + "\u2026"


def _rgb(color: str) -> np.ndarray:
    c = color.lstrip("#")
    return np.array([int(c[i : i + 2], 16) for i in (0, 2, 4)], dtype=np.float64) / 255.0


def _hex(rgb) -> str:
    return "#" + "".join(f"{int(round(min(max(v, 0), 1) * 255)):02X}" for v in rgb)


def _mix(color: str, amount: float) -> str:
    """``color`` blended with white: amount 1 is the colour, 0 white (opaque, print-safe)."""
    return _hex(1 - amount * (1 - _rgb(color)))


def _dark(color: str) -> str:
    """A darker shade of ``color`` for thin lines and text on white (>= 3:1 contrast)."""
    rgb = _rgb(color)
    lum = 0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2]
    return _hex(rgb * 0.72) if lum > 0.35 else color


def _round_sig(v: float) -> str:
    if v >= 10:
        return f"{v:.0f}"
    return f"{v:.1f}"


def predict_scene(
    scene: Scene, state: SceneState
) -> dict[str, tuple[np.ndarray, np.ndarray] | str]:
    """Each of the scene's estimators on the in-domain features' Omega bitmaps (m/2 each).

    Returns name -> (r_hat, phi_hat) per feature (NaN for features outside the networks'
    domain: not in the BFV or not seen by both eyes), or name -> a one-line reason when
    the estimator cannot answer for this scene (made for another m, say). An estimator
    that cannot be loaded at all is an :class:`EyevizError`. Imports
    :mod:`eyeviz.estimators` (and through it torch for the networks) only here.
    """
    from eyeviz.model.predictor import Predictor

    if state.LA is None or state.in_bfv is None:
        state = compute_state(scene, ["bitmaps", "readout"])
    predictor = Predictor()
    for name in scene.estimators:
        est = predictor.estimator(name)
        if isinstance(est, str):
            reason = est.removeprefix("unavailable: ")
            raise EyevizError(f"predictions layer: cannot load estimator {name!r}: {reason}")
    return predictor.predict(scene, state)


def figure(
    scene: Scene,
    state: SceneState | None = None,
    *,
    dpi: float = BASE_DPI,
    merge: bool | None = None,
    predictions: dict | None = None,
    width: float = WIDTH_IN,
) -> Figure:
    """The scene as a matplotlib Figure (no pyplot, no GUI), ``width`` inches wide.

    ``dpi`` is the resolution the figure will be rendered at (decides, with ``merge=None``,
    whether ommatidium triangles are below a pixel and merged into runs; pass
    :data:`VECTOR_DPI` for SVG/PDF). ``predictions`` maps estimator name -> (r_hat,
    phi_hat) arrays per feature; when None and the scene shows predictions, the scene's
    estimators are loaded (:mod:`eyeviz.estimators`, which may import torch).
    """
    import matplotlib

    state = compute_state(scene) if state is None else state
    need = {"eyes": "owner_a", "readout": "r", "tangents": "rA", "sectors": "LA", "bitmaps": "LA"}
    for layer, attr in need.items():
        if layer in scene.layers and getattr(state, attr) is None:
            state = compute_state(scene)
            break
    with matplotlib.rc_context(RC):
        pt = _Painter(scene, state, dpi, merge, predictions, width)
        pt.axes()
        lay = scene.layers
        if "bfv" in lay:
            pt.bfv()
        if "sectors" in lay:
            pt.sectors()
        if "eyes" in lay:
            pt.eyes()
        if "tangents" in lay:
            pt.tangents()
        if "ambiguity" in lay:
            pt.ambiguity()
        if "trajectory" in lay:
            pt.trajectory()
        if "features" in lay:
            pt.features()
        if "predictions" in lay:
            pt.predictions()
        if "labels" in lay:
            pt.labels()
        if "bitmaps" in lay:
            pt.bitmaps()
        if "readout" in lay:
            pt.readout()
        pt.fig._eyeviz_rc = dict(RC)  # savefig must run under the same rc (fonttype)
        pt.fig._eyeviz_merged = getattr(pt, "merged", None)
    return pt.fig
