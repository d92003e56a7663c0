"""``bfv``: the BFV wedge as the Frame clips it to the visible rectangle
(:func:`eyeviz.model.frame.clip_wedge`, Definition 2) and its two edges, in the main view
and the inset, in place: the mesh has a fixed number of points; unused slots collapse onto
a point. The view hands it a Frame clipped to what its cameras show (and a new one after a
zoom or a pan: :meth:`eyeviz.render.vtk.actors.SceneActors.fit_bfv`)."""

from __future__ import annotations

import numpy as np
import pyvista as pv

from eyeviz.model.frame import Frame
from eyeviz.render.vtk.primitives import actor, write_points
from eyeviz.render.vtk.style import BFV_FILL, BFV_LINE, Z_BFV, Z_LINE

__all__ = ["BFVLayer", "BFV_SLOTS"]

BFV_SLOTS = 8  # a rectangle cut by two half-planes has at most 6 vertices


class BFVLayer:
    """The BFV wedge clipped to a rectangle, filled, with its two edges; its actors are in
    the renderers only while the layer is shown."""

    def __init__(self, main, inset):
        self.renderers = (main, inset)
        self.z_fill, self.z_line = Z_BFV, Z_LINE
        k = np.arange(1, BFV_SLOTS - 1)
        faces = np.column_stack([np.full(k.size, 3), np.zeros(k.size, int), k, k + 1]).ravel()
        self.mesh = pv.PolyData(np.zeros((BFV_SLOTS, 3)), faces=faces)
        self.edges = pv.PolyData(np.zeros((4, 3)), lines=[2, 0, 1, 2, 2, 3])
        self.actors = []
        for ren in self.renderers:
            a = actor(self.mesh, BFV_FILL)
            b = actor(self.edges, BFV_LINE)
            b.GetProperty().SetLineWidth(2.5)
            self.actors.append((ren, a))
            self.actors.append((ren, b))
        self.shown = False
        self.polygon = np.zeros((0, 2))
        self._written: tuple | None = None

    def draw(self, frame: Frame, selected: int | None) -> None:
        shown = "bfv" in frame.layers and frame.bfv is not None
        if shown != self.shown:
            for ren, a in self.actors:
                if shown:
                    ren.AddActor(a)
                else:
                    ren.RemoveActor(a)
            self.shown = shown
        if shown:
            self.update(frame)

    def update(self, frame: Frame) -> None:
        """Write the wedge and its edges (nothing when they are what is drawn)."""
        bfv = frame.bfv
        key = None if bfv is None else (bfv.psi, bfv.rect)
        if key == self._written:  # the same wedge and rectangle (a drag): nothing to clip
            return
        self._written = key
        poly = np.zeros((0, 2)) if bfv is None else np.asarray(bfv.polygon)
        edges = [] if bfv is None else bfv.edges
        self.polygon = poly
        pts = np.zeros((BFV_SLOTS, 3))
        pts[:, 2] = self.z_fill
        if len(poly):
            pts[: len(poly), :2] = poly
            pts[len(poly) :, :2] = poly[-1]  # degenerate triangles fill the spare slots
        write_points(self.mesh, pts)
        ep = np.zeros((4, 3))
        ep[:, 2] = self.z_line
        for j, seg in enumerate(edges):
            if seg is not None:
                ep[2 * j] = (seg[0], seg[1], self.z_line)
                ep[2 * j + 1] = (seg[2], seg[3], self.z_line)
        write_points(self.edges, ep)
