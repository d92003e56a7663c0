"""``posterior``: each feature's posterior over centres given its bitmaps, over every g they
allow (:attr:`Frame.posterior`, :mod:`eyeviz.model.posterior`), as translucent polar cells
shaded by density (darker: likelier) over the ambiguity region (whose outline is redrawn
on top), and the limit's estimate
(the MAPE-optimal median, Eq. 34) as a small diamond. Colours from
:mod:`eyeviz.model.palette` (the limit's)."""

from __future__ import annotations

import numpy as np
from matplotlib.colors import ListedColormap
from matplotlib.lines import Line2D
from matplotlib.patches import Patch, Polygon

from eyeviz.model.palette import POSTERIOR_COLOR, posterior_rgba
from eyeviz.render.mpl.canvas import Canvas
from eyeviz.render.mpl.style import dark, legend, slug

Z_POSTERIOR = 8.6  # over the ambiguity region (8.5), under its centre mark and predictions


def paint(cv: Canvas) -> None:
    fr, ax = cv.frame, cv.ax
    drawn = False
    for i, post in fr.posterior.items():
        if post is None or post.empty:
            continue
        _cells(ax, post, f"posterior-{slug(fr.names[i])}")
        reg = fr.ambiguity.get(i) if "ambiguity" in fr.layers else None
        if reg is not None and len(reg["polygon"]) >= 3:
            # the feature's own-g region stays sharp over the posterior
            edge = Polygon(
                reg["polygon"],
                closed=True,
                facecolor="none",
                edgecolor=dark(fr.colors[i]),
                lw=0.6,
                zorder=Z_POSTERIOR + 0.02,
            )
            edge.set_gid(f"posterior-ambiguity-{slug(fr.names[i])}")
            ax.add_patch(edge)
        ex, ey = post.estimate
        ax.plot(
            [ex],
            [ey],
            marker="D",
            ms=2.6,
            mew=0.5,
            mfc="white",
            color=POSTERIOR_COLOR,
            zorder=Z_POSTERIOR + 0.05,
            gid=f"posterior-estimate-{slug(fr.names[i])}",
        )
        drawn = True
    if drawn:
        _legend(ax)


def _cells(ax, post, gid: str) -> None:
    """The density on the polar grid as one mesh (no seams between translucent cells)."""
    if post.grid.size == 0:  # a sliver between the grid's centres: its points
        ax.scatter(post.x, post.y, s=1, c=posterior_rgba(post.density), lw=0, zorder=Z_POSTERIOR)
        return
    rr, pp = np.meshgrid(post.r_edges, post.phi_edges, indexing="ij")
    cmap = ListedColormap(posterior_rgba(np.linspace(0.0, 1.0, 256)))  # masked: not drawn
    mesh = ax.pcolormesh(
        rr * np.cos(pp),
        rr * np.sin(pp),
        np.ma.masked_less_equal(post.grid, 0.0),
        cmap=cmap,
        vmin=0.0,
        vmax=1.0,
        shading="flat",
        antialiased=False,
        edgecolors="none",
        linewidth=0,
        zorder=Z_POSTERIOR,
    )
    mesh.set_gid(gid)
    mesh.sticky_edges.x[:] = []
    mesh.sticky_edges.y[:] = []


def _legend(ax) -> None:
    """Add the posterior's two entries to the view's legend (made by the predictions layer
    when it is on, else here), in the same style."""
    mine = [
        Patch(
            facecolor=posterior_rgba([0.6])[0],
            edgecolor="none",
            label="posterior of the centre (darker: likelier)",
        ),
        Line2D(
            [],
            [],
            ls="",
            marker="D",
            ms=2.6,
            mew=0.5,
            mfc="white",
            color=POSTERIOR_COLOR,
            label="limit's estimate",
        ),
    ]
    old = ax.get_legend()
    handles = list(old.legend_handles) if old is not None else []
    labels = [t.get_text() for t in old.get_texts()] if old is not None else []
    legend(ax, handles + mine, labels + [str(h.get_label()) for h in mine])
