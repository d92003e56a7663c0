"""The figures of the 3D design study (:mod:`eyeviz.reports.study3d`).

House style of the planar study's figures (:mod:`eyeviz.reports.study_figures`: Okabe-Ito
colours, text >= 7 pt at print size); each names the estimator in its title.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from eyeviz.reports.study_design import MIN_COUNT
from eyeviz.reports.study_figures import ONE_COLUMN, TWO_COLUMNS, _fmt_axis, _log_helps, _m_style
from eyeviz.reports.study_law import LawFit, LawPoint

__all__ = ["dd_figure", "design_figure", "elevation_figure", "law_figure3d"]

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
