"""Where the figure's parts go, in inches: title, main view, bitmap strips, readout table.

Pure arithmetic (no matplotlib): the height follows the width, the number of table rows
and the interval-label lanes of the bitmap strips, so nothing is clipped at any width.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from eyeviz.render.mpl.style import SMALL

__all__ = ["ASPECT", "ASPECT_RANGE", "Box", "Layout", "interval_lanes", "layout"]

ASPECT = 0.86  # main view height / width (a scene's own figure)
ASPECT_RANGE = (0.3, 1.6)  # what a window's framing may ask for (eyeviz.render.mpl.vector)
TEXT_ROW = 0.118  # inches per readout row at 6 pt
LANE = 7.0 / 72  # one interval-label lane above/below a bitmap strip, inches
LABEL_PT = SMALL


@dataclass
class Box:
    """An axes rectangle in inches from the figure's bottom-left corner."""

    x: float
    y: float
    w: float
    h: float

    def frac(self, fw: float, fh: float) -> tuple[float, float, float, float]:
        return (self.x / fw, self.y / fh, self.w / fw, self.h / fh)


@dataclass
class Layout:
    width: float
    height: float
    main: Box
    bitmaps: Box | None
    readout: Box | None
    readout_rows: int
    title_y: float | None
    lanes: tuple[int, int] = (2, 2)


def readout_rows(layers, n_features: int, n_estimators: int) -> int:
    if "readout" not in layers or not n_features:
        return 0
    rows = 2 + n_features
    if "predictions" in layers:
        rows += n_features * n_estimators
    if "ambiguity" in layers:
        rows += n_features
    if "posterior" in layers:
        rows += n_features
    return rows


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
        wid = (len(text) * 0.6 * LABEL_PT / 72 + 0.04) * idx_per_in
        centre = min(max(((lo + hi + 1) / 2) % m, wid / 2), m - wid / 2)
        lane = 0
        while any(abs(centre - c) < (wid + w) / 2 and ln == lane for _, _, c, ln, w in placed):
            lane += 1
        placed.append((i, text, centre, lane, wid))
    return [(i, t, c, ln) for i, t, c, ln, _ in placed]


def tick_format(lo: float, hi: float) -> str:
    """The printf format of the tick labels between lo and hi: whole numbers for a view at
    least 10 wide; else %g near the origin; else as many decimals as tell ticks about a
    tenth of the view apart (a view 1e-6 wide at x = 2056 read "2056.84" on every tick)."""
    span = hi - lo
    if span >= 10:
        return "%.0f"
    big = max(abs(lo), abs(hi))
    if not span > 0 or big <= 1000 * span:
        return "%g"
    decimals = min(15, max(1, math.ceil(-math.log10(span / 10)) + 1))
    return f"%.{decimals}f"


def tick_chars(lo: float, hi: float) -> int:
    """Characters of the longest plain tick label between lo and hi."""
    fmt = tick_format(lo, hi)
    if fmt == "%g":
        big = max(abs(lo), abs(hi), 1.0)
        return len(f"{big:.0f}") + (1 if lo < 0 else 0)
    return max(len(fmt % v) for v in (lo, hi, max(abs(lo), abs(hi), 1.0)))


def layout(
    width: float,
    *,
    layers,
    title: bool,
    n_features: int,
    n_estimators: int,
    intervals=None,
    m: int = 0,
    ylim: tuple[float, float] = (0.0, 1.0),
    xlim: tuple[float, float] = (0.0, 1.0),
    aspect: float = ASPECT,
) -> Layout:
    """The figure's boxes for a ``width``-inch figure whose main view is ``aspect`` (height
    / width) as tall as it is wide."""
    left = max(0.42, tick_chars(*ylim) * 0.6 * SMALL / 72 + 0.2)
    right = max(0.1, tick_chars(*xlim) * 0.6 * SMALL / 72 / 2 + 0.03)  # half a tick label
    main_w = width - left - right
    shows_bitmaps = "bitmaps" in layers and n_features and intervals is not None
    lanes = (0, 0)
    if shows_bitmaps:
        (LA, RA), (LB, RB) = intervals
        a = interval_lanes(LA, RA, m, main_w)
        b = interval_lanes(LB, RB, m, main_w)
        lanes = (1 + max(ln for *_, ln in a), 1 + max(ln for *_, ln in b))
    main_h = round(main_w * aspect, 3)
    rows = readout_rows(layers, n_features, n_estimators)
    readout_h = rows * TEXT_ROW + (0.06 if rows else 0.0)
    bitmaps_h = sum(lanes) * LANE + 0.02 + 0.12 * 2 + 0.15 if shows_bitmaps else 0.0
    title_h = 0.22 if title else 0.06
    y = 0.06
    readout = Box(0.1, y, width - 0.2, readout_h) if rows else None
    y += readout_h
    bitmaps = Box(left, y, main_w, bitmaps_h) if bitmaps_h else None
    y += bitmaps_h + (0.05 if bitmaps_h else 0.0) + 0.3  # the main axes' x tick labels
    main = Box(left, y, main_w, main_h)
    y += main_h
    title_y = y + 0.06 if title else None
    # whole hundredths of an inch: the PNG's pixel size then scales exactly with --scale
    height = math.ceil((y + title_h) * 100 - 1e-9) / 100
    return Layout(width, height, main, bitmaps, readout, rows, title_y, lanes)
