"""The README's figure of the spherical eyes: each eye's HEALPix facets on a Mollweide map,
lit exactly by three balls (one on the plane z = 0, one above, one below), and the
equatorial ring of each eye beside the planar eye's bitmap for the same scene.

Run: ``.venv/bin/python scripts/figure_spherical.py [-o docs/img/spherical_eyes.png]``.
It asserts the reduction it draws: on z = 0 the equatorial ring is the planar bitmap.
"""

from __future__ import annotations

import argparse
import warnings
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure
from matplotlib.patches import Patch

from eyeviz.core.geometry import EyePair
from eyeviz.core.geometry3d import EyePair3D
from eyeviz.render.mpl.healpix_map import UNLIT, draw_eye_map

NSIDE = 8
BALLS = [  # (name, x, y, z, g, colour)
    ("on z = 0", 10.0, 160.0, 0.0, 22.0, "#d62728"),
    ("above", -70.0, 150.0, 110.0, 30.0, "#1f77b4"),
    ("below", 95.0, 120.0, -80.0, 25.0, "#2ca02c"),
]


def equator_row(eyes: EyePair3D, lit: list[np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """Owner (ball index, -1 unlit) of each facet of the equatorial ring, and its indices."""
    n = eyes.nside
    first = 2 * n * (n - 1) + 4 * n * n  # ring 2n from the north pole
    ring = np.arange(first, first + 4 * n)
    owner = np.full(4 * n, -1)
    for i, idx in enumerate(lit):
        owner[np.isin(ring, idx)] = i
    return owner, ring


def draw(out: Path) -> None:
    # matplotlib's Mollweide inverse warns on the copies of facets across the wrap,
    # which its outline clips anyway
    warnings.filterwarnings("ignore", "invalid value encountered in arcsin", RuntimeWarning)
    eyes = EyePair3D(40.0, 20.0, NSIDE)
    planar = EyePair(40.0, 20.0, 4 * NSIDE)
    colors = [b[5] for b in BALLS]
    fig = Figure(figsize=(9.0, 4.2), layout="constrained")
    grid = fig.add_gridspec(2, 2, height_ratios=[3.4, 1.0])
    for col, eye in enumerate("AB"):
        lit = [eyes.lit(x, y, z, g)[col] for _, x, y, z, g, _ in BALLS]
        ax = fig.add_subplot(grid[0, col], projection="mollweide")
        draw_eye_map(ax, NSIDE, lit, colors)
        ax.set_title(f"eye {eye}: {eyes.npix} facets (nside {NSIDE})", fontsize=9)
        for lon, label in ((-np.pi / 2, "back (-y)"), (0.0, "+x"), (np.pi / 2, "front (+y)")):
            # on the equator, Mollweide's x is linear in longitude
            ax.text(
                0.5 + lon / (2 * np.pi),
                -0.02,
                label,
                transform=ax.transAxes,
                ha="center",
                va="top",
                fontsize=7,
            )
        ax.text(-np.pi, 0.03, "  equator z = 0", fontsize=7, va="bottom")
        owner, _ring = equator_row(eyes, lit)
        x, y, g = (np.array([b[i] for b in BALLS if b[3] == 0.0]) for i in (1, 2, 4))
        omega = planar.bitmaps(x, y, g)[col].any(axis=0)
        assert np.array_equal(omega, owner == 0), "the equator must be the planar bitmap"
        bx = fig.add_subplot(grid[1, col])
        k = np.arange(4 * NSIDE)
        row_colors = [colors[o] if o >= 0 else UNLIT for o in owner]
        bx.bar(k, 1.0, 1.0, bottom=1.2, align="edge", color=row_colors, edgecolor="#999999", lw=0.3)
        flat = [colors[0] if v else UNLIT for v in omega]
        bx.bar(k, 1.0, 1.0, bottom=0.0, align="edge", color=flat, edgecolor="#999999", lw=0.3)
        bx.set_yticks([0.5, 1.7], ["planar m = 32", "equator ring"], fontsize=8)
        bx.set_xlim(0, 4 * NSIDE)
        bx.set_xlabel("ommatidium k (direction k·γ from +x)", fontsize=8)
        bx.tick_params(labelsize=7)
        for side in ("top", "right"):
            bx.spines[side].set_visible(False)
    fig.legend(
        [Patch(color=c) for c in colors],
        [f"ball {b[0]} (z = {b[3]:g})" for b in BALLS],
        loc="outside upper center",
        ncols=3,
        frameon=False,
        fontsize=8,
    )
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=150)
    print(f"wrote {out}")


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("-o", "--out", type=Path, default=Path("docs/img/spherical_eyes.png"))
    draw(p.parse_args().out)


if __name__ == "__main__":
    main()
