"""The figures of the trajectories report (:mod:`eyeviz.reports.trajectories`)."""

from __future__ import annotations

import math

from eyeviz.model.palette import estimator_color
from eyeviz.reports.trajectories_measure import (
    G_VALUES,
    PAPER_LEVELS,
    PAPER_TEXT,
    TRAIN_R,
    Point,
)


# long: a figure's layout, panel after panel: matplotlib calls, not logic
def plot(points: list[Point], kind: str, names: list[str]):
    """Figures 15-17 style: accuracy against distance, one panel per (target, g)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(
        2, len(G_VALUES), figsize=(13, 7), sharex=True, constrained_layout=True
    )
    xlabel = {
        "horizontal": "distance r of the line y = r",
        "circular": "radius r of the circle",
        "vertical": "y along the central axis (segment centre)",
    }[kind]
    for row, target in enumerate(("ad", "dd")):
        for col, g in enumerate(G_VALUES):
            ax = axes[row, col]
            ax.axvspan(TRAIN_R[1], 10500, color="#eeeeee", zorder=0)
            lows = []
            series = []
            for i, name in enumerate(names):
                pts = sorted(
                    (p for p in points if p.kind == kind and p.g == g and p.estimator == name),
                    key=lambda p: p.r,
                )
                if not pts:
                    continue
                xs = [p.r for p in pts]
                ys = [getattr(p, f"{target}_accuracy") for p in pts]
                lows += [v for v in ys if math.isfinite(v)]
                series.append((name, xs, ys))
                # earlier estimators drawn wider, so identical curves stay visible
                ax.plot(
                    xs,
                    ys,
                    marker="o",
                    ms=3.5 + 0.8 * (len(names) - 1 - i),
                    lw=1.4 + 0.6 * (len(names) - 1 - i),
                    color=estimator_color(name),
                    label=name,
                    zorder=2 + i,
                )
            ref = PAPER_TEXT.get((kind, target, g))
            if ref:
                ax.plot(
                    *zip(*ref, strict=True),
                    ls="",
                    marker="x",
                    ms=8,
                    mew=2,
                    color="#555555",
                    label="paper (Section 6 text)",
                )
                lows += [a for _, a in ref]
            level = PAPER_LEVELS.get((kind, target, g))
            if level is not None:
                ax.axhline(
                    level, color="#555555", ls=":", lw=1.3, label="paper: level stated in Section 6"
                )
                lows.append(level)
            bottom = max(-100.0, min([*lows, 90.0]) - 5.0)
            ax.set_ylim(bottom, 101)
            for name, xs, ys in series:  # below the axis: a triangle on its edge
                off = [x for x, v in zip(xs, ys, strict=True) if v < bottom]
                if off:
                    ax.plot(
                        off,
                        [bottom] * len(off),
                        ls="",
                        marker="v",
                        ms=8,
                        clip_on=False,
                        color=estimator_color(name),
                    )
            ax.set_xlim(500, 10500)
            ax.grid(True, alpha=0.3)
            ax.set_title(
                f"{target.upper()} ({'azimuth' if target == 'ad' else 'distance'}), g = {g:g}",
                fontsize=10,
            )
            if col == 0:
                ax.set_ylabel("accuracy = 100 % - MAPE")
            if row == 1:
                ax.set_xlabel(xlabel)
    handles, labels = [], []
    for ax in axes.ravel():
        for h, lab in zip(*ax.get_legend_handles_labels(), strict=True):
            if lab not in labels:
                handles.append(h)
                labels.append(lab)
    handles.append(plt.Rectangle((0, 0), 1, 1, color="#eeeeee"))
    labels.append("outside the training range r <= 5000")
    if any(v < -100 for p in points if p.kind == kind for v in (p.ad_accuracy, p.dd_accuracy)):
        handles.append(plt.Line2D([], [], ls="", marker="v", color="#555555"))
        labels.append("below -100 %")
    fig.legend(
        handles, labels, loc="outside lower center", ncol=len(labels), fontsize=9, frameon=False
    )
    title = {
        "horizontal": "Horizontal trajectories (Figure 15)",
        "circular": "Circular trajectories (Figure 16)",
        "vertical": "Vertical trajectory (Figure 17)",
    }[kind]
    fig.suptitle(title)
    return fig
