"""The 3D view's ``eyes`` layer: each eye's facets, lit in the colour of the ball they see
(a facet lit by several balls takes the last one's), in both renderers; with ``plane``
each HEALPix eye's equator (that row of facets is the planar eye), with ``labels`` the
eyes' names in the close-up.

The facets come from the eye model's :class:`eyeviz.model.facets3d.EyeSurface`: HEALPix
cells, or a measured eye's hexagonal patches at its lenses. When the surface is ``full``
each eye is one mesh with one cell per facet, and a frame rewrites its cell colours in
place (the cell data's array, one ``Modified``). Beyond (HEALPix nside > 32: 388,800 facets
per eye at nside 180, each under a pixel) the unlit sphere is a smooth mesh drawn once,
and each ball's lit facets are a small mesh of their own, rebuilt only when that ball's
lit set changes.

With the ``responses`` layer (:mod:`eyeviz.model.responses3d`) each lit facet is its
ball's colour blended towards the unlit grey by 1 - its response: a full surface's cells,
and beyond the full LOD each patch cell (one per lit facet); a patch drawn on the coarse
grid (a ball lighting more than ``shapes3d.MAX_PATCH_FACETS`` facets) keeps its ball's
plain colour, since its cells are not the facets.
"""

from __future__ import annotations

import math

import numpy as np
from vtkmodules.vtkCommonDataModel import vtkPolyData
from vtkmodules.vtkRenderingCore import vtkActor

from eyeviz.model import shapes3d
from eyeviz.model.facets3d import EyeSurface
from eyeviz.model.responses3d import lit_responses, owner_values, shade
from eyeviz.model.scene import Scene
from eyeviz.model.state3d import SceneState3D
from eyeviz.render.style3d import EDGE_RGB, EDGES_MAX_NSIDE
from eyeviz.render.vtk.painter3d import Painter3D, lit, palette
from eyeviz.render.vtk.primitives import (
    Store,
    actor,
    poly,
    polyline,
    read_rgb,
    set_rgb,
    sphere,
    text3d,
    write_rgb,
)
from eyeviz.render.vtk.style import INK, UNLIT, rgbf

__all__ = ["EyesPainter", "LABEL_PX", "PATCH_LIFT"]

#: the lit patch of ball i lies at radius l (1 + PATCH_LIFT (1 + i / n)): above the
#: unlit sphere, a later ball's above an earlier one's (the last one's colour wins)
PATCH_LIFT = 0.004
LABEL_PX = 20


class EyesPainter(Painter3D):
    """The eyes' facets (see the module docstring); ``caption`` is the close-up's
    caption actor, whose text names the eyes."""

    def __init__(self, scene_ren, eyes_ren, caption=None) -> None:
        super().__init__(scene_ren, eyes_ren)
        self.caption = caption
        self.full = True
        self.meshes: list[vtkPolyData] = []  # full: one per eye, cell i = facet i
        self.patches: list[list[tuple[vtkPolyData, vtkActor, np.ndarray]]] = [[], []]
        self.patch_store = Store()
        self.equators: list[vtkActor] = []
        self.labels: list = []
        self._owner: list[np.ndarray] = []
        self._patch_key: tuple | None = None

    def _build(self, surface: EyeSurface) -> None:
        self.store.clear()
        self.full = surface.full
        self.meshes, self._owner, self.equators, self.labels = [], [], [], []
        # edges up to a small nside; a measured eye's facets are a few pixels across in
        # the close-up (a 1 px edge would hide their colour): none
        edges = surface.nside is not None and surface.nside <= EDGES_MAX_NSIDE
        for e, centre in enumerate(surface.centres):
            if self.full:
                pts, faces = surface.mesh(e)
                mesh = poly(pts, faces)
                set_rgb(mesh.GetCellData(), np.broadcast_to(UNLIT, (mesh.GetNumberOfCells(), 3)))
                a = lit(actor(mesh, rgb=True))
                if edges:
                    p = a.GetProperty()
                    p.EdgeVisibilityOn()
                    p.SetEdgeColor(*EDGE_RGB)
                    p.SetLineWidth(1.0)
                self.meshes.append(mesh)
                self._owner.append(np.full(surface.counts()[e], -1, dtype=np.int32))
                self.add(a)
            if surface.underlay is not None:
                # a smooth unlit sphere just inside the facets: the whole eye beyond the
                # full LOD, and behind the facets' polygons (which share no points, so
                # the rasteriser leaves pixel cracks between them) up to it
                under = sphere(surface.underlay, centre, theta_resolution=96, phi_resolution=48)
                self.add(lit(actor(under, rgbf("#E1E1E1"))))
            if surface.equator is not None:
                t = np.linspace(0.0, 2.0 * math.pi, 241)
                r, (cx, cy, cz) = surface.equator, centre
                ring = polyline(
                    np.column_stack([cx + r * np.cos(t), cy + r * np.sin(t), cz + 0 * t])
                )
                eq = actor(ring, (0.1, 0.1, 0.1))
                eq.GetProperty().SetLineWidth(2.0)
                self.add(eq)
                self.equators.append(eq)
            if self.eyes_ren is not None:
                lab = text3d(LABEL_PX, INK)  # moved below its eye: names3d
                lab.GetTextProperty().SetJustificationToLeft()
                lab.GetTextProperty().SetVerticalJustificationToBottom()
                lab.SetInput(f"eye {'AB'[e]}")
                lab.SetPosition(*centre)
                self.store.add(self.eyes_ren, lab)
                self.labels.append(lab)
        if self.caption is not None:
            self.caption.SetInput(surface.caption)

    def _build_patches(self, n: int) -> None:
        """One (empty) mesh per ball and eye: the lit facets beyond the full LOD."""
        self.patch_store.clear()
        self.patches = [[], []]
        for e in range(2):
            for _ in range(n):
                mesh = poly()
                set_rgb(mesh.GetCellData(), np.zeros((0, 3), np.uint8))
                a = lit(actor(mesh, rgb=True))
                self.patch_store.add(self.scene_ren, a)
                if self.eyes_ren is not None:
                    self.patch_store.add(self.eyes_ren, a)
                self.patches[e].append((mesh, a, np.empty(0, np.int64)))

    def update(
        self, scene: Scene, state: SceneState3D, selected: int | None, surface: EyeSurface
    ) -> None:
        if surface.key != self.key:
            self._build(surface)
            self.key, self._patch_key = surface.key, None
        patch_key = (surface.key, tuple((f.name, f.color) for f in scene.features))
        if not self.full and patch_key != self._patch_key:
            self._build_patches(state.n)
            self._patch_key = patch_key
        show = scene.shows("eyes")
        for _r, a in self.store.items:
            a.SetVisibility(show)
        pal = palette(scene)
        vals = lit_responses(state, selected) if scene.shows("responses") else None
        if self.full:
            for e, mesh in enumerate(self.meshes):
                own = self._owner[e]
                shapes3d.facet_owner(state, "AB"[e], own)
                rgb = pal[own]
                csr = state.lit_b if e else state.lit_a
                if vals is not None and csr is not None and csr[1].size:
                    pix = np.unique(csr[1])  # the lit facets, as owner_values orders them
                    rgb[pix] = shade(rgb[pix], UNLIT, owner_values(csr, vals["AB"[e]]))
                write_rgb(mesh, rgb)
        else:
            self._draw_patches(state, surface, pal, show, vals)
        for eq in self.equators:
            eq.SetVisibility(show and scene.shows("plane"))
        for lab in self.labels:
            lab.SetVisibility(show and scene.shows("labels"))

    def _draw_patches(self, state, surface: EyeSurface, pal, show: bool, vals=None) -> None:
        """Each ball's lit facets as its own mesh, rebuilt when its lit set changes; the
        cells' colours rewritten every frame (a response moves with its ball even where
        the lit set stays)."""
        n = state.n
        for e, csr in enumerate((state.lit_a, state.lit_b)):
            for i, (mesh, a, was) in enumerate(self.patches[e]):
                lo, hi = (int(csr[0][i]), int(csr[0][i + 1])) if csr is not None else (0, 0)
                pix = csr[1][lo:hi] if csr is not None else was[:0]
                a.SetVisibility(show and pix.size > 0)
                if pix.size != was.size or not np.array_equal(pix, was):
                    lift = 1.0 + PATCH_LIFT * (1.0 + i / max(n, 1))
                    fresh = poly(*surface.patch(e, pix, lift)) if pix.size else poly()
                    set_rgb(fresh.GetCellData(), np.zeros((fresh.GetNumberOfCells(), 3), np.uint8))
                    mesh.ShallowCopy(fresh)
                    self.patches[e][i] = (mesh, a, pix.copy())
                cells = mesh.GetNumberOfCells()
                if cells == 0:
                    continue
                rgb = np.broadcast_to(pal[i], (cells, 3))
                if vals is not None and cells == pix.size:  # one cell per facet
                    rgb = shade(rgb, UNLIT, vals["AB"[e]][lo:hi])
                if not np.array_equal(read_rgb(mesh), rgb):  # unchanged: no Modified
                    write_rgb(mesh, rgb)
