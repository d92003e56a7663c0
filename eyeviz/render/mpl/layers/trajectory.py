"""``trajectory``: the Figure 14 path (:attr:`Frame.trajectory`) with its direction."""

from __future__ import annotations

from eyeviz.render.mpl.canvas import Canvas
from eyeviz.render.mpl.style import INK


def paint(cv: Canvas) -> None:
    t = cv.frame.trajectory
    if t is None or t.n < 2:
        return
    x, y = t.x, t.y
    cv.ax.plot(x, y, color=INK, lw=0.7, ls=(0, (4, 2)), zorder=6.5, gid=f"trajectory-{t.kind}")
    back = min(8, t.n)
    cv.ax.annotate(
        "",
        xy=(x[-1], y[-1]),
        xytext=(x[-back], y[-back]),
        arrowprops=dict(arrowstyle="-|>", lw=0.7, color=INK, mutation_scale=6),
        zorder=6.5,
    )
