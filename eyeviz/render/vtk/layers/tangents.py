"""``tangents``: the selected feature's tangents from each eye centre to the tangent points
(:class:`eyeviz.model.frame.TangentFrame`, Prop. 2, Figure 3b), in the main view and the
inset, and their angles as a screen-space note under the title (never over the rays)."""

from __future__ import annotations

import math

import numpy as np
import pyvista as pv

from eyeviz.model.frame import Frame
from eyeviz.render.vtk.primitives import actor, screen_text, write_points
from eyeviz.render.vtk.style import INK, Z_LINE, halo

__all__ = ["TangentsLayer"]


class TangentsLayer:
    """The selected feature's four tangent segments, eye centre -> tangent point (one mesh,
    its points written in place)."""

    def __init__(self, main, inset):
        self.z = Z_LINE
        self.mesh = pv.PolyData(np.zeros((6, 3)), lines=[2, 0, 1, 2, 0, 2, 2, 3, 4, 2, 3, 5])
        self.text = ""
        self.shown = False
        self.actors = []
        for ren in (main, inset):
            a = actor(self.mesh, INK)
            a.GetProperty().SetLineWidth(2.5)
            ren.AddActor(a)
            self.actors.append(a)
        self.text_actor = screen_text(20, INK, (0.015, 0.90), top=True)
        halo(self.text_actor.GetTextProperty())  # rays panned under it never cross it
        main.AddViewProp(self.text_actor)

    def draw(self, frame: Frame, selected: int | None) -> None:
        ok = selected is not None and 0 <= selected < frame.n and "tangents" in frame.layers
        show = ok and self.update(frame, selected)
        for a in self.actors:
            a.SetVisibility(show)
        self.text_actor.SetVisibility(show and bool(self.text))
        if show and self.text:
            self.text_actor.SetInput(self.text)

    def update(self, frame: Frame, selected: int | None) -> bool:
        """Write the points; returns whether there is anything to show."""
        tans = [t for t in frame.tangents if t.feature == selected]
        pts = np.zeros((6, 3))
        pts[:, 2] = self.z
        for e, eye in enumerate(("A", "B")):
            center = frame.pair.centers[e]
            pts[3 * e : 3 * e + 3, :2] = center
            for t in tans:
                if t.eye == eye:
                    pts[3 * e + 1 : 3 * e + 3, :2] = t.ends
        write_points(self.mesh, pts)
        self.shown = bool(tans)
        if len(tans) == 2:
            a, b = (math.degrees(t.alpha) for t in sorted(tans, key=lambda t: t.eye))
            self.text = f"tangents: arcsin(g/r_A) = {a:.2f}°,  arcsin(g/r_B) = {b:.2f}°"
        else:
            self.text = ""
        return self.shown
