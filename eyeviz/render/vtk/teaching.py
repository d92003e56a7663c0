"""Painters of the teaching layers (Figures 3b, 5-6), drawing ONLY from a Frame.

- :class:`BfvPainter`: the BFV wedge as the Frame clips it to the visible rectangle
  (:func:`eyeviz.model.frame.clip_wedge`, Definition 2) and its two edges;
- :class:`TangentPainter`: the selected feature's tangents from each eye centre
  (:class:`eyeviz.model.frame.TangentFrame`, Prop. 2) and their angles as text;
- :class:`SectorPainter`: the boundary rays of its lit sectors
  (:class:`eyeviz.model.frame.SectorFrame`, Eq. 8, 11).

Nothing here computes geometry: every point is a Frame field. Meshes have a fixed number
of points and cells and are updated in place (``mesh.points[:] = ...``); unused slots
collapse onto a point.
"""

from __future__ import annotations

import math

import numpy as np
import pyvista as pv

from eyeviz.model.frame import WIDE_SECTOR, Frame

__all__ = ["BfvPainter", "SectorPainter", "TangentPainter", "BFV_SLOTS", "RAY_SLOTS"]

BFV_SLOTS = 8  # a rectangle cut by two half-planes has at most 6 vertices
RAY_SLOTS = WIDE_SECTOR + 1  # boundary rays per eye (L..R+1 for a run shorter than 24)


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
        self.mesh.points[:] = pts
        ep = np.zeros((4, 3))
        ep[:, 2] = self.z_line
        for j, seg in enumerate([] if bfv is None else bfv.edges):
            if seg is not None:
                ep[2 * j] = (seg[0], seg[1], self.z_line)
                ep[2 * j + 1] = (seg[2], seg[3], self.z_line)
        self.edges.points[:] = ep


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
        self.mesh.points[:] = pts
        self.shown = bool(tans)
        if len(tans) == 2:
            a, b = (math.degrees(t.alpha) for t in sorted(tans, key=lambda t: t.eye))
            self.text = f"tangents: arcsin(g/r_A) = {a:.2f}°,  arcsin(g/r_B) = {b:.2f}°"
        else:
            self.text = ""
        return self.shown


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
        gamma = frame.pair.gamma
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
                k = np.asarray(s.rays[:RAY_SLOTS], dtype=np.float64)
                self.rays[eye] = [int(v) for v in k]
                pts[c + 1 : c + 1 + k.size, 0] = center[0] + s.reach * np.cos(k * gamma)
                pts[c + 1 : c + 1 + k.size, 1] = center[1] + s.reach * np.sin(k * gamma)
        self.mesh.points[:] = pts
        self.shown = bool(secs)
        return self.shown
