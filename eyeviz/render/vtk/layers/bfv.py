"""``bfv``: the BFV wedge as the Frame clips it to the visible rectangle
(:func:`eyeviz.model.frame.clip_wedge`, Definition 2) and its two edges, in the main view
and the inset, in place: the mesh has a fixed number of points; unused slots collapse onto
a point. The view hands it a Frame clipped to what its cameras show (and a new one after a
zoom or a pan: :meth:`eyeviz.render.vtk.actors.SceneActors.fit_bfv`).

Where the origin is in view, the main view also draws the BFV's angles as the exported
figure does (Definition 2, Figures 5-6): theta's arc between the two edges with its label
above it, psi's arc between the x-axis and the right edge with its label beside it, at a
fifth of the view's height, clear of the eyes where they are large."""

from __future__ import annotations

import math

import numpy as np
import pyvista as pv

from eyeviz.model.frame import Frame
from eyeviz.render.vtk.primitives import actor, text3d, write_points
from eyeviz.render.vtk.style import BFV_FILL, BFV_LINE, Z_BFV, Z_LINE

__all__ = ["ANGLE_LABEL_PX", "ARC_POINTS", "BFVLayer", "BFV_SLOTS", "angle_marks"]

BFV_SLOTS = 8  # a rectangle cut by two half-planes has at most 6 vertices
ARC_POINTS = 49  # points of each angle's arc
ANGLE_LABEL_PX = 18


def angle_marks(psi: float, h: float, rect: tuple[float, float, float, float]) -> dict | None:
    """Where theta's and psi's arcs and labels go in ``rect`` (x0, x1, y0, y1), or None when
    the origin is not in it: {"theta": (N, 2) arc, "psi": (N, 2) arc, "axis": x-axis
    segment, "theta_at" / "psi_at": label anchors}. theta = pi - 2 psi (Eq. 16)."""
    x0, x1, y0, y1 = rect
    if not (x0 <= 0.0 <= x1 and y0 <= 0.0 <= y1):
        return None
    reach = h * (1.0 + math.sin(psi))  # h + l (psi = arcsin(l / h)): the eyes' outer edge
    rad = max(0.2 * (y1 - y0), 1.5 * reach)
    rpsi = max(0.72 * rad, 1.15 * reach)  # both arcs clear the eyes where they are large
    t = np.linspace(psi, math.pi - psi, ARC_POINTS)
    u = np.linspace(0.0, psi, ARC_POINTS)
    return {
        "theta": np.column_stack([rad * np.cos(t), rad * np.sin(t)]),
        "psi": np.column_stack([rpsi * np.cos(u), rpsi * np.sin(u)]),
        "axis": np.array([[0.0, 0.0], [1.3 * rpsi, 0.0]]),
        "theta_at": (0.0, 1.04 * rad),
        "psi_at": (1.08 * rpsi * math.cos(psi / 2), 1.08 * rpsi * math.sin(psi / 2)),
    }


class BFVLayer:
    """The BFV wedge clipped to a rectangle, filled, with its two edges; its actors are in
    the renderers only while the layer is shown."""

    def __init__(self, main, inset):
        self.renderers = (main, inset)  # main first: the angles' labels are placed in it
        self.z_fill, self.z_line = Z_BFV, Z_LINE
        k = np.arange(1, BFV_SLOTS - 1)
        faces = np.column_stack([np.full(k.size, 3), np.zeros(k.size, int), k, k + 1]).ravel()
        self.mesh = pv.PolyData(np.zeros((BFV_SLOTS, 3)), faces=faces)
        self.edges = pv.PolyData(np.zeros((4, 3)), lines=[2, 0, 1, 2, 2, 3])
        self.actors: list[tuple] = []  # (renderer, an actor or a 3D text)
        for ren in self.renderers:
            a = actor(self.mesh, BFV_FILL)
            b = actor(self.edges, BFV_LINE)
            b.GetProperty().SetLineWidth(2.5)
            self.actors.append((ren, a))
            self.actors.append((ren, b))
        # theta and psi in the main view (the inset's footer line names them)
        n = ARC_POINTS
        lines = np.r_[n, np.arange(n), n, np.arange(n, 2 * n), 2, 2 * n, 2 * n + 1]
        self.arcs = pv.PolyData(np.zeros((2 * n + 2, 3)), lines=lines)
        self.arc_actor = actor(self.arcs, BFV_LINE)
        self.arc_actor.GetProperty().SetLineWidth(2.0)
        self.theta_label = text3d(ANGLE_LABEL_PX, BFV_LINE)
        self.psi_label = text3d(ANGLE_LABEL_PX, BFV_LINE)
        for lab in (self.theta_label, self.psi_label):
            tp = lab.GetTextProperty()
            tp.SetBackgroundColor(1.0, 1.0, 1.0)
            tp.SetBackgroundOpacity(0.75)  # a halo: the label reads over a disc
        self.theta_label.GetTextProperty().SetJustificationToCentered()
        self.psi_label.GetTextProperty().SetVerticalJustificationToCentered()
        for part in (self.arc_actor, self.theta_label, self.psi_label):
            self.actors.append((main, part))
        self.shown = False
        self.polygon = np.zeros((0, 2))
        self._written: tuple | None = None
        self._marks: dict | None = None
        self._psi_side = 1.0
        empty = np.zeros(0)
        self._obstacles: tuple = (empty, empty, empty, [], False)  # the last Frame's features
        self._name_chars: tuple[list[str], np.ndarray] = ([], empty)  # names, len + 1 each

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
            self.place_angle_labels(frame)

    def update(self, frame: Frame) -> None:
        """Write the wedge and its edges (nothing when they are what is drawn)."""
        bfv = frame.bfv
        key = None if bfv is None else (bfv.psi, bfv.rect, frame.pair.h)
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
        marks = None if bfv is None else angle_marks(bfv.psi, frame.pair.h, bfv.rect)
        self._marks = marks
        for a in (self.arc_actor, self.theta_label, self.psi_label):
            a.SetVisibility(marks is not None)
        if marks is None or bfv is None:
            return
        self.theta_label.SetInput(f"\u03b8 = {math.degrees(bfv.theta):.0f}\u00b0")
        self.psi_label.SetInput(f"\u03c8 = {math.degrees(bfv.psi):.0f}\u00b0")
        self._write_arcs(1.0)

    def _write_arcs(self, side: float) -> None:
        """theta's arc, and psi's on the right (side 1) or mirrored on the left (-1)."""
        m = self._marks
        assert m is not None  # written only where the origin is in view
        ap = np.zeros((2 * ARC_POINTS + 2, 3))
        ap[:, 2] = self.z_line
        ap[:ARC_POINTS, :2] = m["theta"]
        ap[ARC_POINTS : 2 * ARC_POINTS, :2] = m["psi"] * [side, 1.0]
        ap[2 * ARC_POINTS :, :2] = m["axis"] * [side, 1.0]
        write_points(self.arcs, ap)
        tp = self.psi_label.GetTextProperty()
        if side > 0:
            tp.SetJustificationToLeft()
        else:
            tp.SetJustificationToRight()
        self._psi_side = side

    def place_angle_labels(self, frame: Frame) -> None:
        """theta's label at the first radius along the bisector where it covers no feature
        disc or name, psi's beside the right edge or, mirrored, the left one (as the
        exported figure places them). Cheap: run for every frame, a drag included."""
        m, bfv = self._marks, frame.bfv
        if m is None or bfv is None:
            return
        w, h = self.renderers[0].GetSize()
        upp = (bfv.rect[3] - bfv.rect[2]) / max(h, 1)  # model units per pixel
        if frame.n == 0 and set(frame.layers) == {"bfv"}:
            # the eyes-only Frame of a refit after a zoom (SceneActors.fit_bfv): the
            # features are the last full Frame's
            xs, ys, gs, names, named = self._obstacles
        else:
            xs, ys, gs = np.asarray(frame.x), np.asarray(frame.y), np.asarray(frame.g)
            names, named = list(frame.names), "labels" in frame.layers
            self._obstacles = (xs, ys, gs, names, named)
        # the features' names, right of each disc (22 px text, render.vtk.layers.labels)
        lx0 = xs + gs
        if names != self._name_chars[0]:  # a drag keeps the names: no walk over 10^4 of them
            self._name_chars = (names, np.array([len(n) + 1 for n in names], dtype=float))
        lx1 = lx0 + self._name_chars[1] * 14.0 * upp
        ly0, ly1 = ys, ys + 28.0 * upp

        def free(x0: float, x1: float, y0: float, y1: float) -> bool:
            if not len(xs):
                return True
            dx = np.maximum(np.maximum(x0 - xs, 0.0), xs - x1)
            dy = np.maximum(np.maximum(y0 - ys, 0.0), ys - y1)
            if not np.all(np.hypot(dx, dy) >= gs):
                return False
            on_name = (lx0 < x1) & (lx1 > x0) & (ly0 < y1) & (ly1 > y0)
            return not (named and bool(on_name.any()))

        def size(label) -> tuple[float, float]:
            px = label.GetTextProperty().GetFontSize()
            return 0.62 * px * len(label.GetInput() or "") * upp, 1.3 * px * upp

        tw, th = size(self.theta_label)
        rad = float(m["theta_at"][1]) / 1.04
        ys_try = [rad * f for f in (1.04, 0.7, 1.4, 0.45, 1.8)]
        y = next((v for v in ys_try if free(-tw / 2, tw / 2, v, v + th)), ys_try[0])
        self.theta_label.SetPosition(0.0, y, self.z_line)
        pw, ph = size(self.psi_label)
        px, py = m["psi_at"]
        right = free(px, px + pw, py - ph / 2, py + ph / 2)
        left = free(-px - pw, -px, py - ph / 2, py + ph / 2)
        side = 1.0 if right or not left else -1.0
        if side != self._psi_side:
            self._write_arcs(side)
        self.psi_label.SetPosition(side * px, py, self.z_line)
