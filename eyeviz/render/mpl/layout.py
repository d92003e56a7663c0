"""Where the figure's parts go, in inches: title, main view, bitmap strips, readout table.

Pure arithmetic (no matplotlib): the height follows the width, the number of table rows
and the interval-label lanes of the bitmap strips, so nothing is clipped at any width. Both
are capped (:data:`MAX_TABLE_ROWS`, :data:`MAX_LANES`; what does not fit is counted in one
"... and N more" line), so a figure's size never grows with the number of features: a
10^4-feature scene is as tall as a 50-feature one, and placing its labels is
O(n log n) (sort, then greedy lanes over a bounded number of lanes).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from eyeviz.render.mpl.style import SMALL, WIDTHS

__all__ = [
    "ASPECT",
    "ASPECT_RANGE",
    "ASPECTS",
    "Box",
    "Lanes",
    "Layout",
    "MAX_FIGURE_ASPECT",
    "MAX_LABELS",
    "MAX_LANES",
    "MAX_TABLE_ROWS",
    "MAX_TAUGHT",
    "default_aspect",
    "interval_lanes",
    "layout",
    "more_text",
    "table_features",
]

ASPECT = 0.86  # main view height / width of a single-column figure (a scene's own figure)
#: The default main-view aspect per journal width: a single column keeps 0.86; a double
#: column is 0.5 (at 0.86 a 7.2 in figure's view alone was 5.8 in tall, nearly a page);
#: widths between are interpolated linearly, wider ones keep 0.5 (docs/conventions.md).
ASPECTS = {"single": ASPECT, "double": 0.5}
ASPECT_RANGE = (0.3, 1.6)  # what a window's framing may ask for (eyeviz.render.mpl.vector)
TEXT_ROW = 0.118  # inches per readout row at 6 pt
LANE = 7.0 / 72  # one interval-label lane above/below a bitmap strip, inches
LABEL_PT = SMALL
#: At most this many label lanes above (below) a bitmap strip; labels that fit in none
#: are counted in one more lane ("... and N more").
MAX_LANES = 6
#: At most this many rows in the readout table, headers and the "... and N more" row
#: included; features whose rows do not fit are counted, not listed.
MAX_TABLE_ROWS = 24
#: A figure is at most this many times as tall as it is wide: a journal page's text block
#: (7.1 x 9.7 in, 6.5 x 9 in) or an A4 sheet (1.41). A 2,000-feature snapshot was 2.23
#: (issue 35): the lanes and table rows a figure lists shrink until it fits, the rest
#: counted in their "... and N more" lines.
MAX_FIGURE_ASPECT = 1.4
#: The fewest lanes per strip and table rows the figure keeps, even past that aspect.
MIN_LANES = 1
MIN_TABLE_ROWS = 4
#: A scene of up to this many features keeps its whole table, even past that aspect: it
#: lists every feature (a taller figure rather than "... and 1 more" under four rows).
MIN_TABLE_FEATURES = 8
#: At most this many feature names beside their discs in the main view.
MAX_LABELS = 40
#: At most this many features drawn with the teaching layers' lines (tangents, sectors).
MAX_TAUGHT = 40


def default_aspect(width: float) -> float:
    """The main view's height / width for a ``width``-inch figure when none is asked for:
    :data:`ASPECTS` at the journal widths, linear between, constant beyond."""
    w0, w1 = WIDTHS["single"], WIDTHS["double"]
    a0, a1 = ASPECTS["single"], ASPECTS["double"]
    t = min(max((float(width) - w0) / (w1 - w0), 0.0), 1.0)
    return round(a0 + t * (a1 - a0), 3)


def more_text(n: int, what: str = "more") -> str:
    """The line that stands for ``n`` items left out: "\u2026 and 12 more"."""
    return f"\u2026 and {n:,} {what}"


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
    table_features: int = 0  # features listed in the readout table (the rest are counted)
    min_font: float = 0.0  # no text smaller than this, points (0: the style's sizes)
    max_lanes: int = MAX_LANES  # label lanes per bitmap strip (fewer in a crowded figure)

    def pt(self, size: float) -> float:
        """A font size raised to the figure's minimum."""
        return max(size, self.min_font)

    @property
    def font_scale(self) -> float:
        """How much wider the smallest text is than the style's 6 pt (1 unless raised)."""
        return max(1.0, self.min_font / SMALL)


def _rows_per_feature(layers, n_estimators: int) -> int:
    rows = 1
    if "predictions" in layers:
        rows += n_estimators
    if "ambiguity" in layers:
        rows += 1
    if "posterior" in layers:
        rows += 1
    return rows


def table_features(
    layers, n_features: int, n_estimators: int, max_rows: int = MAX_TABLE_ROWS
) -> int:
    """How many features the readout table lists: all of them while the table fits in
    ``max_rows`` rows, else as many as fit beside a "... and N more" row (at least one)."""
    if "readout" not in layers or not n_features:
        return 0
    per = _rows_per_feature(layers, n_estimators)
    if 2 + n_features * per <= max_rows:
        return n_features
    return max(1, (max_rows - 3) // per)


def readout_rows(layers, n_features: int, n_estimators: int, max_rows: int = MAX_TABLE_ROWS) -> int:
    """Rows of the readout table: two header rows, each listed feature's rows and one
    "... and N more" row when some are left out; at most ``max_rows`` (more only when one
    feature's rows alone exceed it)."""
    shown = table_features(layers, n_features, n_estimators, max_rows)
    if not shown:
        return 0
    return 2 + shown * _rows_per_feature(layers, n_estimators) + (shown < n_features)


@dataclass
class Lanes:
    """The labels of one bitmap strip: ``placed`` (feature index, text, centre, lane) each,
    ``dropped`` labels that fit in none of the lanes."""

    placed: list[tuple[int, str, float, int]] = field(default_factory=list)
    dropped: int = 0
    used: int = 0  # lanes holding a label

    @property
    def height(self) -> int:
        """Lanes the strip needs: the used ones and one for "... and N more"."""
        return self.used + (1 if self.dropped else 0)

    def __iter__(self):
        return iter(self.placed)


def label_width(text: str, pt: float) -> float:
    """A generous width of ``text`` at ``pt`` points, inches (0.6 em per character)."""
    return len(text) * 0.6 * pt / 72 + 0.04


def interval_lanes(
    L, R, m: int, strip_in: float, *, max_lanes: int = MAX_LANES, pt: float = LABEL_PT
) -> Lanes:
    """Place the [L, R] labels of one strip over their runs, in at most ``max_lanes``
    lanes, none overlapping another in its lane.

    Interval partitioning: the labels sorted by their left edge, each goes to the first
    lane whose last label ends at or before that edge (a lane's labels never overlap: the
    one placed last ends furthest right). Unbounded, this uses the fewest lanes any
    placement can (the most labels over one point); bounded, a label that fits in none is
    counted in :attr:`Lanes.dropped`. O(n log n + n * max_lanes), where the previous
    all-pairs scan per lane was cubic (78 s for 1000 labels).
    """
    n = len(L)
    out = Lanes()
    if not n:
        return out
    lo = np.asarray(L, dtype=np.int64)
    hi = np.asarray(R, dtype=np.int64)
    whole = hi - lo >= m - 1
    texts = [
        "whole eye" if w else f"[{a}, {b % m}]"
        for a, b, w in zip(lo.tolist(), hi.tolist(), whole.tolist(), strict=True)
    ]
    idx_per_in = m / strip_in
    wid = np.array([label_width(t, pt) for t in texts]) * idx_per_in
    centre = np.minimum(np.maximum(((lo + hi + 1) / 2) % m, wid / 2), m - wid / 2)
    left = centre - wid / 2
    ends: list[float] = []  # right edge of each lane's last label
    for i in np.lexsort((np.arange(n), left)).tolist():
        a, b = float(left[i]), float(left[i] + wid[i])
        for k, end in enumerate(ends):
            if a >= end:
                ends[k] = b
                out.placed.append((i, texts[i], float(centre[i]), k))
                break
        else:
            if len(ends) < max_lanes:
                out.placed.append((i, texts[i], float(centre[i]), len(ends)))
                ends.append(b)
            else:
                out.dropped += 1
    out.used = len(ends)
    return out


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
    min_font: float = 0.0,
) -> Layout:
    """The figure's boxes for a ``width``-inch figure whose main view is ``aspect`` (height
    / width) as tall as it is wide. ``min_font`` (points, 0 for the style's sizes) raises
    the smallest text: rows, lanes and margins grow with it."""
    k = max(1.0, min_font / SMALL)  # how much wider and taller the smallest text is
    left = max(0.42, tick_chars(*ylim) * 0.6 * SMALL * k / 72 + 0.2)
    right = max(0.1, tick_chars(*xlim) * 0.6 * SMALL * k / 72 / 2 + 0.03)  # half a tick
    main_w = width - left - right
    shows_bitmaps = "bitmaps" in layers and n_features and intervals is not None
    main_h = round(main_w * aspect, 3)
    title_h = 0.22 * k if title else 0.06
    fixed = (
        0.06 + 0.3 * k + main_h + title_h + (0.05 + 0.02 + 0.24 + 0.15 * k) * bool(shows_bitmaps)
    )
    # the most lanes and table rows that keep the figure within MAX_FIGURE_ASPECT: the
    # lanes give way first (down to MIN_LANES), then the table's rows (to MIN_TABLE_ROWS)
    caps = [(c, MAX_TABLE_ROWS) for c in range(MAX_LANES, MIN_LANES - 1, -1)]
    floor = MIN_TABLE_ROWS
    if n_features <= MIN_TABLE_FEATURES:
        floor = max(floor, readout_rows(layers, n_features, n_estimators))
    caps += [(MIN_LANES, r) for r in range(MAX_TABLE_ROWS - 1, floor - 1, -1)]
    for max_lanes, max_rows in caps:
        lanes = (0, 0)
        if shows_bitmaps:
            (LA, RA), (LB, RB) = intervals
            pt = max(LABEL_PT, min_font)
            a = interval_lanes(LA, RA, m, main_w, pt=pt, max_lanes=max_lanes)
            b = interval_lanes(LB, RB, m, main_w, pt=pt, max_lanes=max_lanes)
            lanes = (max(1, a.height), max(1, b.height))
        rows = readout_rows(layers, n_features, n_estimators, max_rows)
        readout_h = rows * TEXT_ROW * k + (0.06 if rows else 0.0)
        if fixed + readout_h + sum(lanes) * LANE * k <= MAX_FIGURE_ASPECT * width:
            break
    shown = table_features(layers, n_features, n_estimators, max_rows)
    bitmaps_h = sum(lanes) * LANE * k + 0.02 + 0.12 * 2 + 0.15 * k if shows_bitmaps else 0.0
    y = 0.06
    readout = Box(0.1, y, width - 0.2, readout_h) if rows else None
    y += readout_h
    bitmaps = Box(left, y, main_w, bitmaps_h) if bitmaps_h else None
    y += bitmaps_h + (0.05 if bitmaps_h else 0.0) + 0.3 * k  # the main axes' x tick labels
    main = Box(left, y, main_w, main_h)
    y += main_h
    title_y = y + 0.06 if title else None
    # whole hundredths of an inch: the PNG's pixel size then scales exactly with --scale
    height = math.ceil((y + title_h) * 100 - 1e-9) / 100
    return Layout(
        width,
        height,
        main,
        bitmaps,
        readout,
        rows,
        title_y,
        lanes,
        shown,
        float(min_font),
        max_lanes,
    )
