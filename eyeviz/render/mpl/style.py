"""Sizes, colours, rc parameters and small text helpers shared by the figure's painters."""

from __future__ import annotations

import math
from collections.abc import Iterator
from contextlib import contextmanager
from contextvars import ContextVar
from typing import TYPE_CHECKING, Any

import numpy as np

from eyeviz.model.palette import estimator_colors

if TYPE_CHECKING:
    from matplotlib.typing import RcKeyType

__all__ = ["RC", "FONT", "SMALL", "estimator_colors", "mix", "dark", "slug", "short", "legend"]

BASE_DPI = 300.0  # PNG pixels per inch at scale 1
VECTOR_DPI = 600.0  # the print resolution vector output is judged at (merging runs)
WIDTH_IN = 3.5  # one printed column
WIDTHS = {"single": 3.5, "double": 7.2}
MIN_WIDTH, MAX_WIDTH = 3.0, 10.0
FONT = 7.0
SMALL = 6.0  # the smallest text in any figure (journals ask for >= 6 pt)
NAME_CHARS = 40  # feature names longer than this are shown with an ellipsis

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

RC: dict[RcKeyType, Any] = {
    "svg.fonttype": "none",
    "pdf.fonttype": 42,
    "ps.fonttype": 42,
    "font.size": FONT,
    "font.family": "DejaVu Sans",
    "mathtext.fontset": "dejavusans",
    "mathtext.default": "regular",
    "text.usetex": False,
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
HALO = {"boxstyle": "round,pad=0.08", "facecolor": "white", "edgecolor": "none", "alpha": 0.75}


def slug(name: str) -> str:
    out = "".join(c if c.isalnum() or c in "-_" else "-" for c in name.strip()[:NAME_CHARS])
    return out or "feature"


def short(s: str, n: int = NAME_CHARS) -> str:
    """``s`` cut to ``n`` characters with an ellipsis (a 10^6-character name stays drawable)."""
    s = s.replace("\n", " ").replace("\r", " ").replace("\x00", "")
    return s if len(s) <= n else s[: n - 1] + "\u2026"


def _rgb(color: str) -> np.ndarray:
    c = color.lstrip("#")
    return np.array([int(c[i : i + 2], 16) for i in (0, 2, 4)], dtype=np.float64) / 255.0


def _hex(rgb) -> str:
    return "#" + "".join(f"{int(round(min(max(v, 0), 1) * 255)):02X}" for v in rgb)


def mix(color: str, amount: float) -> str:
    """``color`` blended with white: amount 1 is the colour, 0 white (opaque, print-safe)."""
    return _hex(1 - amount * (1 - _rgb(color)))


def dark(color: str) -> str:
    """A darker shade of ``color`` for thin lines and text on white (>= 3:1 contrast)."""
    rgb = _rgb(color)
    lum = 0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2]
    return _hex(rgb * 0.72) if lum > 0.35 else color


def round_sig(v: float) -> str:
    return f"{v:.0f}" if v >= 10 else f"{v:.1f}"


def distance(v: float) -> str:
    """A distance in at most 7 characters, so table columns never run together."""
    if not np.isfinite(v):
        return "\u2013"
    if abs(v) < 999_999.5:
        return f"{v:.0f}"
    mant, exp = f"{v:.2e}".split("e")
    return f"{mant}e{int(exp)}"


def arc(radius, th1, th2, color, gid, center=(0.0, 0.0)):
    from matplotlib.patches import Arc

    a = Arc(center, 2 * radius, 2 * radius, theta1=th1, theta2=th2, color=color, lw=0.6, zorder=6)
    a.set_gid(gid)
    return a


#: The smallest text a figure being drawn may have (``snapshot --min-font``); 0 keeps the
#: style's sizes. Set for one figure with :func:`min_font`, read through :func:`pt`.
_MIN_FONT: ContextVar[float] = ContextVar("eyeviz_min_font", default=0.0)
MIN_FONT_RANGE = (SMALL, 12.0)


def check_min_font(points) -> float:
    """``points`` as a float in :data:`MIN_FONT_RANGE`; EyevizError (one line) otherwise."""
    from eyeviz import EyevizError

    lo, hi = MIN_FONT_RANGE
    try:
        v = float(points)
    except (TypeError, ValueError):
        v = math.nan
    if not lo <= v <= hi:
        raise EyevizError(f"min-font must be between {lo:g} and {hi:g} points, got {points!r}")
    return v


def pt(size: float) -> float:
    """A font size raised to the minimum of the figure being drawn."""
    return max(size, _MIN_FONT.get())


@contextmanager
def min_font(points: float) -> Iterator[None]:
    """Draw with no text smaller than ``points`` (0: the style's sizes)."""
    token = _MIN_FONT.set(float(points))
    try:
        yield
    finally:
        _MIN_FONT.reset(token)


def raise_fonts(fig, points: float) -> None:
    """Every text of ``fig`` (tick labels included) at least ``points`` tall."""
    from matplotlib.text import Text

    if points <= 0:
        return
    for t in fig.findobj(Text):
        if t.get_fontsize() < points:
            t.set_fontsize(points)
    for ax in fig.axes:
        for axis, which in ((ax.xaxis, "x"), (ax.yaxis, "y")):
            ticks = axis.get_major_ticks()
            if ticks and ticks[0].label1.get_fontsize() < points:
                ax.tick_params(axis=which, labelsize=points)


def subscripted(ax, x, y, parts, size, ha, color, **kw) -> None:
    """Text with subscripts as plain text objects (no mathtext: every SVG viewer reads it).

    ``parts`` is a list of (text, is_subscript); vertically centred on (x, y) in data units.
    Subscripts are drawn at 0.86 of ``size`` but never below :data:`SMALL`.
    """
    from matplotlib.textpath import TextPath
    from matplotlib.transforms import offset_copy

    size = pt(size)
    sub_size = pt(max(0.86 * size, SMALL))
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
            parse_math=False,
            **kw,
        )
        if gid:
            txt.set_gid(f"{gid}-{len(ax.texts)}")
        x_pt += w


def legend(ax, handles, labels=None):
    """The figure's one legend style: upper right, small text, a thin light frame."""
    kw = {} if labels is None else {"labels": labels}
    leg = ax.legend(
        handles=handles,
        **kw,
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
    return leg
