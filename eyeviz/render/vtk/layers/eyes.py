"""``eyes``: the two eyes as ommatidium triangles (Figure 2), their rims and the origin.

Each eye is ONE PolyData of c triangle cells between the Frame's rim vertices
(:meth:`eyeviz.model.frame.EyeFrame.rim`, Eq. 6) in the main view and in the inset;
lighting writes only the cell colour array in place, from the Frame's per-ommatidium
owners. Level of detail: where the rim is narrower than m/2 pixels, cells pool k ommatidia
(:meth:`EyeFrame.rim` and :meth:`EyeFrame.pooled_owner` of k).
"""

from __future__ import annotations

import math

import numpy as np
import pyvista as pv
from vtkmodules.util.numpy_support import vtk_to_numpy

from eyeviz.model.frame import EyeFrame, Frame
from eyeviz.render.vtk.primitives import (
    CIRCLE_N,
    UNIT,
    Store,
    actor,
    points_actor,
    set_input,
    write_rgb,
)
from eyeviz.render.vtk.style import EDGE_MIN_PX, INK, UNLIT, Z_EYES, Z_LINE, Z_POINT, hex_rgb

__all__ = ["EyesLayer", "mesh_of_rim"]


def mesh_of_rim(center: tuple[float, float], rim: np.ndarray) -> pv.PolyData:
    """Triangles (centre, rim[i], rim[i + 1]) at height Z_EYES, all unlit."""
    n = rim.shape[0] - 1
    pts = np.zeros((n + 2, 3))
    pts[0] = (center[0], center[1], Z_EYES)
    pts[1:, :2] = rim
    pts[1:, 2] = Z_EYES
    k = np.arange(n)
    faces = np.column_stack([np.full(n, 3), np.zeros(n, int), k + 1, k + 2]).ravel()
    mesh = pv.PolyData(pts, faces=faces)
    mesh.cell_data["rgb"] = np.tile(UNLIT, (n, 1))
    return mesh


def _write_changed(mesh, palette: np.ndarray, before: np.ndarray | None, owner: np.ndarray) -> bool:
    """Colour the mesh's cells by ``owner`` (index into ``palette`` minus one), writing only
    the cells whose owner differs from ``before`` (all of them without one); False when
    nothing changed. A drag moves one feature: at m = 36,000 it rewrites a few hundred
    cells instead of gathering 36,000 colours per eye and frame."""
    if before is None or before.shape != owner.shape:
        write_rgb(mesh, palette[owner + 1])
        return True
    changed = np.flatnonzero(before != owner)
    if changed.size == 0:
        return False
    arr = mesh.GetCellData().GetAbstractArray("rgb")
    vtk_to_numpy(arr)[changed] = palette[owner[changed] + 1]
    arr.Modified()
    return True


class EyesLayer:
    """Eye meshes (main A, B; inset A, B), rim outlines and the origin point."""

    def __init__(self, main, inset):
        self.main, self.inset = main, inset
        self.store = Store()
        self.meshes: list[pv.PolyData] = []
        self.actors: list = []  # [main A, main B, inset A, inset B]
        self.lod: dict[tuple[int, int], pv.PolyData] = {}
        self.lod_k = {"main": 1, "inset": 1}
        self.edges_main = self.edges_inset = False
        self.outlines: list[pv.PolyData] = []
        self._eyes: list[EyeFrame] = []
        self._owners: tuple[np.ndarray, ...] | None = None
        self._palette: np.ndarray | None = None
        self._pooled: dict[tuple[int, int], np.ndarray] = {}
        self._colors: tuple[str, ...] = ()
        self._key: tuple | None = None

    def draw(self, frame: Frame, selected: int | None) -> None:
        """New meshes when the eyes (h, l, m) or the layers changed, then the colours."""
        pair = frame.pair
        key = (pair.h, pair.l, pair.m, tuple(sorted(frame.layers)))
        if key != self._key:
            self.build(frame)
            self._key = key
        self.update(frame)

    def build(self, frame: Frame) -> None:
        """New meshes (the eyes' h, l, m or the layers changed)."""
        self.store.clear()
        self.meshes, self.actors, self.outlines = [], [], []
        self._owners = self._palette = None
        self._pooled = {}
        self._eyes = list(frame.eyes) if "eyes" in frame.layers else []
        self.lod = {}
        self.lod_k = {"main": 1, "inset": 1}
        for eye in self._eyes:
            self.meshes.append(mesh_of_rim(eye.center, eye.rim()))
        for ren in (self.main, self.inset):
            for mesh in self.meshes:
                a = actor(mesh, rgb=True)
                a.GetProperty().SetEdgeColor(0.35, 0.35, 0.35)
                a.GetProperty().SetLineWidth(1.0)
                self.store.add(ren, a)
                self.actors.append(a)
        for eye in self._eyes:
            pts = np.empty((CIRCLE_N, 3))
            pts[:, :2] = np.asarray(eye.center) + eye.l * UNIT
            pts[:, 2] = Z_LINE
            outline = pv.PolyData(pts)
            outline.lines = np.concatenate([[CIRCLE_N + 1], np.arange(CIRCLE_N), [0]])
            self.outlines.append(outline)
            for ren in (self.main, self.inset):
                ra = actor(outline, INK)
                ra.GetProperty().SetLineWidth(2.0)
                self.store.add(ren, ra)
        origin = pv.PolyData(np.array([[0.0, 0.0, Z_POINT]]))
        self.store.add(self.main, points_actor(origin, 9, INK))
        self.store.add(self.inset, points_actor(origin, 9, INK))

    def update(self, frame: Frame) -> None:
        """Cell colours from the Frame's owners, in place; nothing when unchanged."""
        if not self.meshes or not frame.eyes:
            return
        self._eyes = list(frame.eyes)
        colors = tuple(frame.colors)
        same_palette = self._palette is not None and colors == self._colors
        if not same_palette:
            self._colors = colors
            self._palette = np.vstack([UNLIT] + [hex_rgb(c) for c in colors]).astype(np.uint8)
        palette = self._palette
        assert palette is not None
        old = self._owners
        for e, (mesh, eye) in enumerate(zip(self.meshes, self._eyes, strict=True)):
            before = old[e] if same_palette and old is not None else None
            if before is not None and before is eye.owner:
                continue
            if not _write_changed(mesh, palette, before, eye.owner):
                continue  # unchanged: no colour write, so no buffer upload at the next render
            for (which, k), lod in self.lod.items():
                if which == e:
                    pooled = eye.pooled_owner(k)
                    was = self._pooled.get((e, k)) if before is not None else None
                    _write_changed(lod, palette, was, pooled)
                    self._pooled[(e, k)] = pooled
        self._owners = tuple(eye.owner for eye in self._eyes)

    def set_zoom(self, main_px_per_unit: float, inset_px_per_unit: float, l: float, m: int):
        """Level of detail by on-screen size: where the eye's rim is narrower than m/2 pixels,
        neighbouring ommatidia are pooled (a pooled cell is lit if any of its ommatidia is, in
        the colour of the last feature lighting it); edges only where a cell is wide enough.
        """
        if not self.meshes:
            return
        if self._eyes:  # the Frame's eyes are what is drawn (l and m given are the scene's)
            l, m = self._eyes[0].l, self._eyes[0].m
        rim_px = {
            "main": 2 * math.pi * l * main_px_per_unit,
            "inset": 2 * math.pi * l * inset_px_per_unit,
        }
        for which, ren_actors in (("main", self.actors[:2]), ("inset", self.actors[2:])):
            k = max(1, math.ceil(m / max(2.0 * rim_px[which], 8.0)))
            self.lod_k[which] = k
            for e, a in enumerate(ren_actors):
                mesh = self.meshes[e] if k == 1 else self._lod_mesh(e, k)
                if a.GetMapper().GetInput() is not mesh:
                    set_input(a, mesh)
                cell_px = rim_px[which] * k / m
                a.GetProperty().SetEdgeVisibility(cell_px >= EDGE_MIN_PX)
        self.edges_main = bool(self.actors[0].GetProperty().GetEdgeVisibility())
        self.edges_inset = bool(self.actors[2].GetProperty().GetEdgeVisibility())
        used = {(e, k) for k in self.lod_k.values() for e in (0, 1)}
        for key in [key for key in self.lod if key not in used]:
            del self.lod[key]
            self._pooled.pop(key, None)

    def _lod_mesh(self, e: int, k: int) -> pv.PolyData:
        if (e, k) not in self.lod:
            eye = self._eyes[e]
            mesh = mesh_of_rim(eye.center, eye.rim(k))
            if self._owners is not None and self._palette is not None:
                pooled = eye.pooled_owner(k)
                write_rgb(mesh, self._palette[pooled + 1])
                self._pooled[(e, k)] = pooled
            self.lod[(e, k)] = mesh
        return self.lod[(e, k)]
