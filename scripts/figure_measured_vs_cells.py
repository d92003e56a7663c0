"""Figure: a HEALPix eye's lit sets against its measured version's (docs/eye_files.md).

For a HEALPix pair (nside 8, h 40, l 20) and ``as_measured`` of it (one acceptance cone
per cell: lens on the eye's surface, axis through the cell's centre, full acceptance
sqrt(4 pi / npix)), four balls in front of eye A, each on a Mollweide map of eye A's
directions: the cells both models light, the cells only the cell model lights (lost by
the cones), and those only the cones light (gained), with each lit facet's acceptance
disc and the ball's angular disc seen from the eye centre.

Run: ``python scripts/figure_measured_vs_cells.py [-o docs/img/measured_vs_cells.png]``
"""

from __future__ import annotations

import argparse
import math
import os

import numpy as np

os.environ.setdefault("MPLBACKEND", "Agg")

import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.lines import Line2D  # noqa: E402
from matplotlib.patches import Patch, Polygon  # noqa: E402

from eyeviz.core import healpix  # noqa: E402
from eyeviz.core.geometry3d import EyePair3D  # noqa: E402
from eyeviz.core.measured_from import as_measured, healpix_width  # noqa: E402

NSIDE, H, L = 8, 40.0, 20.0
COLORS = {"both": "#4c72b0", "cell": "#dd8452", "cone": "#55a868"}


def lonlat(v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Mollweide coordinates of directions: longitude 0 forward (+y), +90 deg towards
    eye B (+x, right), latitude up (+z)."""
    v = v / np.linalg.norm(v, axis=-1, keepdims=True)
    return np.arctan2(v[..., 0], v[..., 1]), np.arcsin(np.clip(v[..., 2], -1, 1))


def local_map(a: np.ndarray):
    """Azimuthal equidistant map (degrees) centred on direction ``a``, seen from the eye
    centre: up is towards +z, right towards +x for a forward direction."""
    a = a / np.linalg.norm(a)
    e1 = np.cross(a, [0.0, 0.0, 1.0])
    e1 = e1 / np.linalg.norm(e1) if np.linalg.norm(e1) > 1e-9 else np.array([1.0, 0, 0])
    e2 = np.cross(e1, a)

    def proj(v: np.ndarray) -> np.ndarray:
        v = v / np.linalg.norm(v, axis=-1, keepdims=True)
        ang = np.degrees(np.arccos(np.clip(v @ a, -1, 1)))
        bearing = np.arctan2(v @ e1, v @ e2)
        return np.column_stack([ang * np.sin(bearing), ang * np.cos(bearing)])

    return proj


def circle(axis: np.ndarray, radius: float, n: int = 60) -> np.ndarray:
    """Unit vectors at angle ``radius`` around ``axis``."""
    a = axis / np.linalg.norm(axis)
    t = np.cross(a, [0.0, 0.0, 1.0] if abs(a[2]) < 0.9 else [1.0, 0.0, 0.0])
    t /= np.linalg.norm(t)
    b = np.cross(a, t)
    s = np.linspace(0, 2 * math.pi, n)
    return math.cos(radius) * a + math.sin(radius) * (
        np.cos(s)[:, None] * t + np.sin(s)[:, None] * b
    )


def balls() -> list[tuple[str, tuple[float, float, float, float]]]:
    """Three balls about eye A (centre (-40, 0, 0)), chosen to show each effect."""
    ca = np.array([-H, 0.0, 0.0])
    corner = healpix.boundaries(NSIDE, [healpix.vec2pix_ring(NSIDE, 0.3, 1.0, 0.2)])[0][0]
    out = []
    for label, d, dist, g in (
        ("far, small, on a cell corner", corner, 400.0, 6.0),
        ("far, larger", np.array([0.2, 1.0, 0.35]), 500.0, 45.0),
        ("near the eye", np.array([-0.3, 1.0, -0.2]), 45.0, 4.0),
    ):
        c = ca + dist * d / np.linalg.norm(d)
        out.append((label, (float(c[0]), float(c[1]), float(c[2]), g)))
    return out


def panel(ax, cells: EyePair3D, cones, label: str, ball) -> None:
    x, y, z, g = ball
    lit_cell = set(cells.lit(x, y, z, g)[0].tolist())
    lit_cone = set(cones.lit(x, y, z, g)[0].tolist())
    c = np.array([x + H, y, z])
    proj = local_map(c)
    rad = math.asin(min(g / np.linalg.norm(c), 1.0))
    half = healpix_width(NSIDE) / 2
    span = max(math.degrees(rad) * 1.6, 12.0)
    centers = healpix.centers(NSIDE)
    near = np.flatnonzero(centers @ (c / np.linalg.norm(c)) > math.cos(math.radians(span * 2)))
    bounds = healpix.boundaries(NSIDE, near, step=4)
    for p, b in zip(near.tolist(), bounds, strict=True):
        kind = None
        if p in lit_cell or p in lit_cone:
            kind = (
                "both" if p in lit_cell and p in lit_cone else ("cell" if p in lit_cell else "cone")
            )
        face = COLORS[kind] if kind else "none"
        ax.add_patch(Polygon(proj(b), closed=True, facecolor=face, edgecolor="#999999", lw=0.5))
        ax.add_patch(
            Polygon(
                proj(circle(centers[p], half)),
                closed=True,
                facecolor="none",
                edgecolor="k" if p in lit_cone else "#bbbbbb",
                lw=0.9 if p in lit_cone else 0.4,
            )
        )
    ax.add_patch(
        Polygon(
            proj(circle(c, rad)),
            closed=True,
            facecolor="none",
            edgecolor="#c44e52",
            lw=1.4,
            ls="--",
        )
    )
    ax.plot([0], [0], "+", color="#c44e52", ms=7)
    ax.set_xlim(-span, span)
    ax.set_ylim(-span, span)
    ax.set_aspect("equal")
    ax.tick_params(labelsize=7)
    both = len(lit_cell & lit_cone)
    ax.set_title(
        f"{label}\nball ({x:.0f}, {y:.0f}, {z:.0f}), g {g:.3g}\ncells {len(lit_cell)}, "
        f"cones {len(lit_cone)} ({both} both, {len(lit_cell - lit_cone)} lost, "
        f"{len(lit_cone - lit_cell)} gained)",
        fontsize=8,
    )
    return c


def overview(ax, dirs) -> None:
    """The four balls' directions on a Mollweide map of eye A's whole sphere."""
    cells = healpix.boundaries(NSIDE, np.arange(healpix.npix(NSIDE)), step=2)
    for b in cells:
        lon, lat = lonlat(b)
        if np.ptp(lon) < math.pi:
            ax.plot(np.append(lon, lon[0]), np.append(lat, lat[0]), color="#cccccc", lw=0.3)
    for k, d in enumerate(dirs, start=1):
        lon, lat = lonlat(d)
        ax.plot(float(lon), float(lat), "o", color="#c44e52", ms=4)
        ax.annotate(
            str(k),
            (float(lon), float(lat)),
            xytext=(4, 3),
            textcoords="offset points",
            fontsize=8,
            color="#c44e52",
        )
    ax.set_xticklabels([])
    ax.set_yticklabels([])
    ax.set_title(
        "the balls' directions from eye A's centre\n(Mollweide; forward in the middle, "
        "towards eye B right)",
        fontsize=8,
    )


def summary(cells: EyePair3D, cones, n: int = 2000):
    """How often the lit sets differ over random balls about eye A, and the smallest
    ball there whose cones gain a facet."""
    rng = np.random.default_rng(1)
    d = rng.normal(size=(n, 3))
    d /= np.linalg.norm(d, axis=1)[:, None]
    dist = 10 ** rng.uniform(math.log10(25), 3, n)
    c = np.array([-H, 0.0, 0.0]) + d * dist[:, None]
    g = dist * np.sin(rng.uniform(0.01, 0.15, n))
    (pa, ia), _ = cells.lit_csr(c[:, 0], c[:, 1], c[:, 2], g)
    (pb, ib), _ = cones.lit_csr(c[:, 0], c[:, 1], c[:, 2], g)
    same = lost = gained = 0
    zc = healpix.centers(NSIDE)[:, 2]
    gain_z = [1.0]
    gain_ball, gain_size = None, 10**9
    for k in range(n):
        a, b = set(ia[pa[k] : pa[k + 1]].tolist()), set(ib[pb[k] : pb[k + 1]].tolist())
        same += a == b
        lost += len(a - b)
        gained += len(b - a)
        gain_z += [abs(float(zc[p])) for p in b - a]
        if b - a and 0 < len(a) < gain_size:
            gain_ball, gain_size = (*map(float, c[k]), float(g[k])), len(a)
    cell_total = int(pa[-1])
    text = (
        f"{n} random balls about eye A\n(distance 25 to 1000 from its centre,\n"
        f"angular radius 0.6 to 8.6 deg):\n"
        f"same lit set for {100 * same / n:.0f} % of the balls;\n"
        f"{lost} of {cell_total} lit cells ({100 * lost / cell_total:.0f} %) lost;\n"
        f"{gained} cones gained ({100 * gained / cell_total:.1f} %), "
        f"\n(all in cells with |z| >= {min(gain_z):.3f})"
    )
    return text, gain_ball


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("-o", "--output", default="docs/img/measured_vs_cells.png")
    args = ap.parse_args()
    cells = EyePair3D(H, L, NSIDE)
    cones = as_measured(cells)
    fig = plt.figure(figsize=(11, 7.4), dpi=150)
    grid = fig.add_gridspec(
        2, 3, left=0.04, right=0.98, top=0.86, bottom=0.06, wspace=0.3, hspace=0.35
    )
    slots = [grid[0, 1], grid[0, 2], grid[1, 0], grid[1, 1]]
    text, gain = summary(cells, cones)
    shown = [*balls(), ("polar cap, where cells are stretched: a gain", gain)]
    dirs = []
    for k, (slot, (label, ball)) in enumerate(zip(slots, shown, strict=True), start=1):
        dirs.append(panel(fig.add_subplot(slot), cells, cones, f"{k}. {label}", ball))
    overview(fig.add_subplot(grid[0, 0], projection="mollweide"), dirs)
    handles = [
        Patch(facecolor=COLORS["both"], edgecolor="#999999", label="cell lit in both models"),
        Patch(facecolor=COLORS["cell"], edgecolor="#999999", label="cell model only (lost)"),
        Patch(facecolor=COLORS["cone"], edgecolor="#999999", label="cone model only (gained)"),
        Line2D([], [], color="k", lw=0.9, label="acceptance disc of a lit cone"),
        Line2D([], [], color="#bbbbbb", lw=0.5, label="acceptance disc, not lit"),
        Line2D([], [], color="#c44e52", ls="--", label="the ball seen from the eye centre"),
    ]
    lax = fig.add_subplot(grid[1, 2])
    lax.axis("off")
    lax.legend(handles=handles, loc="upper left", fontsize=8, frameon=False)
    lax.text(0.0, 0.45, text, fontsize=8, transform=lax.transAxes, va="top")
    fig.suptitle(
        f"Eye A of a HEALPix pair (nside {NSIDE}, h {H:g}, l {L:g}): cells vs acceptance cones "
        f"of width sqrt(4 pi / npix) = {math.degrees(healpix_width(NSIDE)):.2f} deg\n"
        "panels 1-4: directions from the eye centre around each ball (azimuthal, degrees; "
        "up is +z)",
        fontsize=9,
    )
    fig.savefig(args.output)
    print(f"wrote {args.output}")


if __name__ == "__main__":
    main()
