"""``trajectory``: the animated feature's path (Frame ``trajectory``, Figure 14)."""

from __future__ import annotations

import numpy as np
import pyvista as pv

from eyeviz.model.frame import Frame
from eyeviz.render.vtk.primitives import actor, set_input
from eyeviz.render.vtk.style import INK, Z_LINE

__all__ = ["TrajectoryLayer"]


class TrajectoryLayer:
    """The path as one polyline, in the main view (rebuilt when the path changes)."""

    def __init__(self, main, inset):
        self.path_actor = actor(pv.PolyData(), INK)
        self.path_actor.GetProperty().SetLineWidth(2.5)
        self.actors = (self.path_actor,)
        self.path_actor.SetVisibility(False)
        main.AddActor(self.path_actor)
        self.mesh: pv.PolyData | None = None
        self._key: tuple | None = None

    def draw(self, frame: Frame, selected: int | None) -> None:
        self.update(frame)

    def update(self, frame: Frame) -> None:
        path = frame.trajectory
        ok = "trajectory" in frame.layers and path is not None and path.n >= 2
        self.path_actor.SetVisibility(ok)
        if not ok or path is None:
            return
        key = (id(path), path.x.tobytes(), path.y.tobytes())
        if key == self._key:
            return
        self._key = key
        pts = np.column_stack([path.x, path.y, np.full(path.n, Z_LINE - 0.2)])
        self.mesh = pv.PolyData(pts, lines=np.concatenate([[path.n], np.arange(path.n)]))
        set_input(self.path_actor, self.mesh)
