"""``features``: the discs (Frame ``x``, ``y``, ``g``, colours; grey outside the networks'
domain: Frame ``out_of_domain``) and the selected feature's ring, handle and sight lines.

All discs but the selected one are ONE fill mesh (triangle fans) and ONE outline mesh with
cell colours: few draw calls. The selected disc is drawn by template actors placed by
transforms, so a drag uploads no geometry (a transform is a uniform, not a buffer).

Level of detail (issue 25: 10^4 discs of CIRCLE_N vertices took seconds per frame in
software GL): each merged disc gets the fewest vertices of :data:`LOD_LEVELS` whose inscribed
polygon stays within :data:`LOD_ERROR_PX` of the circle on screen (:func:`disc_vertices`),
at the largest zoom of a view it is in (main or inset). The levels follow the cameras
(:meth:`FeaturesLayer.refit`, called on every zoom); the selected disc keeps CIRCLE_N. The
inset draws its own cells over the same points: only the discs that meet its rectangle
(none while it is hidden), as a disc far from the eyes cost the inset as much as the main
view in software GL.

Backdrop (issue 25): from :data:`BACKDROP_MIN_FEATURES` features on, the main view's
merged discs are drawn by a :class:`eyeviz.render.vtk.backdrop.Backdrop` before the main
renderer's other props, and kept (colour and depth) while the discs and the camera are
unchanged: a drag frame, which moves only the selected feature (the live actors), then
copies the kept buffers instead of filling 10^4 discs again. Smaller scenes keep the discs
in the main renderer (the backdrop's copy costs more than it saves there).
"""

from __future__ import annotations

import numpy as np
import pyvista as pv
from vtkmodules.util.numpy_support import vtk_to_numpy
from vtkmodules.vtkCommonCore import vtkPoints
from vtkmodules.vtkCommonMath import vtkMatrix4x4

from eyeviz.model.frame import Frame
from eyeviz.render.vtk.backdrop import Backdrop
from eyeviz.render.vtk.primitives import (
    CIRCLE_N,
    Store,
    actor,
    points_actor,
    set_input,
    set_rgb,
    unit_fan,
    unit_ring,
)
from eyeviz.render.vtk.style import (
    FILL_ALPHA,
    INK,
    OUT_FILL,
    OUT_LINE,
    Z_FEAT,
    Z_LINE,
    Z_POINT,
    hex_rgb,
    rgbf,
)

__all__ = [
    "BACKDROP_MIN_FEATURES",
    "LOD_ERROR_PX",
    "LOD_LEVELS",
    "FeaturesLayer",
    "disc_vertices",
]

#: Vertex counts a merged disc may have (few levels: a zoom step seldom rebuilds).
LOD_LEVELS = np.array([8, 12, 16, 24, 32, 48, 64, 96, 128, CIRCLE_N])
#: Largest gap, in pixels, between a disc's circle and its inscribed polygon.
LOD_ERROR_PX = 0.5
#: Features from which the main view's merged discs go to the backdrop, past the crossover
#: that scripts/bench_app_scale.py --crossover measures (2026-11-26, 2-core machine, a
#: render of a drag's state with the discs kept / in the main renderer: 1.05x at 10
#: features, 0.99x at 30 (the copy costs what the fill saves), 0.79-1.07x at 100, 0.77-0.80x
#: at 150, 0.70-0.74x at 200, 0.56-0.64x at 300, 0.34x at 1,000).
BACKDROP_MIN_FEATURES = 150


def disc_vertices(r_px: np.ndarray) -> np.ndarray:
    """Vertices per disc of on-screen radius ``r_px`` (pixels): the smallest level c of
    LOD_LEVELS with r (1 - cos(pi / c)) <= LOD_ERROR_PX (the polygon's sagitta), CIRCLE_N
    at most."""
    r = np.maximum(np.asarray(r_px, dtype=np.float64), 0.0)
    ok = r[:, None] * (1.0 - np.cos(np.pi / LOD_LEVELS[None, :])) <= LOD_ERROR_PX
    first = np.where(ok.any(axis=1), ok.argmax(axis=1), len(LOD_LEVELS) - 1)
    return LOD_LEVELS[first]


class FeaturesLayer:
    """The merged discs of the unselected features and the selected one's live actors."""

    def __init__(self, main, inset):
        self.main = main
        # the inset shows the discs too: a feature overlapping an eye is drawn over it there
        # (Z_FEAT above Z_EYES), not cut off at the eye (issue 24)
        self.inset = inset
        self.store = Store()
        self.backdrop = Backdrop(main)
        self.backdrop_min = BACKDROP_MIN_FEATURES  # features from which it holds the discs
        self._key: tuple | None = None
        self.fill_mesh: pv.PolyData | None = None
        self.line_mesh: pv.PolyData | None = None
        self.centers_mesh: pv.PolyData | None = None
        self.grey = np.zeros(0, bool)
        self.fan = CIRCLE_N - 2  # fill triangles of the finest merged disc
        self.verts = np.zeros(0, np.int64)  # vertices of each merged disc (level of detail)
        self.inset_fill = pv.PolyData()
        self.inset_line = pv.PolyData()
        self._merged_key: tuple | None = None
        self._last: tuple[Frame, int | None] | None = None
        self.handle_actor = points_actor(pv.PolyData(np.zeros((1, 3))), 13, (0.35, 0.35, 0.35))
        # sight lines (-h, 0) -> (x, y) -> (h, 0): the template (-1, 0) -> (0, 1) -> (1, 0)
        # under the linear map [[h, x], [0, y]]
        self.sight_mesh = pv.PolyData(
            np.array([[-1.0, 0.0, Z_LINE], [0.0, 1.0, Z_LINE], [1.0, 0.0, Z_LINE]]),
            lines=[3, 0, 1, 2],
        )
        self.sight_matrix = vtkMatrix4x4()
        self.sight_actors = [actor(self.sight_mesh, INK), actor(self.sight_mesh, INK)]
        for a in self.sight_actors:
            a.GetProperty().SetLineWidth(2.0)
            a.GetProperty().SetLineStipplePattern(0xF0F0)
            a.SetUserMatrix(self.sight_matrix)
        self.sel_actor = actor(unit_ring(0.0), INK)
        self.sel_actor.GetProperty().SetLineWidth(5.0)
        self.live_fill = actor(unit_fan())
        self.live_line = actor(unit_ring(0.0))
        self.live_line.GetProperty().SetLineWidth(3.0)
        self.live_center = points_actor(pv.PolyData(np.zeros((1, 3))), 11, INK)
        self.live_actors = (self.live_fill, self.live_line, self.live_center)
        for a in self.live_actors:
            a.SetVisibility(False)
            main.AddActor(a)
        main.AddActor(self.sel_actor)
        if inset is not None:
            for a in (*self.live_actors, self.sel_actor):
                inset.AddActor(a)
        main.AddActor(self.handle_actor)
        main.AddActor(self.sight_actors[0])
        inset.AddActor(self.sight_actors[1])  # the sight lines reach the eyes in the inset
        self._feat_rgb = self._rgb_now = (np.zeros((0, 3), np.uint8), np.zeros((0, 3), np.uint8))

    def draw(self, frame: Frame, selected: int | None) -> None:
        """New meshes when the features' names or colours or the layers changed; then the
        discs' points and colours and the selected feature's actors."""
        key = (tuple(frame.names), tuple(frame.colors), tuple(sorted(frame.layers)))
        if key != self._key:
            self.build(frame)
            self._key = key
        self.update(frame, selected)

    def build(self, frame: Frame) -> None:
        """New merged meshes (the features' names or colours, or the layers, changed)."""
        self.store.clear()
        self.centers_mesh = self.fill_mesh = self.line_mesh = None
        self._merged_key = None
        if "features" not in frame.layers or not frame.n:
            return
        n = frame.n
        cols = np.array([hex_rgb(col) for col in frame.colors], dtype=np.float64)
        # an opaque tint, not alpha: translucency costs whole extra passes in software GL
        tint = np.round(FILL_ALPHA * cols + (1 - FILL_ALPHA) * 255).astype(np.uint8)
        self._feat_rgb = (tint, cols.astype(np.uint8))
        self._rgb_now = self._feat_rgb
        self.grey = np.zeros(n, bool)
        self.verts = np.zeros(0, np.int64)
        self.fill_mesh = pv.PolyData()
        self.line_mesh = pv.PolyData()
        self.inset_fill = pv.PolyData()  # the inset's cells: the discs it shows
        self.inset_line = pv.PolyData()
        main = self.backdrop if n >= self.backdrop_min else self.main
        for ren, fill, line in (
            (main, self.fill_mesh, self.line_mesh),
            (self.inset, self.inset_fill, self.inset_line),
        ):
            if ren is not None:
                fa = actor(fill, rgb=True)
                la = actor(line, rgb=True)
                la.GetProperty().SetLineWidth(3.0)
                self.store.add(ren, fa)
                self.store.add(ren, la)
        self.centers_mesh = pv.PolyData(np.zeros((n, 3)))
        self._centers_actor = points_actor(self.centers_mesh, 11, None)
        mapper = self._centers_actor.GetMapper()
        mapper.SetScalarModeToUsePointFieldData()
        mapper.SelectColorArray("rgb")
        mapper.SetColorModeToDirectScalars()
        mapper.ScalarVisibilityOn()
        self.store.add(main, self._centers_actor)
        if main is self.main:
            # the selected feature's live actors after the merged ones, as over a backdrop
            # (drawn before all of the main renderer's props): a tie at one depth (the
            # centre dots of two coincident features, both at Z_POINT) goes to the live
            # actors on either path
            for a in self.live_actors:
                self.main.RemoveActor(a)
                self.main.AddActor(a)

    def set_backdrop_min(self, n: int) -> None:
        """Features from which the merged discs go to the backdrop; the discs are rebuilt."""
        self.backdrop_min = n
        self._key = None
        if self._last is not None:
            self.draw(*self._last)

    def refit(self) -> None:
        """The cameras changed (zoom): the discs' levels of detail follow."""
        if self._last is not None:
            self.update(*self._last)

    def _levels(self, frame: Frame) -> tuple[np.ndarray, np.ndarray]:
        """Vertices of each disc (:func:`disc_vertices`) at the largest pixels per unit of
        the views (main, inset) whose visible rectangle it meets, and which discs meet the
        inset's; CIRCLE_N and every disc while no view has a size yet."""
        scale = np.zeros(frame.n)
        in_inset = np.zeros(frame.n, bool)
        sized = False
        for ren in (self.main, self.inset):
            if ren is None or not ren.GetDraw():  # a hidden inset
                continue
            cam = ren.GetActiveCamera()
            half_h = cam.GetParallelScale()
            h_px = ren.GetSize()[1]
            if not (half_h > 0 and h_px > 0):
                continue
            sized = True
            half_w = half_h * max(ren.GetTiledAspectRatio(), 1e-3)
            cx, cy, _ = cam.GetFocalPoint()
            meets = (np.abs(frame.x - cx) <= half_w + frame.g) & (
                np.abs(frame.y - cy) <= half_h + frame.g
            )
            scale = np.where(meets, np.maximum(scale, h_px / (2.0 * half_h)), scale)
            if ren is self.inset:
                in_inset = meets
        if not sized:
            return np.full(frame.n, CIRCLE_N), np.ones(frame.n, bool)
        return disc_vertices(frame.g * scale), in_inset

    def update(self, frame: Frame, selected: int | None) -> None:
        self._last = (frame, selected)
        n = frame.n
        has_sel = selected is not None and 0 <= selected < n and "features" in frame.layers
        sel = selected if has_sel and self.fill_mesh is not None else None
        if self.fill_mesh is not None:
            self._grey(frame)
            tint, cols = self._rgb_now
            others = np.ones(n, bool)
            if sel is not None:
                others[sel] = False
            geo = np.column_stack([frame.x, frame.y, frame.g])[others]
            verts, in_inset = self._levels(frame)
            verts[~others] = LOD_LEVELS[0]  # the selected disc is the live actors'
            key: tuple = (sel, geo.tobytes(), tint.tobytes(), cols.tobytes())
            key += (verts.tobytes(), in_inset.tobytes())
            if key != self._merged_key:  # not while only the selected feature moves
                self._merged_key = key
                self._write_merged(frame, others, tint, cols, verts)
                self._write_cells(
                    self.inset_fill, self.inset_line, others & in_inset, tint, cols, verts
                )
        for a in self.live_actors:
            a.SetVisibility(sel is not None)
        self.handle_actor.SetVisibility(has_sel)
        self.sel_actor.SetVisibility(has_sel)
        for a in self.sight_actors:
            a.SetVisibility(has_sel)
        if not has_sel or selected is None:
            return
        x, y, g = float(frame.x[selected]), float(frame.y[selected]), float(frame.g[selected])
        if sel is not None:
            z = Z_FEAT + 0.9 * sel / n
            tint, cols = self._rgb_now
            self.live_fill.SetPosition(x, y, z)
            self.live_line.SetPosition(x, y, z)
            self.live_center.SetPosition(x, y, Z_POINT)
            for a in (self.live_fill, self.live_line):
                a.SetScale(g, g, 1.0)
            self.live_fill.GetProperty().SetColor(*(tint[sel] / 255.0))
            for a in (self.live_line, self.live_center):
                a.GetProperty().SetColor(*(cols[sel] / 255.0))
        self.handle_actor.SetPosition(x + g, y, Z_POINT + 0.5)
        self.sel_actor.SetPosition(x, y, Z_LINE)
        self.sel_actor.SetScale(g, g, 1.0)
        h = frame.pair.h
        mat = self.sight_matrix
        if (mat.GetElement(0, 0), mat.GetElement(0, 1), mat.GetElement(1, 1)) != (h, x, y):
            mat.SetElement(0, 0, h)
            mat.SetElement(0, 1, x)
            mat.SetElement(1, 1, y)
            mat.Modified()
        col = rgbf(frame.colors[selected])
        self.sel_actor.GetProperty().SetColor(*col)
        for a in self.sight_actors:
            a.GetProperty().SetColor(*col)

    def _write_merged(self, frame: Frame, others: np.ndarray, tint, cols, verts) -> None:
        """The merged fill/outline/centre meshes of every feature but the selected one;
        disc i a polygon of ``verts[i]`` vertices inscribed in its circle."""
        assert self.fill_mesh is not None and self.line_mesh is not None
        n = frame.n
        zf = Z_FEAT + 0.9 * np.arange(n) / n
        start = np.concatenate([[0], np.cumsum(verts)])  # disc i's first point id
        disc = np.repeat(np.arange(n), verts)  # the disc of each point
        k = np.arange(start[-1]) - start[disc]  # its vertex number on the disc
        t = 2.0 * np.pi * k / verts[disc]
        ring = np.empty((start[-1], 3))
        ring[:, 0] = frame.x[disc] + frame.g[disc] * np.cos(t)
        ring[:, 1] = frame.y[disc] + frame.g[disc] * np.sin(t)
        ring[:, 2] = zf[disc]
        if self.fill_mesh.GetPoints() is None or self.fill_mesh.n_points != len(ring):
            pts = vtkPoints()
            pts.SetDataTypeToDouble()  # features lie far from the origin: keep float64
            pts.SetNumberOfPoints(len(ring))
            for mesh in (self.fill_mesh, self.line_mesh, self.inset_fill, self.inset_line):
                mesh.SetPoints(pts)
        pts = self.fill_mesh.GetPoints()
        vtk_to_numpy(pts.GetData())[:] = ring
        pts.Modified()
        self._write_cells(self.fill_mesh, self.line_mesh, others, tint, cols, verts)
        c = self.verts = verts[others]
        self.fan = int(c.max()) - 2 if len(c) else CIRCLE_N - 2
        centers = pv.PolyData(np.column_stack([frame.x, frame.y, np.full(n, Z_POINT)])[others])
        set_rgb(centers.GetPointData(), cols[others])
        self.centers_mesh = centers
        set_input(self._centers_actor, centers)

    @staticmethod
    def _write_cells(fill, line, shown_mask, tint, cols, verts) -> None:
        """The fill fans and outlines of the discs in ``shown_mask`` over the shared points
        (disc i's ``verts[i]`` points from sum(verts[:i]))."""
        start = np.concatenate([[0], np.cumsum(verts)])
        # front to back (the last feature is on top): the depth test then rejects the
        # covered fragments early, ~15 % of a frame of 10^4 overlapping discs
        shown = np.flatnonzero(shown_mask)[::-1]
        c, s0 = verts[shown], start[shown]
        # triangle fans, not c-gons: VTK would re-triangulate every polygon at each upload
        tri_disc = np.repeat(np.arange(len(shown)), c - 2)
        tri_start = np.concatenate([[0], np.cumsum(c - 2)])
        j = np.arange(len(tri_disc)) - tri_start[tri_disc] + 1
        o = s0[tri_disc]
        fill.faces = np.column_stack([np.full(len(o), 3), o, o + j, o + j + 1]).ravel()
        set_rgb(fill.GetCellData(), np.repeat(tint[shown], c - 2, axis=0))
        # outlines: [c + 1, first, ..., last, first] per disc
        cell_start = np.concatenate([[0], np.cumsum(c + 2)])
        lines = np.empty(cell_start[-1], np.int64)
        lines[cell_start[:-1]] = c + 1
        lines[cell_start[1:] - 1] = s0
        v_disc = np.repeat(np.arange(len(shown)), c)
        v_k = np.arange(len(v_disc)) - np.concatenate([[0], np.cumsum(c)])[v_disc]
        lines[cell_start[v_disc] + 1 + v_k] = s0[v_disc] + v_k
        line.lines = lines
        set_rgb(line.GetCellData(), cols[shown])
        fill.Modified()
        line.Modified()

    def fill_rgb(self, i: int) -> np.ndarray:
        """The fill colour feature i is drawn in."""
        return self._rgb_now[0][i]

    def _grey(self, frame: Frame) -> None:
        """Features the Frame marks out of the networks' domain (predictions layer) are grey."""
        grey = frame.out_of_domain
        if grey is None or not grey.any():
            self._rgb_now = self._feat_rgb
            self.grey = np.zeros(frame.n, bool)
            return
        tint, cols = (a.copy() for a in self._feat_rgb)
        tint[grey] = OUT_FILL
        cols[grey] = OUT_LINE
        self._rgb_now = (tint, cols)
        self.grey = grey
