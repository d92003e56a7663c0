"""``eyeviz report study STUDY.csv -o DIR``: figures of the eye-design study (issue 11).

The study table (``eyeviz study``, read by :mod:`eyeviz.reports.study_table`) holds the
information limit's AD and DD error (MAPE, Eq. 34) per eye design (h, l, m; Table 3) and
distance bin. The paper's open question (Section 8) is how accuracy depends on h, l and
m. This report draws, in PDF, SVG and PNG (house style of :mod:`eyeviz.render.mpl.style`,
Okabe-Ito colours, text >= 7 pt at print size):

``study_dd``  DD limit (MAPE %) against distance, one panel per h, one curve per m;
``study_ad``  the same for AD;
``study_heatmap``  DD MAPE in the distance bin holding ``--at`` over (h, m), values in
    the cells;
``study_law``  the law relative DD error = C * gamma * r / (2h) (gamma = 2 pi / m, Prop. 1):
    every measured bin against gamma r / (2h) on log-log axes with the fitted C.

For each h the panels and the heatmap use the paper's l (``--l``, default 20) when the
table has it, else the l nearest to it (stated in the label). The paper's design
(h = 40, l = 20, m = 720) is marked in every figure. ``summary.json`` holds the fitted
constant and its spread, ``summary.csv`` the table behind the heatmap, ``study.md`` the
answer to "which m and h give a DD error below --target % at --at".

The fit of C: least squares in log space with the slope fixed at 1, i.e.
log C = mean(log y - log x), over bins with at least :data:`MIN_COUNT` test elements,
x = gamma r_mid / (2h) <= ``--law-max`` (beyond it the error saturates: the prior's range
bounds it) and not the first or last bin of a design (there the prior's bounds r_min,
r_max truncate the posterior and lower the error). Its spread is the standard deviation
of the log residuals (a factor exp(sd)); a free log-log slope is reported beside it.
"""

from __future__ import annotations

import argparse
import csv
import io
import json
import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from eyeviz import EyevizError
from eyeviz.files.atomic import atomic_output
from eyeviz.reports.study_table import Row, read_study

HELP = "figures of the eye-design study: the limit against h, l, m and distance"

PAPER = (40.0, 20.0, 720)  # the paper's eyes (Table 3)
MIN_COUNT = 30  # fewest test elements in a bin for it to be drawn / fitted
LAW_MAX = 0.25  # default upper end of gamma r / (2h) for the fit
FORMATS = ("pdf", "svg", "png")
PNG_DPI = 300
PT = 7.0  # every text in these figures, ticks included
OKABE_ITO = ("#E69F00", "#56B4E9", "#009E73", "#0072B2", "#D55E00", "#CC79A7", "#000000")
DASHES = ("-", "--", ":", "-.")
TWO_COLUMNS, ONE_COLUMN = 7.2, 3.5  # inches
CAPTIONS = {
    "study_dd": "DD limit (MAPE %) against distance, a panel per h, a curve per m",
    "study_ad": "AD limit (MAPE %) against distance, a panel per h, a curve per m",
    "study_heatmap": "DD limit at --at over (h, m), values in the cells",
    "study_law": "relative DD error against gamma r / (2h) with the fitted C",
}


# --- analysis ---------------------------------------------------------------------------


@dataclass
class Design:
    """One design point's rows: the overall row and its bins (sorted by distance)."""

    h: float
    l: float  # noqa: E741
    m: int
    all: Row
    bins: list[Row]

    @property
    def key(self) -> tuple[float, float, int]:
        return (self.h, self.l, self.m)

    @property
    def is_paper(self) -> bool:
        return self.key == PAPER


def designs_of(rows: Sequence[Row], prior: str) -> dict[tuple[float, float, int], Design]:
    """Rows of ``prior`` grouped per design; of several runs (n, seed) the largest n."""
    mine = [r for r in rows if r.prior == prior]
    if not mine:
        have = sorted({r.prior for r in rows})
        raise EyevizError(f"the study table has no rows of prior {prior!r} (it has {have})")
    runs: dict[tuple, list[Row]] = {}
    for r in mine:
        runs.setdefault(r.run, []).append(r)
    best: dict[tuple[float, float, int], list[Row]] = {}
    for run_rows in runs.values():
        d = run_rows[0].design
        if d not in best or run_rows[0].n > best[d][0].n:
            best[d] = run_rows
    out = {}
    for d, rr in best.items():
        alls = [r for r in rr if r.bin == "all"]
        bins = sorted((r for r in rr if r.bin != "all"), key=lambda r: r.r_lo)
        if not alls:
            raise EyevizError(
                f"line {rr[0].line}: design h={d[0]:g} l={d[1]:g} m={d[2]} has "
                "no overall row (bin all)"
            )
        if not bins:
            raise EyevizError(
                f"line {alls[0].line}: design h={d[0]:g} l={d[1]:g} m={d[2]} has no distance bins"
            )
        out[d] = Design(d[0], d[1], d[2], alls[0], bins)
    return dict(sorted(out.items()))


def l_per_h(designs: dict, l_wanted: float) -> dict[float, float]:
    """For each h, ``l_wanted`` if the table has it, else the l nearest to it (larger on ties)."""
    out = {}
    for h in sorted({k[0] for k in designs}):
        ls = sorted({k[1] for k in designs if k[0] == h})
        out[h] = l_wanted if l_wanted in ls else min(ls, key=lambda v: (abs(v - l_wanted), -v))
    return out


def bin_at(d: Design, at: float) -> Row | None:
    """The bin holding distance ``at`` ([r_lo, r_hi), the last bin closed)."""
    for i, b in enumerate(d.bins):
        if b.r_lo <= at < b.r_hi or (i == len(d.bins) - 1 and at == b.r_hi):
            return b
    return None


def heatmap_table(designs: dict, l_of: dict[float, float], at: float) -> list[dict]:
    """Rows (h, l, m, bin, DD and AD MAPE) behind the heatmap: one per (h, m)."""
    out = []
    for (h, l_, m), d in designs.items():
        if l_of[h] != l_:
            continue
        b = bin_at(d, at)
        if b is None:
            continue
        out.append(
            {
                "h": h,
                "l": l_,
                "m": m,
                "gamma": d.all.gamma,
                "at": at,
                "r_lo": b.r_lo,
                "r_hi": b.r_hi,
                "count": b.count,
                "dd_mape": b.dd_mape,
                "ad_mape": b.ad_mape,
                "paper_design": d.is_paper,
            }
        )
    if not out:
        lo = min(d.all.r_min for d in designs.values())
        hi = max(d.all.r_max for d in designs.values())
        raise EyevizError(f"--at {at:g} lies outside the study's distances [{lo:g}, {hi:g}]")
    return out


@dataclass
class LawPoint:
    h: float
    l: float  # noqa: E741
    m: int
    r: float
    x: float  # gamma r / (2h)
    y: float  # relative DD error (MAPE / 100)
    fitted: bool
    paper: bool


@dataclass
class LawFit:
    """relative DD error = C * gamma r / (2h), C fitted in log space with slope 1."""

    C: float | None
    log_sd: float | None  # standard deviation of log(y / (C x)) over the fitted points
    n: int
    slope: float | None  # free least-squares slope of log y on log x (for comparison)
    C_free: float | None  # exp(intercept) of that free fit
    x_max: float
    method: str = (
        "least squares in log space with the slope fixed at 1: log C = mean(log y - log x)"
    )

    @property
    def factor(self) -> float | None:
        return None if self.log_sd is None else math.exp(self.log_sd)


def law_points(designs: dict, x_max: float = LAW_MAX) -> list[LawPoint]:
    out = []
    for d in designs.values():
        n = len(d.bins)
        for i, b in enumerate(d.bins):
            if b.count < MIN_COUNT or not (b.dd_mape > 0):
                continue
            x = d.all.gamma * b.r_mid / (2 * d.h)
            interior = n < 3 or 0 < i < n - 1
            out.append(
                LawPoint(
                    d.h,
                    d.l,
                    d.m,
                    b.r_mid,
                    x,
                    b.dd_mape / 100.0,
                    interior and x <= x_max,
                    d.is_paper,
                )
            )
    return out


def fit_law(points: Sequence[LawPoint], x_max: float = LAW_MAX) -> LawFit:
    """C of relative DD error = C gamma r / (2h) (see the module docstring for the method)."""
    use = [p for p in points if p.fitted]
    if len(use) < 2:
        return LawFit(None, None, len(use), None, None, x_max)
    lx = np.log([p.x for p in use])
    ly = np.log([p.y for p in use])
    res = ly - lx
    log_c = float(res.mean())
    sd = float(res.std(ddof=1))
    slope = c_free = None
    if np.ptp(lx) > 0:
        s, i = np.polyfit(lx, ly, 1)
        slope, c_free = float(s), float(math.exp(i))
    return LawFit(math.exp(log_c), sd, len(use), slope, c_free, x_max)


def smallest_m(designs: dict, l_of: dict, at: float, target: float) -> dict[float, int | None]:
    """For each h (at its l): the fewest ommatidia whose DD MAPE at ``at`` is <= target %."""
    out: dict[float, int | None] = {}
    for h, l_ in l_of.items():
        ok = [
            m
            for (hh, ll, m), d in designs.items()
            if hh == h and ll == l_ and (b := bin_at(d, at)) is not None and b.dd_mape <= target
        ]
        out[h] = min(ok) if ok else None
    return out


# --- figures ----------------------------------------------------------------------------


def _rc() -> dict:
    from eyeviz.render.mpl.style import RC

    return {
        **RC,
        "font.size": PT,
        "axes.labelsize": PT,
        "xtick.labelsize": PT,
        "ytick.labelsize": PT,
        "legend.fontsize": PT,
        "axes.titlesize": PT,
    }


def _m_style(ms: Sequence[int]) -> dict[int, dict]:
    return {
        m: {"color": OKABE_ITO[i % len(OKABE_ITO)], "ls": DASHES[(i // len(OKABE_ITO)) % 4]}
        for i, m in enumerate(sorted(ms))
    }


def _log_helps(values) -> bool:
    v = np.asarray([x for x in values if np.isfinite(x) and x > 0])
    return v.size > 1 and v.max() / v.min() > 5


def _fmt_axis(ax, log: bool) -> None:
    from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter

    if log:
        ax.set_yscale("log")
        ax.yaxis.set_major_locator(LogLocator(base=10, subs=(1.0, 2.0, 5.0)))
        ax.yaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
        ax.yaxis.set_minor_formatter(NullFormatter())
    ax.grid(True, which="major", color="#E6E6E6", lw=0.5)
    ax.set_axisbelow(True)


def _paper_label() -> str:
    h, l_, m = PAPER
    return f"paper's eyes (h {h:g}, l {l_:g}, m {m})"


def curves_figure(designs: dict, l_of: dict, target: str, wanted: float = PAPER[1]):
    """DD or AD limit against distance: a panel per h (its l), a curve per m."""
    from matplotlib.figure import Figure
    from matplotlib.lines import Line2D

    hs = sorted(l_of)
    ms = sorted({k[2] for k in designs})
    style = _m_style(ms)
    col = f"{target}_mape"
    vals = [getattr(b, col) for d in designs.values() for b in d.bins if b.count >= MIN_COUNT]
    log = _log_helps(vals)
    ncols = min(len(hs), 3)
    spare = (-len(hs)) % ncols
    nrows = math.ceil(len(hs) / ncols)
    width = TWO_COLUMNS if ncols > 1 else ONE_COLUMN  # one h: one column of a paper
    fig = Figure(
        figsize=(width, 0.4 + 1.75 * nrows + (0.6 if ncols == 1 else 0)), layout="constrained"
    )
    axes = fig.subplots(nrows, ncols, sharex=True, sharey=True, squeeze=False).ravel()
    paper_drawn = False
    for ax, h in zip(axes, hs, strict=False):
        l_ = l_of[h]
        for m in ms:
            d = designs.get((h, l_, m))
            if d is None:
                continue
            bins = [b for b in d.bins if b.count >= MIN_COUNT]
            r = [b.r_mid for b in bins]
            v = [getattr(b, col) for b in bins]
            if d.is_paper:
                ax.plot(r, v, color="black", lw=3.2, ls="-", zorder=2, solid_capstyle="round")
                paper_drawn = True
            ax.plot(r, v, lw=1.4, marker="o", ms=2.4, zorder=3, **style[m], label=f"m = {m}")
        note = "" if l_ == wanted else f"  (no l {wanted:g} at this h)"
        ax.set_title(f"h = {h:g}, l = {l_:g}{note}", loc="left", pad=2)
        _fmt_axis(ax, log)
    for ax in axes[len(hs) :]:
        ax.set_axis_off()
    name = "distance" if target == "dd" else "azimuth"
    for i, ax in enumerate(axes[: len(hs)]):
        if i % ncols == 0:
            ax.set_ylabel(f"{target.upper()} limit: MAPE (%)")
        if i >= len(hs) - ncols:
            ax.set_xlabel("distance r")
            ax.tick_params(labelbottom=True)
    handles = [Line2D([], [], lw=1.4, marker="o", ms=2.4, **style[m]) for m in ms]
    labels = [f"m = {m}  (γ = {360 / m:.3g}°)" for m in ms]
    if paper_drawn:
        handles.append(Line2D([], [], color="black", lw=3.2))
        labels.append(_paper_label() + ": black underlay")
    title = f"{name} limit (the best\nany estimator can do)"
    if spare:
        axes[-1].legend(
            handles, labels, loc="center left", frameon=False, title=title, alignment="left"
        )
    else:
        fig.legend(
            handles, labels, loc="outside lower center", ncol=3 if ncols > 1 else 1, frameon=False
        )
    return fig


def _cell(v: float) -> str:
    """Three significant digits, trailing zeros kept (18.0, 2.50, 0.864)."""
    s = f"{v:#.3g}"
    return s[:-1] if s.endswith(".") else s


def heatmap_figure(table: list[dict], l_of: dict, at: float, wanted: float = PAPER[1]):
    """DD MAPE at ``at`` over (h, m); values in the cells; the paper's design boxed."""
    from matplotlib.colors import LogNorm, Normalize
    from matplotlib.figure import Figure
    from matplotlib.patches import Rectangle

    hs = sorted({t["h"] for t in table})
    ms = sorted({t["m"] for t in table})
    grid = np.full((len(hs), len(ms)), np.nan)
    for t in table:
        grid[hs.index(t["h"]), ms.index(t["m"])] = t["dd_mape"]
    finite = grid[np.isfinite(grid) & (grid > 0)]
    fig = Figure(figsize=(ONE_COLUMN, max(2.4, 0.9 + 0.42 * len(hs))), layout="constrained")
    ax = fig.add_subplot()
    norm = (
        LogNorm(finite.min(), finite.max())
        if finite.size > 1 and finite.max() / finite.min() > 3
        else Normalize(*(finite.min(), finite.max()) if finite.size else (0, 1))
    )
    im = ax.imshow(grid, origin="lower", cmap="cividis", norm=norm, aspect="auto")
    cmap = im.get_cmap()
    for i in range(len(hs)):
        for j in range(len(ms)):
            v = grid[i, j]
            if not np.isfinite(v):
                ax.text(j, i, "–", ha="center", va="center", color="#7A7A7A")
                continue
            rgb = cmap(norm(v))[:3] if finite.size else (1, 1, 1)
            lum = 0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2]
            ax.text(
                j, i, _cell(v), ha="center", va="center", color="black" if lum > 0.45 else "white"
            )
    paper = [t for t in table if t["paper_design"]]
    for t in paper:
        i, j = hs.index(t["h"]), ms.index(t["m"])
        ax.add_patch(Rectangle((j - 0.5, i - 0.5), 1, 1, fill=False, ec="black", lw=1.8))
        ax.add_patch(Rectangle((j - 0.44, i - 0.44), 0.88, 0.88, fill=False, ec="white", lw=0.7))
    ax.set_xticks(range(len(ms)), [str(m) for m in ms])
    ax.set_yticks(
        range(len(hs)), [f"{h:g}" + ("" if l_of[h] == wanted else f" (l {l_of[h]:g})") for h in hs]
    )
    paper = [t for t in table if t["paper_design"]]
    ax.set_xlabel("ommatidia m" + ("\n(boxed: " + _paper_label() + ")" if paper else ""))
    ax.set_ylabel("h (eye centres at x = ±h)")
    ax.tick_params(length=0)
    for s in ax.spines.values():
        s.set_visible(False)
    t0 = table[0]
    ax.set_title(
        f"DD limit: MAPE (%) at r = {at:g} (bin {t0['r_lo']:g}–{t0['r_hi']:g}), l = {wanted:g}",
        loc="left",
        pad=3,
    )
    cb = fig.colorbar(im, ax=ax, shrink=0.9, pad=0.02, aspect=25)
    cb.ax.tick_params(labelsize=PT, length=2)
    cb.outline.set_visible(False)
    from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter

    if isinstance(norm, LogNorm):
        cb.ax.yaxis.set_major_locator(LogLocator(base=10, subs=(1.0, 2.0, 5.0)))
    cb.ax.yaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
    cb.ax.yaxis.set_minor_formatter(NullFormatter())
    return fig


def law_figure(points: Sequence[LawPoint], fit: LawFit):
    """Measured relative DD error per bin against gamma r / (2h), log-log, with C x."""
    from matplotlib.figure import Figure
    from matplotlib.lines import Line2D

    ms = sorted({p.m for p in points})
    style = _m_style(ms)
    fig = Figure(figsize=(ONE_COLUMN, 3.9), layout="constrained")
    ax = fig.add_subplot()
    ax.set_xscale("log")
    ax.set_yscale("log")
    for m in ms:
        sel = [p for p in points if p.m == m]
        on = [p for p in sel if p.fitted]
        off = [p for p in sel if not p.fitted]
        c = style[m]["color"]
        ax.scatter([p.x for p in on], [p.y for p in on], s=7, color=c, lw=0, alpha=0.85, zorder=3)
        ax.scatter(
            [p.x for p in off],
            [p.y for p in off],
            s=7,
            facecolor="none",
            edgecolor=c,
            lw=0.5,
            alpha=0.85,
            zorder=3,
        )
    pp = [p for p in points if p.paper]
    if pp:
        ax.scatter(
            [p.x for p in pp],
            [p.y for p in pp],
            s=22,
            marker="D",
            facecolor="none",
            edgecolor="black",
            lw=0.9,
            zorder=4,
        )
    xs = np.array([p.x for p in points])
    handles = [Line2D([], [], ls="", marker="o", ms=3, color=style[m]["color"]) for m in ms]
    labels = [f"m = {m}" for m in ms]
    ys = np.array([p.y for p in points])
    if ys.size:
        ax.set_ylim(ys.min() / 1.6, ys.max() * 1.6)
    if fit.C is not None and xs.size:
        f = fit.factor or 1.0
        x_fit = max(p.x for p in points if p.fitted)
        xx = np.geomspace(xs.min(), x_fit, 50)
        ax.fill_between(xx, fit.C * xx / f, fit.C * xx * f, color="#D9D9D9", lw=0, zorder=1)
        ax.plot(xx, fit.C * xx, color="black", lw=1.0, zorder=2)
        x_end = min(xs.max(), ys.max() * 1.5 / fit.C)
        if x_end > x_fit:  # the law extrapolated beyond the fitted range: dashed
            xe = np.geomspace(x_fit, x_end, 20)
            ax.plot(xe, fit.C * xe, color="black", lw=0.8, ls=(0, (3, 2)), zorder=2)
        ax.axvline(fit.x_max, color="#7A7A7A", lw=0.6, ls=":", zorder=1)
        handles.append(Line2D([], [], color="black", lw=1.0))
        labels.append(f"C·γr/(2h), C = {fit.C:.3g} (×÷{f:.2f})")
        text = (
            f"least squares in log space, slope 1;\n{fit.n} filled points (x ≤ {fit.x_max:g}),"
            f" band ×÷ 1 s.d.;\na free fit has slope {fit.slope:.2f}"
            if fit.slope is not None
            else ""
        )
        ax.text(0.98, 0.03, text, transform=ax.transAxes, ha="right", va="bottom")
    else:
        ax.text(0.5, 0.5, "too few points to fit C", transform=ax.transAxes, ha="center")
    handles.append(Line2D([], [], ls="", marker="o", ms=3, mfc="none", mec="#7A7A7A", mew=0.5))
    labels.append(f"not fitted (edge bin or x > {fit.x_max:g})")
    if pp:
        handles.append(Line2D([], [], ls="", marker="D", ms=4, mfc="none", mec="black"))
        labels.append(_paper_label())
    fig.legend(
        handles,
        labels,
        loc="outside lower center",
        ncol=2,
        frameon=False,
        handlelength=1.2,
        labelspacing=0.25,
        columnspacing=1.0,
    )
    from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter

    ax.yaxis.set_major_locator(LogLocator(base=10, subs=(1.0, 2.0, 5.0)))
    ax.yaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{100 * v:g} %"))
    ax.yaxis.set_minor_formatter(NullFormatter())
    ax.xaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
    ax.set_xlabel("γ r / (2h)   (γ = 2π/m)")
    ax.set_ylabel("relative DD error of the limit (MAPE)")
    ax.grid(True, which="major", color="#E6E6E6", lw=0.5)
    ax.set_axisbelow(True)
    return fig


def save(fig, outdir: Path, stem: str) -> list[Path]:
    """The figure as PDF, SVG and PNG (300 dpi), each written atomically."""
    paths = []
    for ext in FORMATS:
        path = outdir / f"{stem}.{ext}"
        meta = {"CreationDate": None} if ext == "pdf" else {"Date": None} if ext == "svg" else {}
        with atomic_output(path) as tmp:
            fig.savefig(tmp, format=ext, dpi=PNG_DPI, metadata=meta, facecolor="white")
        paths.append(path)
    return paths


# --- output -----------------------------------------------------------------------------


def _write_text(path: Path, text: str) -> Path:
    with atomic_output(path) as tmp:
        tmp.write_text(text, encoding="utf-8")
    return path


def summary_csv(table: list[dict], fit: LawFit) -> str:
    buf = io.StringIO()
    cols = [*table[0].keys(), "law_dd_mape"]
    w = csv.DictWriter(buf, fieldnames=cols, lineterminator="\n")
    w.writeheader()
    for t in table:
        x = t["gamma"] * 0.5 * (t["r_lo"] + t["r_hi"]) / (2 * t["h"])  # the bin centre
        w.writerow({**t, "law_dd_mape": "" if fit.C is None else round(100 * fit.C * x, 6)})
    return buf.getvalue()


def _clean(v):
    if isinstance(v, float) and not math.isfinite(v):
        return None
    return v


def summary_json(table, fit: LawFit, args_d: dict, designs: dict, best: dict) -> str:
    paper = designs.get(PAPER)
    out = {
        "source": args_d,
        "law": {
            "formula": "relative DD error (MAPE/100) = C * gamma * r / (2h), gamma = 2 pi / m",
            "C": fit.C,
            "method": fit.method,
            "log_sd": fit.log_sd,
            "factor_1sd": fit.factor,
            "points_fitted": fit.n,
            "x_max": fit.x_max,
            "min_count": MIN_COUNT,
            "excluded": "the first and last bin of each design (the prior's bounds truncate "
            "the posterior there) and bins with gamma r / (2h) > x_max (saturation)",
            "free_slope": fit.slope,
            "free_C": fit.C_free,
        },
        "paper_design": None
        if paper is None
        else {
            "h": PAPER[0],
            "l": PAPER[1],
            "m": PAPER[2],
            "dd_mape": paper.all.dd_mape,
            "ad_mape": paper.all.ad_mape,
            "n": paper.all.n,
        },
        "smallest_m_for_target": {f"{h:g}": m for h, m in best.items()},
        "heatmap": [{k: _clean(v) for k, v in t.items()} for t in table],
    }
    return json.dumps(out, indent=1, allow_nan=False) + "\n"


def markdown(table, fit, designs, l_of, best, args_d, figures) -> str:
    at, target = args_d["at"], args_d["target"]
    lines = [
        "# The eye-design study: the information limit against h, l, m and distance",
        "",
        f"Source: `{args_d['table']}`, prior `{args_d['prior']}`, {len(designs)} designs. "
        "MAPE (Eq. 34) of the information limit: no estimator that sees only the two "
        "bitmaps has a lower expected error under the prior.",
        "",
    ]
    paper = designs.get(PAPER)
    if paper is None:
        lines += ["The paper's eyes (h 40, l 20, m 720) are not in this table: no figure marks "
                  "them.", ""]  # fmt: skip
    else:
        lines += [
            f"The paper's eyes (h 40, l 20, m 720): DD {paper.all.dd_mape:.2f} %, "
            f"AD {paper.all.ad_mape:.3f} % over r in [{paper.all.r_min:g}, "
            f"{paper.all.r_max:g}] (n = {paper.all.n}).",
            "",
        ]
    if fit.C is not None:
        lines += [
            f"**The law**: relative DD error = C γ r / (2h) with C = {fit.C:.3g} "
            f"(×÷ {fit.factor:.2f} for one standard deviation, {fit.n} bins; {fit.method}; "
            f"bins with γ r/(2h) <= {fit.x_max:g}, not the first or last bin of a design). "
            f"A free log-log fit gives slope {fit.slope:.2f}.",
            "",
        ]
    lines += [
        f"Fewest ommatidia m for a DD error <= {target:g} % at r = {at:g}:",
        "",
        "| h | l | m |",
        "|---:|---:|---:|",
    ]
    for h, m in best.items():
        lines.append(f"| {h:g} | {l_of[h]:g} | {m if m is not None else 'none in the grid'} |")
    lines += ["", "Figures (each as PDF, SVG and PNG):", ""]
    for f in figures:
        lines += [f"**{f}**: {CAPTIONS.get(f, '')}", "", f"![{f}]({f}.png)", ""]
    return "\n".join(lines) + "\n"


def write_report(
    path: Path,
    outdir: Path,
    at: float = 3000.0,
    prior: str | None = None,
    l_wanted: float = PAPER[1],
    law_max: float = LAW_MAX,
    target: float = 5.0,
) -> list[Path]:
    """Read the study table at ``path`` and write every figure and summary into ``outdir``."""
    for name, v in (("--at", at), ("--l", l_wanted), ("--law-max", law_max), ("--target", target)):
        if not (math.isfinite(v) and v > 0):
            raise EyevizError(f"{name} must be a finite number > 0, got {v!r}")
    rows = read_study(path)
    if prior is None:  # the table's only prior, else the single-pass one
        have = sorted({r.prior for r in rows})
        prior = have[0] if len(have) == 1 else "single"
    designs = designs_of(rows, prior)
    l_of = l_per_h(designs, l_wanted)
    table = heatmap_table(designs, l_of, at)
    points = law_points(designs, law_max)
    fit = fit_law(points, law_max)
    best = smallest_m(designs, l_of, at, target)
    outdir.mkdir(parents=True, exist_ok=True)
    import matplotlib

    written: list[Path] = []
    with matplotlib.rc_context(_rc()):
        for stem, fig in (
            ("study_dd", curves_figure(designs, l_of, "dd", l_wanted)),
            ("study_ad", curves_figure(designs, l_of, "ad", l_wanted)),
            ("study_heatmap", heatmap_figure(table, l_of, at, l_wanted)),
            ("study_law", law_figure(points, fit)),
        ):
            written += save(fig, outdir, stem)
    args_d = {"table": str(path), "prior": prior, "at": at, "l": l_wanted, "target": target}
    written.append(_write_text(outdir / "summary.csv", summary_csv(table, fit)))
    written.append(
        _write_text(outdir / "summary.json", summary_json(table, fit, args_d, designs, best))
    )
    figs = [p.stem for p in written if p.suffix == ".png"]  # in the order drawn
    written.append(
        _write_text(outdir / "study.md", markdown(table, fit, designs, l_of, best, args_d, figs))
    )
    return written


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("table", type=Path, help="the study table (eyeviz study -o STUDY.csv)")
    parser.add_argument("-o", "--output", required=True, type=Path, help="output directory")
    parser.add_argument(
        "--at", type=float, default=3000.0, help="distance of the heatmap (default 3000)"
    )
    parser.add_argument(
        "--prior",
        default=None,
        choices=("single", "multi"),
        help="which prior's rows to draw (default: the table's only prior, else single)",
    )
    parser.add_argument(
        "--l",
        type=float,
        default=PAPER[1],
        dest="l_wanted",
        help="eye radius l of the curves and the heatmap (default 20, the "
        "paper's; an h without it uses the nearest l)",
    )
    parser.add_argument(
        "--law-max",
        type=float,
        default=LAW_MAX,
        help=f"fit the law where gamma r/(2h) <= this (default {LAW_MAX:g})",
    )
    parser.add_argument(
        "--target",
        type=float,
        default=5.0,
        help="DD error (%%) for the 'fewest ommatidia' table (default 5)",
    )


def run(args: argparse.Namespace) -> int:
    paths = write_report(
        args.table, args.output, args.at, args.prior, args.l_wanted, args.law_max, args.target
    )
    print(f"wrote {len(paths)} files into {args.output}")
    return 0
