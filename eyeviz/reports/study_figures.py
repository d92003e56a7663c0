"""The figures of the eye-design study (:mod:`eyeviz.reports.study`) and their saving.

Planar eyes: DD/AD limit against distance, the heatmap over (h, m) and the law's log-log
plot. Spherical eyes: DD and elevation error against h, l and nside, DD against distance
with the law's lines, every distance bin's law plot and the elevation error; each names
the estimator in its title. All in the house style of :mod:`eyeviz.render.mpl.style`
(Okabe-Ito colours, text >= 7 pt at print size), each saved as PDF, SVG and PNG.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from eyeviz.reports.study_design import MIN_COUNT, PAPER
from eyeviz.reports.study_law import LawFit, LawPoint

FORMATS = ("pdf", "svg", "png")
PNG_DPI = 300
PT = 7.0  # every text in these figures, ticks included
OKABE_ITO = ("#E69F00", "#56B4E9", "#009E73", "#0072B2", "#D55E00", "#CC79A7", "#000000")
DASHES = ("-", "--", ":", "-.")
TWO_COLUMNS, ONE_COLUMN = 7.2, 3.5  # inches


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


# long: a figure's layout, panel after panel: matplotlib calls, not logic
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


def save(fig, outdir: Path, stem: str, formats: tuple[str, ...] = FORMATS) -> list[Path]:
    """The figure in each of ``formats`` (PDF, SVG and PNG at 300 dpi by default), each
    written atomically."""
    from eyeviz.reports.common import save_formats

    return save_formats(fig, outdir / stem, formats, dpi=PNG_DPI, facecolor="white")


# The spherical eyes (a 3D study table)

_DEG = 180.0 / math.pi


def _nside_label(nside: int) -> str:
    return f"nside {nside} (γ = {90 / nside:.3g}°)"


def _title(fig, what: str, estimator: str) -> None:
    fig.suptitle(f"{what}\nestimator: {estimator}", x=0.01, ha="left", fontsize=7)


def design_figure(designs: dict, l_of: dict, h_star: float, estimator: str):
    """Overall DD MAPE (top) and elevation error (bottom) against h (at each h's l, a curve
    per nside), l (at h_star, a curve per nside) and nside (a curve per h, at its l)."""
    from matplotlib.figure import Figure

    hs = sorted(l_of)
    ns = sorted({k[2] for k in designs})
    n_style = _m_style(ns)
    h_style = _m_style([int(h * 1000) for h in hs])
    fig = Figure(figsize=(TWO_COLUMNS, 4.4), layout="constrained")
    axes = fig.subplots(2, 3, squeeze=False)
    metrics = (("dd_mape", "DD: MAPE (%)"), ("el_mae_deg", "elevation: mean |error| (°)"))
    for row, (col, ylabel) in enumerate(metrics):
        ax_h, ax_l, ax_n = axes[row]
        for nv in ns:
            pts = [
                (h, designs[(h, l_of[h], nv)].all[col]) for h in hs if (h, l_of[h], nv) in designs
            ]
            if pts:
                ax_h.plot(
                    *zip(*pts, strict=True),
                    marker="o",
                    ms=2.4,
                    lw=1.2,
                    **n_style[nv],
                    label=_nside_label(nv),
                )
            ls_ = sorted(k[1] for k in designs if k[0] == h_star and k[2] == nv)
            if ls_:
                v = [designs[(h_star, lv, nv)].all[col] for lv in ls_]
                ax_l.plot(ls_, v, marker="o", ms=2.4, lw=1.2, **n_style[nv])
        for h in hs:
            pts = [
                (nv, designs[(h, l_of[h], nv)].all[col]) for nv in ns if (h, l_of[h], nv) in designs
            ]
            if pts:
                ax_n.plot(
                    *zip(*pts, strict=True),
                    marker="o",
                    ms=2.4,
                    lw=1.2,
                    **h_style[int(h * 1000)],
                    label=f"h {h:g}, l {l_of[h]:g}",
                )
        vals = [d.all[col] for d in designs.values()]
        for ax in (ax_h, ax_l, ax_n):
            ax.set_xscale("log")
            _fmt_axis(ax, _log_helps(vals))
        ax_h.set_ylabel(ylabel)
        if row == 1:
            ax_h.set_xlabel("h (eyes 2h apart), l nearest 20")
            ax_l.set_xlabel(f"eye radius l, at h = {h_star:g}")
            ax_n.set_xlabel("nside (4 nside facets on the equator)")
    from matplotlib.ticker import FuncFormatter, NullFormatter

    ls_star = sorted({k[1] for k in designs if k[0] == h_star})
    for j, ticks in enumerate((hs, ls_star, ns)):
        for ax in axes[:, j]:
            ax.set_xticks(ticks)
            ax.xaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
            ax.xaxis.set_minor_formatter(NullFormatter())
    axes[0, 0].legend(frameon=False, loc="best")
    axes[0, 2].legend(frameon=False, loc="best")
    _title(fig, "Over all distances and elevations: against h, l and nside", estimator)
    return fig


def _dd_curves(designs: dict, l_of: dict) -> tuple[dict, dict, list[str]]:
    """The curves of :func:`dd_figure`: for each h, its designs with a style key each; the
    styles and the legend's labels. A curve per nside at each h's l; when the table has
    one nside only, a curve per l instead (every l the table has at that h)."""
    ns = sorted({k[2] for k in designs})
    if len(ns) > 1:
        per_h = {h: [(designs[k], k[2]) for nv in ns if (k := (h, l_of[h], nv)) in designs]
                 for h in l_of}  # fmt: skip
        return per_h, _m_style(ns), [_nside_label(nv) for nv in ns]
    ls_ = sorted({k[1] for k in designs})
    keys = [round(lv * 1000) for lv in ls_]
    per_h = {h: [(designs[(h, lv, ns[0])], kv) for lv, kv in zip(ls_, keys, strict=True)
                 if (h, lv, ns[0]) in designs] for h in l_of}  # fmt: skip
    labels = [f"l = {lv:g}, {_nside_label(ns[0])}" for lv in ls_]
    return per_h, _m_style(keys), labels


def dd_figure(designs: dict, l_of: dict, fit: LawFit, estimator: str):
    """DD MAPE against r, a panel per h, a curve per nside at its l (or per l, for a table
    of one nside; :func:`_dd_curves`), each bin's stated error as a bar; dashed:
    C gamma r/(2h)."""
    from matplotlib.figure import Figure
    from matplotlib.lines import Line2D

    hs = sorted(l_of)
    per_h, style, labels = _dd_curves(designs, l_of)
    vals = [b["dd_mape"] for d in designs.values() for b in d.r_bins if b["count"] >= MIN_COUNT]
    ncols = min(len(hs), 3)
    nrows = math.ceil(len(hs) / ncols)
    fig = Figure(
        figsize=(TWO_COLUMNS if ncols > 1 else ONE_COLUMN, 0.9 + 1.8 * nrows), layout="constrained"
    )
    axes = fig.subplots(nrows, ncols, sharex=True, sharey=True, squeeze=False).ravel()
    for ax, h in zip(axes, hs, strict=False):
        for d, key in per_h[h]:
            c = style[key]["color"]
            bins = [b for b in d.r_bins if b["count"] >= MIN_COUNT]
            r = np.array([b.get("r_mid", 0.5 * (b["lo"] + b["hi"])) for b in bins])
            dd = [b["dd_mape"] for b in bins]
            ax.plot(r, dd, marker="o", ms=2.4, lw=1.3, **style[key])
            se = np.array([b.get("dd_se", math.nan) for b in bins], float)
            if np.isfinite(se).any():  # each bin's sampling error, where the table states it
                ax.errorbar(r, dd, yerr=se, fmt="none", lw=0.8, capsize=1.5, color=c)
            if fit.C is not None and r.size:
                ax.plot(r, 100 * fit.C * d.gamma * r / (2 * h), lw=0.8, ls=(0, (3, 2)), color=c)
        ls_h = ", ".join(f"{d.l:g}" for d, _ in per_h[h])
        ax.set_title(f"h = {h:g}, l = {ls_h}", loc="left", pad=2)
        _fmt_axis(ax, _log_helps(vals))
    for ax in axes[len(hs) :]:
        ax.set_axis_off()
    for i, ax in enumerate(axes[: len(hs)]):
        if i % ncols == 0:
            ax.set_ylabel("DD: MAPE (%)")
        if i >= len(hs) - ncols:
            ax.set_xlabel("distance r")
            ax.tick_params(labelbottom=True)
    handles = [Line2D([], [], marker="o", ms=2.4, lw=1.3, **st) for st in style.values()]
    if fit.C is not None:
        handles.append(Line2D([], [], lw=0.8, ls=(0, (3, 2)), color="black"))
        labels.append(f"dashed: the planar law's form C·γr/(2h), C = {fit.C:.3g} fitted in 3D")
    fig.legend(handles, labels, loc="outside lower center", ncol=min(ncols, 2), frameon=False)
    have_se = any(np.isfinite(b.get("dd_se", math.nan)) for d in designs.values() for b in d.r_bins)
    bars = "\n(bars: ± 1 standard error of each bin)" if have_se else ""
    _title(fig, "Distance error against r: does the γr/(2h) law carry over?" + bars, estimator)
    return fig


def law_figure3d(points: Sequence[LawPoint], fit: LawFit, power: dict | None, estimator: str):
    """Relative DD error of every distance bin against gamma r / (2h), log-log."""
    from matplotlib.figure import Figure
    from matplotlib.lines import Line2D

    ms = sorted({p.m for p in points})
    by_h = len(ms) == 1  # one nside: a colour per h, a marker per l
    group = (lambda p: round(p.h * 1000)) if by_h else (lambda p: p.m)
    keys = sorted({group(p) for p in points})
    style = _m_style(keys)
    ls_ = sorted({p.l for p in points}) if by_h else []
    marker = {lv: "osD^v"[i % 5] for i, lv in enumerate(ls_)}
    fig = Figure(figsize=(ONE_COLUMN, 4.6), layout="constrained")
    ax = fig.add_subplot()
    ax.set_xscale("log")
    ax.set_yscale("log")
    for p in points:
        c = style[group(p)]["color"]
        if math.isfinite(p.y_se):  # the bin's stated sampling error
            ax.errorbar(p.x, p.y, yerr=p.y_se, fmt="none", lw=0.6, color=c, zorder=2.5)
        face = c if p.fitted else "none"
        mk = marker.get(p.l, "o")
        ax.scatter(p.x, p.y, s=7, marker=mk, facecolor=face, edgecolor=c, lw=0.5, zorder=3)
    handles = [Line2D([], [], ls="", marker="o", ms=3, color=style[k]["color"]) for k in keys]
    labels = [f"h = {k / 1000:g}" if by_h else f"nside {k // 4}" for k in keys]
    if by_h:
        handles += [Line2D([], [], ls="", marker=marker[lv], ms=3, color="black") for lv in ls_]
        labels += [f"l = {lv:g}, nside {ms[0] // 4}" for lv in ls_]
    xs = np.array([p.x for p in points])
    if fit.C is not None and xs.size:
        xx = np.geomspace(xs.min(), xs.max(), 50)
        ax.plot(xx, fit.C * xx, color="black", lw=1.0, zorder=2)
        handles.append(Line2D([], [], color="black", lw=1.0))
        labels.append(f"C·γr/(2h): C = {fit.C:.3g}, ×÷{fit.factor or 1:.2f}")
        if fit.slope is not None and fit.C_free is not None:
            ax.plot(xx, fit.C_free * xx**fit.slope, color="#7A7A7A", lw=0.9, ls="--", zorder=2)
            handles.append(Line2D([], [], color="#7A7A7A", lw=0.9, ls="--"))
            labels.append(f"free slope {fit.slope:.2f}")
    if power is not None:
        sym = {"exp_gamma": "γ", "exp_r": "r", "exp_h": "h", "exp_l": "l"}
        parts = [f"{sym[k]}^{power[k]:.2f}" for k in sym if power[k] is not None]
        ax.text(
            0.02,
            0.98,
            "power law fit:\nrel. DD ∝ "
            + " ".join(parts)
            + f"\n(planar law: γ^1 r^1 h^-1 l^0)\n{power['n']} filled bins",
            transform=ax.transAxes,
            va="top",
            ha="left",
        )
    ax.set_xlabel("γ r / (2h)   (γ = 2π / (4 nside))")
    ax.set_ylabel("relative DD error (MAPE / 100)")
    _fmt_axis(ax, False)
    fig.legend(handles, labels, loc="outside lower center", ncol=2, frameon=False)
    bars = ", bars: ± 1 s.e." if any(math.isfinite(p.y_se) for p in points) else ""
    _title(fig, f"Every distance bin (filled: fitted{bars})", estimator)
    return fig


def elevation_figure(designs: dict, h: float, l_: float, estimator: str):
    """Elevation (solid) and azimuth (dotted) error against elevation and against r, a
    curve per nside, at (h, l)."""
    from matplotlib.figure import Figure
    from matplotlib.lines import Line2D

    ns = sorted(k[2] for k in designs if k[:2] == (h, l_))
    style = _m_style(ns)
    fig = Figure(figsize=(TWO_COLUMNS, 2.9), layout="constrained")
    ax_e, ax_r = fig.subplots(1, 2, squeeze=True)
    vals = []
    for nv in ns:
        d = designs[(h, l_, nv)]
        for ax, bins, scale in ((ax_e, d.el_bins, _DEG), (ax_r, d.r_bins, 1.0)):
            bins = [b for b in bins if b["count"] >= MIN_COUNT]
            x = [0.5 * (b["lo"] + b["hi"]) * scale for b in bins]
            el = [b["el_mae_deg"] for b in bins]
            az = [b["az_mae_deg"] for b in bins]
            vals += el + az
            ax.plot(x, el, marker="o", ms=2.4, lw=1.3, **style[nv])
            se = np.array([b.get("el_se", math.nan) for b in bins], float)
            if np.isfinite(se).any():  # each bin's sampling error, where the table states it
                c = style[nv]["color"]
                ax.errorbar(x, el, yerr=se, fmt="none", lw=0.8, capsize=1.5, color=c)
            ax.plot(x, az, lw=0.9, ls=":", color=style[nv]["color"])
    for ax in (ax_e, ax_r):
        _fmt_axis(ax, _log_helps(vals))
        ax.set_ylabel("mean |error| (°)")
    ax_e.set_xlabel("elevation of the ball (°)")
    ax_r.set_xlabel("distance r")
    handles = [Line2D([], [], marker="o", ms=2.4, lw=1.3, **style[nv]) for nv in ns]
    labels = [_nside_label(nv) for nv in ns]
    handles.append(Line2D([], [], lw=0.9, ls=":", color="black"))
    labels.append("dotted: azimuth error, for comparison")
    fig.legend(handles, labels, loc="outside right center", frameon=False)
    have_se = any(
        np.isfinite(b.get("el_se", math.nan)) for nv in ns for b in designs[(h, l_, nv)].el_bins
    )
    bars = " (bars: ± 1 standard error of each bin)" if have_se else ""
    _title(fig, f"Elevation error (solid) at h = {h:g}, l = {l_:g}{bars}", estimator)
    return fig
