"""The figures of the estimators report (:mod:`eyeviz.reports.estimators`): the planar
eyes' (:func:`plot`) and those of the eyes that see lit sets, spherical or measured
(:func:`plot_lit`)."""

from __future__ import annotations

import math

from eyeviz.model.palette import ESTIMATOR_COLORS, estimator_color
from eyeviz.reports.estimators_measure import PAPER_TABLE5, Result, _limit

# one colour per estimator name, the same in the app, the figures and every report
# (eyeviz.model.palette); kept under this name for the reports that import it
_COLORS = ESTIMATOR_COLORS


# long: a figure's layout, panel after panel: matplotlib calls, not logic
def plot(results: list[Result]):
    """Figure: AD and DD MAPE against inference time per sample (log-log).

    Markers sit at the batched time; a thin line runs from there to the time of one call
    with one sample (the latency an interactive user sees).
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.lines import Line2D
    from matplotlib.ticker import FuncFormatter, LogLocator

    fig, axes = plt.subplots(1, 2, figsize=(11, 4.8), constrained_layout=True)
    lim = _limit(results)
    ok = [r for r in results if r.ok and r.batched_us]
    handles: dict[str, Line2D] = {}
    for ax, (key, title) in zip(axes, (("ad", "AD: azimuth"), ("dd", "DD: distance")), strict=True):
        for i, r in enumerate(ok):
            c = estimator_color(r.name)
            size = 45 + 45 * (len(ok) - 1 - i)  # coincident points show as concentric rings
            assert r.batched_us is not None  # ok keeps only timed results
            x = r.batched_us * 1e-6
            y = r.metrics["single"][key]["mape"]
            if r.single_ms and math.isfinite(y):
                ax.plot(
                    [x, r.single_ms * 1e-3],
                    [y, y],
                    color=c,
                    lw=1.0,
                    alpha=0.6,
                    marker="|",
                    markevery=[1],
                    ms=10,
                    zorder=2,
                )
            for mode, marker, face in (("single", "o", c), ("multi", "s", "none")):
                y = r.metrics[mode][key]["mape"]
                if math.isfinite(y):
                    ax.scatter(
                        [x],
                        [y],
                        marker=marker,
                        s=size,
                        facecolors=face,
                        edgecolors=c,
                        linewidths=1.5,
                        zorder=3 + i,
                    )
            handles.setdefault(
                r.name, Line2D([], [], marker="o", ls="", color=c, label=r.label_short())
            )
        t5 = PAPER_TABLE5[key]["mape"]
        ax.axhline(t5, color="#555555", ls=":", lw=1.3)
        if lim is not None:
            ax.axhline(
                lim.metrics["single"][key]["mape"],
                color=estimator_color("bayes"),
                ls="--",
                lw=1.0,
                alpha=0.8,
            )
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.margins(x=0.2, y=0.25)
        lo, hi = ax.get_ylim()
        major = (
            (1.0, 2.0, 5.0)
            if math.log10(hi / lo) > 1.2
            else (1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0)
        )
        ax.yaxis.set_major_locator(LogLocator(subs=major))
        ax.yaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
        ax.yaxis.set_minor_locator(LogLocator(subs=tuple(float(k) for k in range(1, 10))))
        ax.yaxis.set_minor_formatter(FuncFormatter(lambda v, _: ""))
        ax.set_xlabel("inference time per sample (s)")
        ax.set_ylabel("MAPE (%)")
        ax.set_title(title)
        ax.grid(True, which="major", alpha=0.35)
        ax.grid(True, which="minor", alpha=0.12)
    extra = [
        Line2D([], [], marker="o", ls="", color="k", label="single-pass test set, batched"),
        Line2D(
            [],
            [],
            marker="s",
            ls="",
            markerfacecolor="none",
            color="k",
            label="multi-pass test set, batched",
        ),
        Line2D(
            [], [], marker="|", ms=10, color="k", lw=1.0, alpha=0.6, label="one sample per call"
        ),
        Line2D([], [], ls=":", color="#555555", lw=1.3, label="paper Table 5 (quoted)"),
    ]
    if lim is not None:
        extra.append(
            Line2D(
                [],
                [],
                ls="--",
                color=estimator_color("bayes"),
                label="information limit (bayes, single-pass)",
            )
        )
    missing = [r.name for r in results if not r.ok]
    if missing:
        extra.append(Line2D([], [], ls="", label="unavailable: " + ", ".join(missing)))
    fig.legend(
        handles=[*handles.values(), *extra],
        loc="outside lower center",
        ncol=4,
        fontsize=8,
        frameon=False,
    )
    return fig


# long: the three panels' matplotlib calls, as plot's
def plot_lit(results: list[Result]):
    """Figure: DD and AD MAPE and elevation MAE on the subset against time per row, each
    with its bootstrap standard error as an error bar (``Result.errors``)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 3, figsize=(14, 4.6), constrained_layout=True)
    ok = [r for r in results if r.ok]
    panels = (
        ("dd", "DD: distance, MAPE (%)"),
        ("ad", "AD: azimuth, MAPE (%)"),
        ("el_mae_deg", "elevation, MAE (degrees)"),
    )
    for ax, (key, title) in zip(axes, panels, strict=True):
        for r in ok:
            assert r.batched_us is not None and r.single_ms is not None  # measured
            x = r.batched_us * 1e-6
            y = r.metrics["subset"][key]
            c = estimator_color(r.name.removesuffix("3d"))
            ax.plot([x, r.single_ms * 1e-3], [y, y], color=c, lw=1.0, alpha=0.6)
            se = r.errors.get("subset", {}).get(key, math.nan)
            if math.isfinite(se):
                ax.errorbar(
                    [x], [y], yerr=[se], fmt="none", color="black", lw=1.0, capsize=5, zorder=4
                )
            ax.scatter([x], [y], s=70, color=c, edgecolors="black", zorder=3, label=r.name)
            ax.annotate(r.name, (x, y), textcoords="offset points", xytext=(6, 6), fontsize=8)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_title(title)
        ax.set_xlabel("seconds per row (marker: batched; line to: one row alone)")
        ax.grid(True, which="both", alpha=0.3)
    if ok:
        axes[0].legend(loc="best", fontsize=8)
    return fig
