"""``predictions``: each estimator's (r_hat, phi_hat) as a ghost disc joined to the truth,
from :attr:`Frame.predictions`, in the estimator's fixed colour (:mod:`eyeviz.model.palette`)."""

from __future__ import annotations

import math

from matplotlib.lines import Line2D
from matplotlib.patches import Circle

from eyeviz.model.frame import PredictionFrame
from eyeviz.model.palette import estimator_color
from eyeviz.render.mpl.canvas import Canvas
from eyeviz.render.mpl.style import OUT_OF_DOMAIN, legend, slug


def paint(cv: Canvas) -> None:
    fr, ax = cv.frame, cv.ax
    if not fr.n:
        return
    ood = fr.out_of_domain
    assert ood is not None  # build_frame always sets it
    handles = []
    for name, pred in fr.predictions.items():
        if not isinstance(pred, PredictionFrame):
            continue
        col = estimator_color(name)
        for i, fname in enumerate(fr.names):
            px, py = float(pred.x_hat[i]), float(pred.y_hat[i])
            if ood[i] or not (math.isfinite(px) and math.isfinite(py)):
                continue
            ax.plot(
                [fr.x[i], px],
                [fr.y[i], py],
                color=col,
                lw=0.7,
                zorder=9,
                gid=f"prediction-link-{slug(name)}-{slug(fname)}",
            )
            ghost = Circle(
                (px, py),
                float(fr.g[i]),
                facecolor="none",
                edgecolor=col,
                lw=0.9,
                ls=(0, (2.2, 1.2)),
                zorder=9,
            )
            ghost.set_gid(f"prediction-{slug(name)}-{slug(fname)}")
            ax.add_patch(ghost)
            ax.plot([px], [py], marker="x", ms=3, mew=0.7, color=col, zorder=9)
        handles.append(
            Line2D(
                [],
                [],
                color=col,
                lw=0.9,
                ls=(0, (2.2, 1.2)),
                marker="x",
                ms=3,
                mew=0.7,
                label=f"{name} (predicted)",
            )
        )
    if ood.any():
        handles.append(
            Line2D(
                [],
                [],
                color=OUT_OF_DOMAIN,
                lw=0,
                marker="o",
                ms=4,
                label="outside the networks' domain",
            )
        )
    if handles:
        legend(ax, handles)
