"""``bfv``: the BFV wedge as the Frame clips it to the visible rectangle
(:func:`eyeviz.model.frame.clip_wedge`, Definition 2) and its two edges, in place: the mesh
has a fixed number of points; unused slots collapse onto a point."""

from __future__ import annotations

import numpy as np
import pyvista as pv

from eyeviz.model.frame import Frame
from eyeviz.render.vtk.primitives import write_points

__all__ = ["BfvPainter", "BFV_SLOTS"]

BFV_SLOTS = 8  # a rectangle cut by two half-planes has at most 6 vertices


class BfvPainter:
    """The BFV wedge clipped to a rectangle, filled, with its two edges."""

    def __init__(self, renderers, fill, line, z_fill: float, z_line: float, make_actor):
        self.z_fill, self.z_line = z_fill, z_line
        k = np.arange(1, BFV_SLOTS - 1)
        faces = np.column_stack([np.full(k.size, 3), np.zeros(k.size, int), k, k + 1]).ravel()
        self.mesh = pv.PolyData(np.zeros((BFV_SLOTS, 3)), faces=faces)
        self.edges = pv.PolyData(np.zeros((4, 3)), lines=[2, 0, 1, 2, 2, 3])
        self.actors = []
        for ren in renderers:
            a = make_actor(self.mesh, fill)
            b = make_actor(self.edges, line)
            b.GetProperty().SetLineWidth(2.5)
            self.actors.append((ren, a))
            self.actors.append((ren, b))
        self.polygon = np.zeros((0, 2))

    def update(self, frame: Frame) -> None:
        bfv = frame.bfv
        poly = np.zeros((0, 2)) if bfv is None else np.asarray(bfv.polygon)
        self.polygon = poly
        pts = np.zeros((BFV_SLOTS, 3))
        pts[:, 2] = self.z_fill
        if len(poly):
            pts[: len(poly), :2] = poly
            pts[len(poly) :, :2] = poly[-1]  # degenerate triangles fill the spare slots
        write_points(self.mesh, pts)
        ep = np.zeros((4, 3))
        ep[:, 2] = self.z_line
        for j, seg in enumerate([] if bfv is None else bfv.edges):
            if seg is not None:
                ep[2 * j] = (seg[0], seg[1], self.z_line)
                ep[2 * j + 1] = (seg[2], seg[3], self.z_line)
        write_points(self.edges, ep)
