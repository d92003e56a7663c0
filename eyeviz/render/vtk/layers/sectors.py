"""``sectors``: the boundary rays k*gamma of the selected feature's lit sectors from each
eye (:class:`eyeviz.model.frame.SectorFrame`, Eq. 8, 11), dashed, in the main view and the
inset; points written in place."""

from __future__ import annotations

import numpy as np
import pyvista as pv

from eyeviz.model.frame import WIDE_SECTOR, Frame
from eyeviz.render.vtk.primitives import actor, write_points
from eyeviz.render.vtk.style import Z_LINE

__all__ = ["SectorsLayer", "RAY_SLOTS"]

RAY_SLOTS = WIDE_SECTOR + 1  # boundary rays per eye (L..R+1 for a run shorter than 24)


class SectorsLayer:
    """The boundary rays k*gamma of the selected feature's lit sectors, from each eye."""

    def __init__(self, main, inset):
        self.z = Z_LINE
        n = 2 * (1 + RAY_SLOTS)
        lines = []
        for e in range(2):
            c = e * (1 + RAY_SLOTS)
            for j in range(RAY_SLOTS):
                lines += [2, c, c + 1 + j]
        self.mesh = pv.PolyData(np.zeros((n, 3)), lines=lines)
        self.rays: dict[str, list[int]] = {}
        self.shown = False
        self.actors = []
        for ren in (main, inset):
            a = actor(self.mesh, (0.45, 0.45, 0.45))
            a.GetProperty().SetLineWidth(2.0)
            a.GetProperty().SetLineStipplePattern(0xFF00)
            ren.AddActor(a)
            self.actors.append(a)

    def draw(self, frame: Frame, selected: int | None) -> None:
        ok = selected is not None and 0 <= selected < frame.n and "sectors" in frame.layers
        show = ok and self.update(frame, selected)
        for a in self.actors:
            a.SetVisibility(show)

    def update(self, frame: Frame, selected: int | None) -> bool:
        """Write the points; returns whether there is anything to show."""
        secs = [s for s in frame.sectors if s.feature == selected]
        pts = np.zeros((2 * (1 + RAY_SLOTS), 3))
        pts[:, 2] = self.z
        self.rays = {}
        for e, eye in enumerate(("A", "B")):
            c = e * (1 + RAY_SLOTS)
            center = frame.pair.centers[e]
            pts[c : c + 1 + RAY_SLOTS, :2] = center
            for s in secs:
                if s.eye != eye:
                    continue
                self.rays[eye] = [int(v) for v in s.rays[:RAY_SLOTS]]
                ends = np.asarray(s.ends)[:RAY_SLOTS]
                pts[c + 1 : c + 1 + len(ends), :2] = ends
        write_points(self.mesh, pts)
        self.shown = bool(secs)
        return self.shown
