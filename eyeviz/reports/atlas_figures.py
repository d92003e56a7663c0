"""The atlas's figures (matplotlib), each written as PNG and SVG (:func:`write_all`).

- ``atlas_field``: per pair, the whole sphere of directions at the prior's r_max
  (Mollweide: eye A only, eye B only, both; the r_min binocular field outlined), and the
  binocular field close up, coloured by the facets of eye A and of eye B that see it;
- ``atlas_distance``: per pair, DD against r (mm below, baselines b above) for every
  estimator, with standard errors;
- ``atlas_rule``: per pair, DD against the rule of thumb's Z dphi / b (log-log, the line
  DD = rule dashed);
- ``atlas_scaling``: every pair's DD against r / b on one axis (eye size);
- ``atlas_angles``: azimuth and elevation mean absolute errors against r / b.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

__all__ = ["FORMATS", "write_all"]

FORMATS = ("png", "svg")
DPI = 130
_MAP_COLORS = ("#ffffff", "#9ecae1", "#fdae6b", "#54278f")  # none, A only, B only, both
_STYLE = {"analytic3d": ("#1f77b4", "o", "--"), "limit3d": ("#d62728", "s", "-")}
_PAIR_COLORS = (
    "#1b9e77",
    "#d95f02",
    "#7570b3",
    "#e7298a",
    "#66a61e",
    "#e6ab02",
    "#a6761d",
    "#666666",
)


def _style(name: str) -> tuple[str, str, str]:
    return _STYLE.get(name, ("#2ca02c", "^", "-."))


def _save(fig, outdir: Path, stem: str, formats: tuple[str, ...] = FORMATS) -> Path:
    from eyeviz.reports.common import save_formats

    return save_formats(fig, outdir / stem, formats, dpi=DPI)[0]


#: imshow extent of the whole-sphere grid: azimuth 270 ... -90 from left to right, so eye
#: A's side (azimuth 180) is on the left, as the animal sees it; elevation -90 ... 90
_EXTENT = (270.0, -90.0, -90.0, 90.0)


def _outline(ax, field: dict) -> None:
    """The binocular directions of ``field`` outlined (in azimuth, elevation)."""
    if field["both"].any():
        ax.contour(
            90.0 - field["lon"],
            field["lat"],
            field["both"].astype(float),
            levels=[0.5],
            colors="#e7298a",
            linewidths=1.2,
        )


def _map_panel(ax, a, near: dict, far: dict) -> None:
    """The whole sphere at r_max: eye A only, eye B only, both; r_min's field outlined."""
    from matplotlib.colors import ListedColormap

    cls = (far["na"] >= 2).astype(int) + 2 * (far["nb"] >= 2).astype(int)
    cls[(cls == 3) & ~far["both"]] = 0  # both see it but the ball holds a lens
    ax.imshow(
        cls,
        cmap=ListedColormap(_MAP_COLORS),
        vmin=-0.5,
        vmax=3.5,
        origin="lower",
        extent=_EXTENT,
        aspect="auto",
        interpolation="nearest",
    )
    _outline(ax, near)
    ax.set_xlim(270, -90)
    ax.set_xticks([270, 180, 90, 0, -90])
    ax.set_xticklabels(
        ["behind", "180 left (A)", "90 forward", "0 right (B)", "behind"], fontsize=7
    )
    ax.set_yticks([-90, -45, 0, 45, 90])
    ax.tick_params(axis="y", labelsize=7)
    ax.set_ylabel("elevation (deg)", fontsize=8)
    ax.grid(True, color="#bbbbbb", linewidth=0.4)
    ax.set_title(
        f"{a.label} ({a.facets[0]} + {a.facets[1]} facets, b = "
        f"{a.prior['b_mm']:.2f} mm)\nwhich eye sees each direction at "
        f"{far['r_mm']:.3g} mm (azimuth, deg)",
        fontsize=9,
    )


def _zoom_panel(fig, ax, near: dict, far: dict, key: str, eye: str, cmap: str, box) -> None:
    """The binocular field at r_max close up, coloured by the facets of one eye."""
    from matplotlib.ticker import MaxNLocator

    if far["both"].any():
        val = np.where(far["both"], far[key], np.nan).astype(float)
        im = ax.imshow(
            val,
            cmap=cmap,
            origin="lower",
            extent=_EXTENT,
            aspect="auto",
            interpolation="nearest",
            vmin=2,
            vmax=max(3, np.nanmax(val)),
        )
        cb = fig.colorbar(im, ax=ax, shrink=0.85, pad=0.02, label="facets lit")
        cb.ax.yaxis.set_major_locator(MaxNLocator(integer=True))
    else:
        ax.text(0.5, 0.5, "no binocular direction", ha="center", transform=ax.transAxes)
    _outline(ax, near)
    ax.set_xlim(box[1], box[0])  # azimuth grows to the left, as the animal sees it
    ax.set_ylim(box[2], box[3])
    ax.axvline(90, color="#888", lw=0.6, ls="--")
    ax.set_xlabel("azimuth (deg; 90 = forward)", fontsize=8)
    ax.set_ylabel("elevation (deg)", fontsize=8)
    ax.set_title(
        f"binocular at {far['r_mm']:.3g} mm ({far['r_b']:.3g} b): facets of eye {eye}", fontsize=9
    )


def _field_figure(atlases):
    import matplotlib.pyplot as plt
    from matplotlib.patches import Patch

    k = len(atlases)
    fig = plt.figure(figsize=(16, 4.2 * k))
    for row, a in enumerate(atlases):
        near, far = a.fields[0], a.fields[-1]
        _map_panel(fig.add_subplot(k, 3, 3 * row + 1), a, near, far)
        box = _box(far["both"] | near["both"], far["lon"], far["lat"], a.grid_step)
        for col, (key, eye, cmap) in enumerate(
            (("na", "A (left)", "Blues"), ("nb", "B (right)", "Oranges"))
        ):
            ax = fig.add_subplot(k, 3, 3 * row + 2 + col)
            _zoom_panel(fig, ax, near, far, key, eye, cmap, box)
    handles = [
        Patch(color=_MAP_COLORS[1], label="eye A (left) only"),
        Patch(color=_MAP_COLORS[2], label="eye B (right) only"),
        Patch(color=_MAP_COLORS[3], label="both (binocular) at r_max"),
        Patch(facecolor="none", edgecolor="#e7298a", label="binocular at r_min"),
    ]
    fig.legend(handles=handles, loc="lower center", ncol=4, fontsize=9, frameon=False)
    fig.suptitle(
        "Binocular field: balls of angular radius "
        f"{_ball(atlases)} deg; seen = at least 2 facets lit, no lens inside",
        fontsize=11,
    )
    fig.tight_layout(rect=(0, 0.03, 1, 0.97))
    return fig


def _ball(atlases) -> str:
    return f"{atlases[0].ball_deg:g}"


def _box(both, lon, lat, step) -> tuple[float, float, float, float]:
    if not both.any():
        return (60.0, 120.0, -60.0, 60.0)
    az = 90.0 - lon[both]
    pad = 4.0
    return (
        float(az.min()) - pad,
        float(az.max()) + pad,
        max(float(lat[both].min()) - pad, -90.0),
        min(float(lat[both].max()) + pad, 90.0),
    )


def _errorbars(ax, x, rows, key, name, label=None, color=None) -> None:
    c, m, ls = _style(name)
    y = np.array([b[key] for b in rows])
    se = np.array([b[key + "_se"] for b in rows])
    ax.errorbar(
        x,
        y,
        yerr=np.nan_to_num(se),
        color=color or c,
        marker=m,
        ls=ls,
        ms=5,
        capsize=3,
        lw=1.3,
        label=label or name,
    )


def _distance_figure(atlases):
    import matplotlib.pyplot as plt

    k = len(atlases)
    fig, axes = plt.subplots(1, k, figsize=(5.2 * k, 4.4), squeeze=False)
    for ax, a in zip(axes[0], atlases, strict=True):
        b = a.prior["b_mm"]
        for name, rows in a.bins.items():
            _errorbars(ax, [r["r_mid_mm"] for r in rows], rows, "dd", name)
            ax.plot(
                [r["r_mid_mm"] for r in rows],
                [r["rule"] for r in rows],
                color="#555",
                ls=":",
                lw=1.0,
                label="rule Z dphi / b" if name == next(iter(a.bins)) else None,
            )
        ax.set_xlabel("distance r (mm)")
        ax.set_ylabel("DD: mean |r^ - r| / r (%)")
        ax.set_title(f"{a.label}", fontsize=10)
        ax.grid(alpha=0.3)
        top = ax.secondary_xaxis("top", functions=(lambda x, b=b: x / b, lambda x, b=b: x * b))
        top.set_xlabel("distance r / b (baselines)")
        ax.legend(fontsize=8)
    fig.suptitle("Distance error against distance (mean, bars: standard error)", fontsize=11)
    fig.tight_layout()
    return fig


def _rule_figure(atlases):
    import matplotlib.pyplot as plt
    from matplotlib.ticker import NullFormatter, ScalarFormatter

    k = len(atlases)
    fig, axes = plt.subplots(1, k, figsize=(4.8 * k, 4.4), squeeze=False)
    for ax, a in zip(axes[0], atlases, strict=True):
        lo, hi = np.inf, 0.0
        for name, rows in a.bins.items():
            x = np.array([r["rule"] for r in rows])
            _errorbars(ax, x, rows, "dd", name)
            ok = np.isfinite(x) & (x > 0)
            if ok.any():
                lo, hi = min(lo, x[ok].min()), max(hi, x[ok].max())
        if hi > 0:
            t = np.array([lo / 1.5, hi * 1.5])
            ax.plot(t, t, color="#555", ls="--", lw=1, label="DD = Z dphi / b")
        ax.set_xscale("log")
        ax.set_yscale("log")
        for axis in (ax.xaxis, ax.yaxis):  # plain numbers: 30, 40, 60 rather than 3 x 10^1
            axis.set_major_formatter(ScalarFormatter())
            axis.set_minor_formatter(NullFormatter())
        ax.set_xlabel("rule of thumb: Z dphi_loc / b (%)")
        ax.set_ylabel("DD (%)")
        ax.set_title(a.label, fontsize=10)
        ax.grid(alpha=0.3, which="both")
        ax.legend(fontsize=8)
    fig.suptitle(
        "The rule of thumb dZ ~ Z^2 dphi / b against the measured error, per distance bin",
        fontsize=11,
    )
    fig.tight_layout()
    return fig


def _scaling_figure(atlases, keys=(("dd", "DD (%)"),), title="Eye size"):
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, len(keys), figsize=(6.0 * len(keys), 4.6), squeeze=False)
    for ax, (key, ylabel) in zip(axes[0], keys, strict=True):
        for i, a in enumerate(atlases):
            b = a.prior["b_mm"]
            for name, rows in a.bins.items():
                x = [r["r_mid_mm"] / b for r in rows]
                _errorbars(
                    ax,
                    x,
                    rows,
                    key,
                    name,
                    color=_PAIR_COLORS[i % 8],
                    label=f"{a.label} ({sum(a.facets)} facets), {name}",
                )
        ax.set_xlabel("distance r / b (baselines)")
        ax.set_ylabel(ylabel)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
    fig.suptitle(title, fontsize=11)
    fig.tight_layout()
    return fig


def write_all(atlases, outdir: Path, formats: tuple[str, ...] = FORMATS) -> list[Path]:
    """Every figure in each of ``formats`` in ``outdir``; the first format's paths."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    outdir.mkdir(parents=True, exist_ok=True)
    figures = (
        ("atlas_field", lambda: _field_figure(atlases)),
        ("atlas_distance", lambda: _distance_figure(atlases)),
        ("atlas_rule", lambda: _rule_figure(atlases)),
        (
            "atlas_scaling",
            lambda: _scaling_figure(
                atlases,
                title="How the distance error scales with the eye: every pair against "
                "r in baselines",
            ),
        ),
        (
            "atlas_angles",
            lambda: _scaling_figure(
                atlases,
                (
                    ("az", "azimuth: mean absolute error (deg)"),
                    ("el", "elevation: mean absolute error (deg)"),
                ),
                "Azimuth and elevation errors against r in baselines",
            ),
        ),
    )
    paths = []
    for stem, make in figures:
        fig = make()
        paths.append(_save(fig, outdir, stem, formats))
        plt.close(fig)
    return paths
