"""Figure: the binocular field of a real bee's eyes (docs/measured.md).

For the shipped honeybee (AM_60185) and the two bumblebees (BT_77967, BT_77973), small
balls (angular radius 0.5 degrees seen from the head) are placed on a 0.5-degree
longitude/latitude grid of directions from the head's centre (the midpoint of the two
lens centroids, ``Domain3D.origin``) at 20 mm and at 100 mm. Each ball's lit sets come
from ``pair.lit_csr`` (exact). A direction is *seen* by an eye when its ball lights at
least two facets of that eye (Definition 1) and *binocular* when both eyes see it (no
ball at these distances contains a lens, so this is ``in_bfv``).

Per bee, one row: a Mollweide map of the whole sphere of directions at 100 mm (eye A
only, eye B only, both; the 20 mm binocular field outlined), then a close-up of the
binocular field coloured by the number of facets of eye A, and of eye B, that see each
binocular direction at 100 mm. Azimuth is eyeviz's: 90 degrees straight ahead (+y),
0 towards eye B (right, +x), 180 towards eye A (left); elevation up (+z).
The script prints each field's extent (azimuth and elevation ranges, solid angle).

Run: ``python scripts/figure_bee_field.py [-o docs/img/bee_binocular_field.png]``
"""

from __future__ import annotations

import argparse
import math
import os

import numpy as np

os.environ.setdefault("MPLBACKEND", "Agg")

import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.colors import ListedColormap  # noqa: E402
from matplotlib.patches import Patch  # noqa: E402
from matplotlib.ticker import MaxNLocator  # noqa: E402

from eyeviz.measured import load_eyes, shipped_eye  # noqa: E402

BEES = (
    ("AM_60185-real.eye", "honeybee (Apis mellifera) AM_60185"),
    ("BT_77967-real.eye", "bumblebee (Bombus terrestris) BT_77967"),
    ("BT_77973-real.eye", "small bumblebee BT_77973"),
)
DISTANCES = (100.0, 20.0)  # filled, outlined
STEP = 0.5  # grid step, degrees
BALL = 0.5  # ball's angular radius seen from the head, degrees
COLORS = ("#ffffff", "#9ecae1", "#fdae6b", "#54278f")  # none, A only, B only, both


def grid() -> tuple[np.ndarray, np.ndarray]:
    """(plot longitude, latitude) in degrees of the grid's cell centres, 2D. The plot
    longitude is 90 - azimuth: 0 straight ahead, +90 to the right (eye B), +-180 behind."""
    lon = np.arange(-180 + STEP / 2, 180, STEP)
    lat = np.arange(-90 + STEP / 2, 90, STEP)
    return np.meshgrid(lon, lat)


def counts(pair, r: float, lon: np.ndarray, lat: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Facets of eye A and of eye B lit by the ball at distance r in each grid direction."""
    o = np.mean(np.array(pair.centers), axis=0)
    az = np.radians(90.0 - lon.ravel())
    el = np.radians(lat.ravel())
    x = o[0] + r * np.cos(el) * np.cos(az)
    y = o[1] + r * np.cos(el) * np.sin(az)
    z = o[2] + r * np.sin(el)
    g = np.full(x.shape, r * math.sin(math.radians(BALL)))
    (pa, _), (pb, _) = pair.lit_csr(x, y, z, g)
    return np.diff(pa).reshape(lon.shape), np.diff(pb).reshape(lon.shape)


def extent(both: np.ndarray, lon: np.ndarray, lat: np.ndarray) -> dict[str, float]:
    """The binocular field's azimuth and elevation ranges (degrees) and solid angle (sr)."""
    if not both.any():
        return {"sr": 0.0}
    az = 90.0 - lon[both]
    cell = math.radians(STEP) ** 2 * np.cos(np.radians(lat[both]))
    return {
        "az_min": float(az.min() - STEP / 2),
        "az_max": float(az.max() + STEP / 2),
        "el_min": float(lat[both].min() - STEP / 2),
        "el_max": float(lat[both].max() + STEP / 2),
        "sr": float(cell.sum()),
    }


def describe(name: str, r: float, e: dict[str, float], na, nb) -> str:
    if e["sr"] == 0.0:
        return f"{name} at {r:g} mm: no binocular direction"
    return (
        f"{name} at {r:g} mm: azimuth {e['az_min']:.1f} to {e['az_max']:.1f} deg, "
        f"elevation {e['el_min']:.1f} to {e['el_max']:.1f} deg, "
        f"{e['sr']:.3f} sr ({e['sr'] * (180 / math.pi) ** 2:.0f} deg^2); facets seeing a "
        f"binocular direction: eye A median {np.median(na):.0f} (max {na.max()}), "
        f"eye B median {np.median(nb):.0f} (max {nb.max()})"
    )


def map_panel(ax, lon, lat, na, nb, both_far) -> None:
    """Mollweide map of which eye sees each direction (first distance); the second
    distance's binocular field outlined."""
    cls = (na >= 2).astype(int) + 2 * (nb >= 2).astype(int)
    edges_lon = np.radians(np.arange(-180, 180 + STEP / 2, STEP))
    edges_lat = np.radians(np.arange(-90, 90 + STEP / 2, STEP))
    ax.pcolormesh(
        edges_lon,
        edges_lat,
        cls,
        cmap=ListedColormap(COLORS),
        vmin=-0.5,
        vmax=3.5,
        shading="flat",
        rasterized=True,
    )
    ax.contour(
        np.radians(lon),
        np.radians(lat),
        both_far.astype(float),
        levels=[0.5],
        colors="#e7298a",
        linewidths=1.2,
    )
    ticks = [-150, -90, -30, 30, 90, 150]
    ax.set_xticks(np.radians(ticks))
    ax.set_xticklabels(
        [f"{90 - t:g}" if 90 - t >= 0 else f"{90 - t + 360:g}" for t in ticks],
        fontsize=7,
        color="#444444",
    )
    ax.set_yticks(np.radians([-60, -30, 0, 30, 60]))
    ax.tick_params(axis="y", labelsize=7)
    ax.grid(True, color="#bbbbbb", linewidth=0.4)
    for txt, x, y in (
        ("forward", 0, 12),
        ("left\n(eye A)", -90, 12),
        ("right\n(eye B)", 90, 12),
        ("up", 0, 80),
        ("down", 0, -84),
    ):
        ax.text(
            math.radians(x),
            math.radians(y),
            txt,
            ha="center",
            va="bottom",
            fontsize=8,
            fontweight="bold",
            color="#222222",
        )


def zoom_panel(ax, fig, lon, lat, n, both, both_far, box, title, cmap) -> None:
    """Close-up (azimuth, elevation) of the binocular field at the first distance,
    coloured by facet count."""
    val = np.where(both, n, np.nan).astype(float)
    az = 90.0 - lon
    im = ax.pcolormesh(
        az,
        lat,
        val,
        cmap=cmap,
        shading="nearest",
        rasterized=True,
        vmin=2,
        vmax=np.nanmax(val) if both.any() else 3,
    )
    ax.contour(az, lat, both_far.astype(float), levels=[0.5], colors="#e7298a", linewidths=1.2)
    ax.set_xlim(box[1], box[0])  # azimuth grows to the left: left on the left, as seen
    ax.set_ylim(box[2], box[3])
    ax.axvline(90, color="#888888", linewidth=0.6, linestyle="--")
    ax.set_xlabel("azimuth (deg; 90 = forward, left <- -> right)", fontsize=8)
    ax.set_ylabel("elevation (deg)", fontsize=8)
    ax.tick_params(labelsize=7)
    ax.set_title(title, fontsize=9)
    cb = fig.colorbar(im, ax=ax, shrink=0.85, pad=0.02)
    cb.ax.yaxis.set_major_locator(MaxNLocator(integer=True))
    cb.ax.tick_params(labelsize=7)


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("-o", "--output", default="docs/img/bee_binocular_field.png")
    args = ap.parse_args(argv)
    lon, lat = grid()
    fig = plt.figure(figsize=(17, 4.3 * len(BEES)))
    for row, (fname, title) in enumerate(BEES):
        pair = load_eyes(shipped_eye(fname))
        near = counts(pair, DISTANCES[0], lon, lat)
        far = counts(pair, DISTANCES[1], lon, lat)
        both_near = (near[0] >= 2) & (near[1] >= 2)
        both_far = (far[0] >= 2) & (far[1] >= 2)
        for r, (na, nb), both in sorted(
            ((DISTANCES[0], near, both_near), (DISTANCES[1], far, both_far)), key=lambda t: t[0]
        ):
            print(describe(title, r, extent(both, lon, lat), na[both], nb[both]))
        e = extent(both_near | both_far, lon, lat)
        pad = 4.0
        box = (
            e["az_min"] - pad,
            e["az_max"] + pad,
            max(e["el_min"] - pad, -90),
            min(e["el_max"] + pad, 90),
        )
        ax = fig.add_subplot(len(BEES), 3, 3 * row + 1, projection="mollweide")
        map_panel(ax, lon, lat, near[0], near[1], both_far)
        ax.set_title(
            f"{title}\n(h = {pair.h:.2f} mm; directions from the head's centre)", fontsize=9
        )
        for col, (n, eye, cmap) in enumerate(
            ((near[0], "A (left)", "Blues"), (near[1], "B (right)", "Oranges"))
        ):
            zoom_panel(
                fig.add_subplot(len(BEES), 3, 3 * row + 2 + col),
                fig,
                lon,
                lat,
                n,
                both_near,
                both_far,
                box,
                f"binocular field at {DISTANCES[0]:g} mm: facets of eye {eye}",
                cmap,
            )
    handles = [
        Patch(color=COLORS[1], label="seen by eye A (left) only"),
        Patch(color=COLORS[2], label="seen by eye B (right) only"),
        Patch(color=COLORS[3], label=f"seen by both (binocular), {DISTANCES[0]:g} mm"),
        Patch(
            facecolor="none", edgecolor="#e7298a", label=f"binocular field at {DISTANCES[1]:g} mm"
        ),
    ]
    fig.legend(handles=handles, loc="lower center", ncol=4, fontsize=9, frameon=False)
    fig.suptitle(
        f"Which directions each eye sees: balls of angular radius {BALL:g} deg at "
        f"{DISTANCES[0]:g} mm (fill) and {DISTANCES[1]:g} mm (outline); seen = at least 2 "
        "facets lit",
        fontsize=11,
    )
    fig.tight_layout(rect=(0, 0.03, 1, 0.97))
    fig.savefig(args.output, dpi=110)
    print(f"wrote {args.output}")


if __name__ == "__main__":
    main()
