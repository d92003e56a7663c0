"""``sectors``: the ommatidium boundaries around each lit interval (Eq. 8, 11), from
:attr:`Frame.sectors` (rays at k * gamma)."""

from __future__ import annotations

import math

from matplotlib.patches import Wedge

from eyeviz.render.mpl.canvas import Canvas
from eyeviz.render.mpl.layers.tangents import taught
from eyeviz.render.mpl.style import GREY, HALO, SMALL, dark, slug


def paint(cv: Canvas) -> None:
    fr, p = cv.frame, cv.pair
    # one ray per eye and boundary k, as long as the longest sector that has it: features
    # sharing a boundary drew it once each (52 lines a feature, minutes for 10^3 features)
    rays: dict[tuple[str, int], tuple[tuple[float, float], float, int]] = {}
    drawn = taught(cv, [s.feature for s in fr.sectors], "without sectors")
    for s in fr.sectors:
        if s.feature not in drawn:
            continue
        for k in s.rays:
            key = (s.eye, k % p.m)
            if key not in rays or rays[key][1] < s.reach:
                rays[key] = (s.center, s.reach, k)
        col = fr.colors[s.feature]
        cx, cy = s.center
        th1, th2 = math.degrees(s.rays[0] * p.gamma), math.degrees(s.rays[-1] * p.gamma)
        for ax in cv.eye_axes():
            fan = Wedge(
                (cx, cy), s.reach, th1, th2, facecolor=col, alpha=0.06, edgecolor="none", zorder=1
            )
            fan.set_gid(f"sector-fan-{s.eye}-{slug(fr.names[s.feature])}")
            ax.add_patch(fan)
        _numbers(cv, s, dark(col))
    for ax in cv.eye_axes():
        for (eye, km), ((cx, cy), reach, k) in rays.items():
            a = k * p.gamma
            ax.plot(
                [cx, cx + reach * math.cos(a)],
                [cy, cy + reach * math.sin(a)],
                color=GREY,
                lw=0.35,
                ls=(0, (2.5, 1.5)),
                zorder=1.5,
                gid=f"sector-{eye}-{km}",
            )


def _numbers(cv: Canvas, s, col: str) -> None:
    """Number the lit ommatidia along their sectors when there is room (Figure 3b)."""
    p, ax, upi = cv.pair, cv.eye_ax, cv.eye_units_per_in
    rad = 1.3 * p.l
    if s.R - s.L > 12 or rad * p.gamma / upi * 72 < 6.5:
        return
    cx, cy = s.center
    for k in range(s.L, s.R + 1):
        a = (k + 0.5) * p.gamma
        ax.text(
            cx + rad * math.cos(a),
            cy + rad * math.sin(a),
            str(k % p.m),
            ha="center",
            va="center",
            fontsize=SMALL,
            color=col,
            zorder=6,
            bbox=HALO,
            gid=f"sector-number-{s.eye}-{k % p.m}",
        )
