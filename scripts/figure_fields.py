"""The two 3D binocular fields, wedge and both-eyes, on one picture (docs/img/fields3d.png).

Draws balls as Algorithm 1 in 3D does (r and g as its steps 7-11, the elevation uniform in
the band, the azimuth uniform in front), keeps those lighting at least two facets of each
eye, and marks which field each lies in: the wedge (``EyePair3D.in_bfv``, the data sets'
default) and both-eyes (touching neither eye, the centre hidden by neither eye,
``eyeviz generate --field both-eyes``). Prints the share of both-eyes balls outside the
wedge.

    .venv/bin/python scripts/figure_fields.py [--nside 180] [--n 20000] [-o docs/img/fields3d.png]
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

import numpy as np

from eyeviz.core.domain import Domain3D
from eyeviz.dataset.algorithm1_3d import _sight_clear
from eyeviz.dataset.records import spherical_to_xyz


def classify(d: Domain3D, n: int, seed: int):
    rng = np.random.default_rng(seed)
    u = rng.random((4, n))
    r = d.r_min + (d.r_max - d.r_min) * u[0]
    g_min = r * math.sin(d.gamma / 2)
    g = g_min + (d.g_max - g_min) * u[1]
    keep = (g_min <= d.g_max) & (g <= r)
    r, g, u = r[keep], g[keep], u[:, keep]
    el = d.el_max * (2 * u[2] - 1)
    az = math.pi * u[3]
    x, y, z = spherical_to_xyz(r, az, el)
    eyes = d.eyes
    (pa, _), (pb, _) = eyes.lit_csr(x, y, z, g)
    seen = (np.diff(pa) >= 2) & (np.diff(pb) >= 2)
    wedge = np.asarray(eyes.in_bfv(x, y, z, g), bool) & seen
    ta, tb = eyes.overlaps_eye(x, y, z, g)
    clear = _sight_clear(x, y, z, -d.h, d.h, d.l) & _sight_clear(x, y, z, d.h, -d.h, d.l)
    both = seen & ~(np.asarray(ta, bool) | np.asarray(tb, bool)) & clear
    return np.degrees(az), np.degrees(el), wedge, both


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--nside", type=int, default=180)
    ap.add_argument("--n", type=int, default=20000)
    ap.add_argument("--seed", type=int, default=2026120204)
    ap.add_argument("-o", type=Path, default=Path("docs/img/fields3d.png"))
    a = ap.parse_args()
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    d = Domain3D(nside=a.nside)
    az, el, wedge, both = classify(d, a.n, a.seed)
    outside = both & ~wedge
    share = outside.sum() / max(1, both.sum())
    se = math.sqrt(share * (1 - share) / max(1, both.sum()))
    print(
        f"nside {a.nside}: {int(both.sum())} of {az.size} balls in front lie in the both-eyes "
        f"field, {int(wedge.sum())} in the wedge; {100 * share:.1f} ± {100 * se:.1f} % of the "
        f"both-eyes balls are outside the wedge; wedge balls outside both-eyes: "
        f"{int((wedge & ~both).sum())}"
    )
    fig, ax = plt.subplots(figsize=(7.5, 4.2), constrained_layout=True)
    ax.scatter(az[wedge & both], el[wedge & both], s=2, color="#9ecae1", label="in both fields")
    ax.scatter(az[outside], el[outside], s=3, color="#d62728",
               label=f"both-eyes only ({100 * share:.1f} % of both-eyes)")  # fmt: skip
    only_w = wedge & ~both
    if only_w.any():
        ax.scatter(az[only_w], el[only_w], s=3, color="black", label="wedge only")
    ax.set_xlim(0, 180)
    ax.set_ylim(-math.degrees(d.el_max), math.degrees(d.el_max))
    ax.set_xlabel("azimuth of the ball's centre (degrees; 90 = straight ahead)")
    ax.set_ylabel("elevation (degrees)")
    ax.set_title(
        f"Which balls both eyes see (nside {a.nside}, h = {d.h:g}, l = {d.l:g}): the wedge "
        "against 'both-eyes'",
        fontsize=10,
    )
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.16), ncol=3, fontsize=8,
              markerscale=4, frameon=False)  # fmt: skip
    a.o.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(a.o, dpi=150)
    print(f"wrote {a.o}")


if __name__ == "__main__":
    main()
