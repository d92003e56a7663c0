"""``sectors``: the boundary rays k*gamma of the selected feature's lit sectors from each
eye (:class:`eyeviz.model.frame.SectorFrame`, Eq. 8, 11), in place."""

from __future__ import annotations

import numpy as np
import pyvista as pv

from eyeviz.model.frame import WIDE_SECTOR, Frame
from eyeviz.render.vtk.primitives import write_points

__all__ = ["SectorPainter", "RAY_SLOTS"]

RAY_SLOTS = WIDE_SECTOR + 1  # boundary rays per eye (L..R+1 for a run shorter than 24)


class SectorPainter:
    """The boundary rays k*gamma of the selected feature's lit sectors, from each eye."""

    def __init__(self, z: float):
        self.z = z
        n = 2 * (1 + RAY_SLOTS)
        lines = []
        for e in range(2):
            c = e * (1 + RAY_SLOTS)
            for j in range(RAY_SLOTS):
                lines += [2, c, c + 1 + j]
        self.mesh = pv.PolyData(np.zeros((n, 3)), lines=lines)
        self.rays: dict[str, list[int]] = {}
        self.shown = False

    def update(self, frame: Frame, selected: int | None) -> bool:
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
