"""The 3D view's balls: ``features`` (each ball a sphere in its colour, the selected one
ringed by three great circles), ``labels`` (their names) and ``tangents`` (the tangent
cone from each eye's centre to each ball, the 3D Proposition 2; in the close-up only the
first EYE_CONE eye radii of each). Balls and labels move by their actors' transforms,
cones by writing their points in place; nothing is rebuilt during a drag.
"""

from __future__ import annotations

import math

import numpy as np
from vtkmodules.vtkCommonDataModel import vtkPolyData
from vtkmodules.vtkRenderingCore import vtkActor

from eyeviz.model import shapes3d
from eyeviz.model.facets3d import EyeSurface
from eyeviz.model.labels3d import Named3D
from eyeviz.model.scene import Scene
from eyeviz.model.state3d import SceneState3D
from eyeviz.render.style3d import CONE_OPACITY, EYE_CONE
from eyeviz.render.vtk.eyes3d import LABEL_PX
from eyeviz.render.vtk.names3d import named_of
from eyeviz.render.vtk.painter3d import Painter3D, lit, palette
from eyeviz.render.vtk.primitives import (
    actor,
    point_cells,
    poly,
    set_rgb,
    sphere,
    text3d,
    write_points,
)
from eyeviz.render.vtk.style import INK, rgbf

__all__ = ["CONE_RES", "BallsPainter"]

SELECT_RGB = INK
RING = 1.3  # the selection's great circles' radius, in ball radii
CONE_RES = 40


def _great_circles(r: float, n: int = 96) -> vtkPolyData:
    """Three great circles of radius ``r`` (the selected ball's marker)."""
    t = np.linspace(0.0, 2.0 * math.pi, n + 1)
    c, s, z = r * np.cos(t), r * np.sin(t), 0.0 * t
    pts = np.concatenate([np.column_stack(v) for v in ((c, s, z), (c, z, s), (z, c, s))])
    lines = np.concatenate(
        [np.r_[n + 1, np.arange(k * (n + 1), (k + 1) * (n + 1))] for k in range(3)]
    )
    return poly(pts, lines=lines, verts=point_cells(len(pts)))


class BallsPainter(Painter3D):
    """The balls, their names, the selection and the tangent cones (the module docstring)."""

    def __init__(self, scene_ren, eyes_ren) -> None:
        super().__init__(scene_ren, eyes_ren)
        self.unit_ball = sphere(1.0, theta_resolution=40, phi_resolution=24)
        self.unit_ring = _great_circles(RING)
        self.ball_actors: list[vtkActor] = []
        self.ball_labels: list = []
        self.select_actor: vtkActor | None = None
        self.cones: vtkPolyData | None = None
        self.cone_actor: vtkActor | None = None
        self.near_cones = poly()
        self.near_cone_actor: vtkActor = actor(self.near_cones)

    def _build(self, scene: Scene) -> None:
        self.store.clear()
        self.ball_actors, self.ball_labels = [], []
        for f in scene.features:
            a = lit(actor(self.unit_ball, rgbf(f.color)), 0.35, 0.7)
            self.add(a, eyes=False)
            self.ball_actors.append(a)
            lab = text3d(LABEL_PX, rgbf(f.color))
            lab.GetTextProperty().SetJustificationToLeft()
            lab.GetTextProperty().SetVerticalJustificationToBottom()
            lab.SetInput(f.name)
            self.add(lab, eyes=False)
            self.ball_labels.append(lab)
        n = len(scene.features)
        sel = actor(self.unit_ring, SELECT_RGB)
        sel.GetProperty().SetLineWidth(2.0)
        self.add(sel, eyes=False)
        self.select_actor = sel
        # the tangent cones: 2 per ball, cells coloured by ball
        res = CONE_RES
        faces = shapes3d.cone_faces(res).reshape(res, 4)
        allf = np.concatenate(
            [faces + np.array([0, 1, 1, 1]) * k * (res + 1) for k in range(2 * n)]
            or [np.zeros((0, 4), dtype=int)]
        )
        zeros = np.zeros((max(2 * n, 1) * (res + 1), 3))
        self.cones = poly(zeros, allf.ravel() if n else None)
        if n:
            cols = np.repeat(palette(scene)[:n], res, axis=0)
            set_rgb(self.cones.GetCellData(), np.concatenate([cols, cols]))
        self.cone_actor = actor(self.cones, rgb=bool(n))
        self.cone_actor.GetProperty().SetOpacity(CONE_OPACITY)
        self.add(self.cone_actor, eyes=False)
        # in the eyes' close-up, the cones' first EYE_CONE eye radii only
        # (a mesh of its own: a shallow copy would share the points written in place)
        self.near_cones = poly(zeros, allf.ravel() if n else None)
        if n:
            set_rgb(self.near_cones.GetCellData(), np.concatenate([cols, cols]))
        self.near_cone_actor = actor(self.near_cones, rgb=bool(n))
        self.near_cone_actor.GetProperty().SetOpacity(CONE_OPACITY)
        self.add(self.near_cone_actor, scene=False)

    def named(
        self, state: SceneState3D, others: np.ndarray, dpi: int, selected: int | None
    ) -> tuple[list[int], Named3D]:
        """The shown ball names and what they must not cover (every ball, ``others``: the
        eyes, the ghosts), for :mod:`eyeviz.render.vtk.names3d`; the selected ball's first."""
        c = np.column_stack([state.x, state.y, state.z]) if state.n else np.zeros((0, 3))
        labs = self.ball_labels[: state.n]
        g = np.array(state.g[: len(labs)], float)
        if selected is not None and 0 <= selected < len(g):
            g[selected] *= RING  # the selection's great circles are wider than the ball
        return named_of(labs, c[: len(labs)], g, others, dpi, first=selected)

    def update(
        self, scene: Scene, state: SceneState3D, selected: int | None, surface: EyeSurface
    ) -> None:
        key = (tuple((f.name, f.color) for f in scene.features), surface.key)
        if key != self.key:
            self._build(scene)
            self.key = key
        n = state.n
        show_f = scene.shows("features")
        for i, a in enumerate(self.ball_actors):
            a.SetVisibility(show_f)
            a.SetPosition(state.x[i], state.y[i], state.z[i])
            a.SetScale(state.g[i])
            lab = self.ball_labels[i]
            lab.SetVisibility(show_f and scene.shows("labels"))
            lab.SetPosition(state.x[i], state.y[i], state.z[i])  # moved aside: names3d
        sel = self.select_actor
        if sel is not None:
            on = show_f and selected is not None and 0 <= selected < n
            sel.SetVisibility(on)
            if on:
                assert selected is not None
                sel.SetPosition(state.x[selected], state.y[selected], state.z[selected])
                sel.SetScale(state.g[selected])
        if self.cones is None or self.cone_actor is None:
            return
        on = scene.shows("tangents") and n > 0
        self.cone_actor.SetVisibility(on)
        self.near_cone_actor.SetVisibility(on)
        if on:
            apex = np.repeat(np.asarray(surface.centres, dtype=np.float64), n, axis=0)
            c = np.column_stack([state.x, state.y, state.z])
            pts = shapes3d.tangent_cones(
                apex, np.concatenate([c, c]), np.concatenate([state.g, state.g]), CONE_RES
            )
            write_points(self.cones, pts)
            write_points(
                self.near_cones, shapes3d.shorten_cones(pts, CONE_RES, EYE_CONE * surface.radius)
            )
