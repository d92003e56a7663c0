"""``tangents``: the tangent rays from each eye centre and arcsin(g/r_E) (Prop. 2, Fig. 3b).

Drawn from :attr:`Frame.tangents`; nothing is computed here but label placement.
"""

from __future__ import annotations

import math

from eyeviz.render.mpl.canvas import Canvas
from eyeviz.render.mpl.layout import MAX_TAUGHT, more_text
from eyeviz.render.mpl.style import HALO, SMALL, arc, dark, slug, subscripted


def taught(cv: Canvas, features: list[int], what: str) -> set[int]:
    """The first :data:`MAX_TAUGHT` of ``features`` (scene order) that a teaching layer
    draws; the rest are counted in a note ("... and N more without tangents")."""
    unique = sorted(set(features))
    if len(unique) > MAX_TAUGHT:
        cv.notes.append(more_text(len(unique) - MAX_TAUGHT, f"more {what}"))
    return set(unique[:MAX_TAUGHT])


def paint(cv: Canvas) -> None:
    fr = cv.frame
    rA, rB = fr.rA, fr.rB
    assert rA is not None and rB is not None  # the tangents layer needs the readout
    drawn = taught(cv, [t.feature for t in fr.tangents], "without tangents")
    for t in fr.tangents:
        i = t.feature
        if i not in drawn:
            continue
        col = dark(fr.colors[i])
        cx, cy = t.center
        name = slug(fr.names[i])
        for ax in cv.eye_axes():
            thin = ax is cv.ax and cv.inset is not None
            for end in t.ends:
                ax.plot(
                    [cx, cx + 1.04 * (end[0] - cx)],
                    [cy, cy + 1.04 * (end[1] - cy)],
                    color=col,
                    lw=0.35 if thin else 0.55,
                    alpha=0.8 if thin else 1.0,
                    zorder=7,
                    gid=f"tangent-{t.eye}-{name}",
                )
            if not thin:
                ax.plot([cx, fr.x[i]], [cy, fr.y[i]], color=col, lw=0.4, ls=(0, (3, 2)), zorder=7)
        # the angle arcsin(g/r_E) for the nearer eye, where it reads
        if (t.eye == "A") != (rA[i] < rB[i]):
            continue
        upi = cv.eye_units_per_in
        rad = min(0.5 * (t.r_e - fr.g[i]), 0.6 * upi)
        if t.alpha * rad / upi * 72 < 4:
            continue
        cv.eye_ax.add_patch(
            arc(
                rad,
                math.degrees(t.phi_e),
                math.degrees(t.phi_e + t.alpha),
                col,
                f"tangent-angle-{t.eye}-{name}",
                center=(cx, cy),
            )
        )
        mid = t.phi_e + t.alpha / 2
        subscripted(
            cv.eye_ax,
            cx + 1.1 * rad * math.cos(mid),
            cy + 1.1 * rad * math.sin(mid),
            [
                ("arcsin(g / r", False),
                (t.eye, True),
                (f") = {math.degrees(t.alpha):.1f}\u00b0", False),
            ],
            SMALL,
            "right" if math.cos(mid) < 0 else "left",
            col,
            gid=f"tangent-angle-label-{t.eye}-{name}",
            zorder=9,
            bbox=HALO,
        )
