"""``ambiguity``: the centres giving the same bitmaps (:attr:`Frame.ambiguity`)."""

from __future__ import annotations

from matplotlib.patches import Polygon

from eyeviz.render.mpl.canvas import Canvas
from eyeviz.render.mpl.style import INK, dark, mix, slug


def paint(cv: Canvas) -> None:
    fr = cv.frame
    for i, reg in fr.ambiguity.items():
        if reg is None or len(reg["polygon"]) < 3:
            continue
        col = fr.colors[i]
        poly = Polygon(
            reg["polygon"],
            closed=True,
            facecolor=mix(col, 0.3),
            edgecolor=dark(col),
            lw=0.6,
            hatch="//////",
            zorder=8.5,
            alpha=0.85,
        )
        poly.set_gid(f"ambiguity-{slug(fr.names[i])}")
        cv.ax.add_patch(poly)
        cv.ax.plot([fr.x[i]], [fr.y[i]], marker="+", ms=3.5, mew=0.6, color=INK, zorder=8.7)
