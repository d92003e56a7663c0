"""The figure of the renderers report (:mod:`eyeviz.reports.renderers`): three panels.

(a) the RMS error of sampled responses against rays per facet, (b) the response of the
issue's 1-degree ball against its offset from the axis, (c) the share of each sampler's
rays within an angle of the axis.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from eyeviz.reports.renderers_measure import TARGET, Row

FORMATS = ("png", "svg", "pdf")
DPI = 200
COLORS = {
    "gauss2d": "#4c72b0",
    "compoundray": "#c44e52",
    "invertpy": "#8172b3",
    "uniform": "#dd8452",
    "uniform-flat": "#55a868",
    "gaussian": "black",
    "flat": "#55a868",
}


def _errors(ax, rows: list[Row]) -> None:
    for row in rows:
        ns = sorted(row.rms)
        ys = [row.rms[n] for n in ns]
        c = COLORS[row.key]
        if len(ns) == 1:
            ax.plot(ns, ys, "*", ms=13, color=c, label=row.label, zorder=5)
        else:
            ax.plot(ns, ys, "-", lw=1.8, color=c, label=row.label)
            if row.bias_rms > 1e-6:
                ax.axhline(row.bias_rms, color=c, ls=":", lw=1)
        if row.mc_rays and math.isfinite(row.mc_rms):
            ax.plot([row.mc_rays], [row.mc_rms], "o", mfc="none", color=c, ms=7)
    ax.axhline(TARGET, color="0.3", ls="--", lw=1)
    ax.text(1.2, TARGET * 0.8, "1 % error", fontsize=8, color="0.3", va="top")
    ax.set_xscale("log", base=2)
    ax.set_yscale("log")
    ax.set_xlabel("rays per facet N")
    ax.set_ylabel("RMS error of the response (full coverage = 1)")
    ax.set_title(
        "(a) sampled against exact: error against rays\n"
        "dotted: the bias floor; circles: Monte-Carlo check",
        fontsize=9,
    )
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=7.5, loc="lower left", frameon=False)


def _offsets(ax, curves: dict[str, np.ndarray], example: dict[str, float]) -> None:
    deg = np.degrees(curves["delta"])
    ax.plot(deg, curves["gaussian"], color="black", lw=2.2, label="exact gaussian")
    ax.plot(
        deg,
        curves["flat"],
        color=COLORS["flat"],
        lw=1.6,
        ls="--",
        label="exact flat = uniform cone",
    )
    ax.plot(
        deg, curves["compoundray"], color=COLORS["compoundray"], lw=1.8, label="CompoundRay's limit"
    )
    ax.plot(
        deg, curves["invertpy"], color=COLORS["invertpy"], lw=1.4, label="InvertPy, mean over roll"
    )
    ax.fill_between(
        deg,
        curves["invertpy_lo"],
        curves["invertpy_hi"],
        color=COLORS["invertpy"],
        alpha=0.18,
        lw=0,
        label="InvertPy, range over roll",
    )
    x = example["delta_deg"]
    ax.axvline(x, color="0.5", lw=0.8, ls=":")
    ax.set_xlabel("ball centre's angle from the facet's axis (degrees)")
    ax.set_ylabel("response")
    ax.set_title(
        f"(b) a {example['beta_deg']:g}-degree ball, facet of {example['dr_deg']:g} degrees\n"
        f"at {x:g} degrees: exact {example['exact']:.3f}, CompoundRay {example['compoundray']:.3f}",
        fontsize=9,
    )
    ax.set_ylim(0, None)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7.5, frameon=False)


def _radial(ax, cdf: dict[str, np.ndarray], dr: float) -> None:
    t = cdf["theta"] / dr
    labels = {
        "gauss2d": "2-D Gaussian",
        "compoundray": "CompoundRay",
        "invertpy": "InvertPy (weights)",
        "uniform": "uniform cone",
    }
    for s, lab in labels.items():
        style = "-" if s != "invertpy" else "-"
        ax.plot(
            t,
            cdf[s],
            style,
            color=COLORS[s],
            lw=1.8,
            label=lab,
            drawstyle="steps-post" if s == "invertpy" else "default",
        )
    ax.axvline(0.5, color="0.4", lw=0.8, ls=":")
    ax.axhline(0.5, color="0.4", lw=0.8, ls=":")
    ax.set_xlabel("angle from the axis / acceptance angle (FWHM)")
    ax.set_ylabel("share of the rays within that angle")
    ax.set_title("(c) where the rays go: at FWHM/2 a Gaussian has 50 %", fontsize=9)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7.5, frameon=False, loc="lower right")


def plot(rows, curves, cdf, dr: float, example: dict[str, float], path: Path) -> list[Path]:
    """The three panels at ``path`` (.png) and beside it as .svg and .pdf; the paths."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from eyeviz.reports.common import save_formats

    fig, axes = plt.subplots(1, 3, figsize=(15.5, 4.9), constrained_layout=True)
    _errors(axes[0], rows)
    _offsets(axes[1], curves, example)
    _radial(axes[2], cdf, dr)
    fig.suptitle(
        f"Sampled against exact responses, facet acceptance {math.degrees(dr):g} degrees"
        " (issue 34.4)",
        fontsize=11,
    )
    fig.canvas.draw()  # lay out once; the three formats reuse it
    fig.set_layout_engine("none")
    written = save_formats(fig, path.with_suffix(""), FORMATS, dpi=DPI)
    plt.close(fig)
    return written
