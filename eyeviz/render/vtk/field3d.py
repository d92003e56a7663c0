"""The 3D view's field layers in the scene renderer: ``bfv`` (the HEALPix pair's 3D
binocular field's boundary cones, translucent; a measured pair's field has no such
closed form and is shown by its balls' readout) and ``plane`` (the plane z = 0). Both
reach as far as the balls and are rebuilt only when the balls' extent changes by about
40 % (in steps of 2^0.5), not every frame of a drag.
"""

from __future__ import annotations

import math

import numpy as np
from vtkmodules.vtkRenderingCore import vtkActor

from eyeviz.model import shapes3d
from eyeviz.model.facets3d import EyeSurface
from eyeviz.model.scene import Scene
from eyeviz.model.state3d import SceneState3D
from eyeviz.render.style3d import BFV_OPACITY, BFV_RGB, PLANE_RGB
from eyeviz.render.vtk.painter3d import Painter3D
from eyeviz.render.vtk.primitives import actor, point_cells, poly

__all__ = ["FieldPainter"]


class FieldPainter(Painter3D):
    """The BFV's cones and the plane z = 0 (the module docstring)."""

    def __init__(self, scene_ren, eyes_ren) -> None:
        super().__init__(scene_ren, eyes_ren)
        self.bfv_actor: vtkActor | None = None
        self.plane_actors: list[vtkActor] = []

    def _build(self, state: SceneState3D, surface: EyeSurface, reach: float) -> None:
        self.store.clear()
        pair = state.pair
        self.bfv_actor = None
        if surface.bfv:
            pts, faces = shapes3d.bfv_cones(pair.h, pair.l, reach)
            self.bfv_actor = actor(poly(pts, faces), BFV_RGB)
            self.bfv_actor.GetProperty().SetOpacity(BFV_OPACITY)
            self.add(self.bfv_actor, eyes=False)
        corners, segs = shapes3d.plane_z0(-reach * 0.8, reach * 0.8, -0.2 * reach, reach)
        quad = poly(corners, np.array([4, 0, 1, 2, 3]))
        fill = actor(quad, PLANE_RGB)
        fill.GetProperty().SetOpacity(0.10)
        seg_lines = np.column_stack(
            [np.full(len(segs), 2), 2 * np.arange(len(segs)), 2 * np.arange(len(segs)) + 1]
        ).ravel()
        grid = poly(segs.reshape(-1, 3), lines=seg_lines, verts=point_cells(2 * len(segs)))
        lines = actor(grid, PLANE_RGB)
        lines.GetProperty().SetOpacity(0.6)
        self.plane_actors = [fill, lines]
        for a in self.plane_actors:
            self.add(a, eyes=False)

    def update(
        self, scene: Scene, state: SceneState3D, selected: int | None, surface: EyeSurface
    ) -> None:
        step = round(2.0 * math.log2(1.1 * shapes3d.scene_extent(state)))
        key = (surface.key, step)
        if key != self.key:
            self._build(state, surface, 2.0 ** (step / 2.0 + 0.5))
            self.key = key
        if self.bfv_actor is not None:
            self.bfv_actor.SetVisibility(scene.shows("bfv"))
        for a in self.plane_actors:
            a.SetVisibility(scene.shows("plane"))
