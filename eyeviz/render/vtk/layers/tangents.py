"""``tangents``: the selected feature's tangents from each eye centre to the tangent points
(:class:`eyeviz.model.frame.TangentFrame`, Prop. 2, Figure 3b) and their angles as text."""

from __future__ import annotations

import math

import numpy as np
import pyvista as pv

from eyeviz.model.frame import Frame
from eyeviz.render.vtk.primitives import write_points

__all__ = ["TangentPainter"]


class TangentPainter:
    """The selected feature's four tangent segments, eye centre -> tangent point."""

    def __init__(self, z: float):
        self.z = z
        self.mesh = pv.PolyData(np.zeros((6, 3)), lines=[2, 0, 1, 2, 0, 2, 2, 3, 4, 2, 3, 5])
        self.text = ""
        self.shown = False

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
