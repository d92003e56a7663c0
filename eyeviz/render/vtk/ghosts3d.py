"""The 3D view's predictions layer in VTK (issue 23 item 4, docs/spherical.md): per
estimator a translucent ghost ball of the true radius at its answer, its outline facing the
camera, its centre and a line from the true centre; the limit's posterior as a cloud of
points, each as opaque as its weight. Drawn from :class:`eyeviz.model.predictions3d.
Predictions3D` only (nothing computed here).

The layer lies in a renderer of its own over the scene's (layer 1 of the render window,
the scene's camera and viewport), as the planar ghosts lie above the discs: at the paper's
distances an answer is within a few percent of the truth, and a ghost inside the opaque
true ball would not show. The actors are made once per estimator and moved by their
transforms; the cloud's points are rewritten only when its samples change.
"""

from __future__ import annotations

import math

import numpy as np
from vtkmodules.util.numpy_support import numpy_to_vtk
from vtkmodules.vtkCommonDataModel import vtkPolyData
from vtkmodules.vtkRenderingCore import vtkActor, vtkFollower, vtkRenderer

from eyeviz.model.predictions3d import LIMIT, Cloud, Predictions3D, estimator_color3d
from eyeviz.render.style3d import (
    CLOUD_PX,
    GHOST_DOT_PX,
    GHOST_LINE_PX,
    GHOST_OPACITY,
    LINK_OPACITY,
)
from eyeviz.render.vtk.primitives import actor, point_cells, poly, sphere, write_points
from eyeviz.render.vtk.style import hex_rgb, rgbf

__all__ = ["Ghosts3D", "make_overlay"]

_RING_N = 96


def make_overlay(scene_ren: vtkRenderer) -> vtkRenderer | None:
    """A renderer over ``scene_ren`` (layer 1 of its window, its camera and viewport), or
    None while ``scene_ren`` has no window."""
    rw = scene_ren.GetRenderWindow()
    if rw is None:
        return None
    ov = vtkRenderer()
    ov.SetLayer(1)
    ov.InteractiveOff()
    ov.SetUseOIT(False)
    ov.SetUseDepthPeeling(False)
    ov.SetActiveCamera(scene_ren.GetActiveCamera())
    ov.SetViewport(*scene_ren.GetViewport())
    if rw.GetNumberOfLayers() < 2:
        rw.SetNumberOfLayers(2)
    rw.AddRenderer(ov)
    return ov


def _unit_circle() -> vtkPolyData:
    t = np.linspace(0.0, 2.0 * math.pi, _RING_N + 1)
    pts = np.column_stack([np.cos(t), np.sin(t), np.zeros_like(t)])
    lines = np.r_[_RING_N + 1, np.arange(_RING_N + 1)]
    return poly(pts, lines=lines, verts=point_cells(_RING_N + 1))


class _Ghost:
    """One estimator's ghost: ball, outline (a follower), centre dot and link."""

    def __init__(self, ren: vtkRenderer, name: str, ball: vtkPolyData, circle: vtkPolyData):
        rgb = rgbf(estimator_color3d(name))
        self.ball = actor(ball, rgb)
        p = self.ball.GetProperty()
        p.SetOpacity(GHOST_OPACITY)
        p.BackfaceCullingOn()
        self.ring = vtkFollower()
        self.ring.SetMapper(actor(circle, rgb).GetMapper())
        self.ring.GetProperty().SetColor(*rgb)
        self.ring.GetProperty().SetLineWidth(GHOST_LINE_PX)
        self.ring.SetCamera(ren.GetActiveCamera())
        self.dot_mesh = poly(np.zeros((1, 3)))
        self.dot = actor(self.dot_mesh, rgb)
        dp = self.dot.GetProperty()
        dp.SetRepresentationToPoints()
        dp.SetPointSize(GHOST_DOT_PX)
        dp.RenderPointsAsSpheresOn()
        self.link_mesh = poly(np.zeros((2, 3)), lines=np.array([2, 0, 1]))
        self.link = actor(self.link_mesh, rgb)
        self.link.GetProperty().SetLineWidth(GHOST_LINE_PX * 0.6)
        self.link.GetProperty().SetOpacity(LINK_OPACITY)
        self.actors: tuple[vtkActor, ...] = (self.ball, self.ring, self.dot, self.link)
        for a in self.actors:
            ren.AddActor(a)

    def show(self, on: bool) -> None:
        for a in self.actors:
            a.SetVisibility(on)

    def place(self, centre: tuple[float, float, float], g: float, truth) -> None:
        self.ball.SetPosition(*centre)
        self.ball.SetScale(g)
        self.ring.SetPosition(*centre)
        self.ring.SetScale(g)
        write_points(self.dot_mesh, np.array([centre], np.float64))
        self.dot_mesh.Modified()
        write_points(self.link_mesh, np.array([truth, centre], np.float64))
        self.link_mesh.Modified()


class Ghosts3D:
    """The layer's actors in ``ren`` (the overlay); ``draw(preds)`` shows ``preds`` or,
    for None, nothing. Read by tests: ``centres`` (estimator -> ghost centre drawn),
    ``cloud_n`` (cloud points drawn)."""

    def __init__(self, ren: vtkRenderer) -> None:
        self.ren = ren
        self.ball = sphere(1.0, theta_resolution=40, phi_resolution=24)
        self.circle = _unit_circle()
        self.ghosts: dict[str, _Ghost] = {}
        self.cloud_mesh = poly()
        self.cloud = actor(self.cloud_mesh)
        mapper = self.cloud.GetMapper()
        mapper.SetScalarModeToUsePointFieldData()
        mapper.SelectColorArray("rgba")
        mapper.SetColorModeToDirectScalars()
        mapper.ScalarVisibilityOn()
        cp = self.cloud.GetProperty()
        cp.SetRepresentationToPoints()
        cp.SetPointSize(CLOUD_PX)
        cp.RenderPointsAsSpheresOn()
        self.cloud.SetVisibility(False)
        ren.AddActor(self.cloud)
        self._cloud_of: Cloud | None = None
        self.centres: dict[str, tuple[float, float, float]] = {}
        self.cloud_n = 0
        self.g = 0.0

    def discs(self) -> np.ndarray:
        """The ghosts shown, (k, 4: x, y, z, radius): what a ball's name must not cover."""
        if not self.centres:
            return np.zeros((0, 4))
        return np.array([(*c, self.g) for c in self.centres.values()], float)

    def draw(self, preds: Predictions3D | None) -> None:
        shown: dict[str, tuple[float, float, float]] = {}
        if preds is not None:
            for a in preds.ghosts():
                gh = self.ghosts.get(a.name)
                if gh is None:
                    gh = self.ghosts[a.name] = _Ghost(self.ren, a.name, self.ball, self.circle)
                gh.place((a.x, a.y, a.z), preds.g, preds.truth)
                shown[a.name] = (a.x, a.y, a.z)
        for name, gh in self.ghosts.items():
            gh.show(name in shown)
        self.centres = shown
        self.g = preds.g if preds is not None else 0.0
        cloud = preds.cloud if preds is not None else None
        if cloud is None or len(cloud.points) == 0:
            self.cloud.SetVisibility(False)
            self.cloud_n = 0
            self._cloud_of = None
            return
        if cloud is not self._cloud_of:
            self._set_cloud(cloud)
            self._cloud_of = cloud
        self.cloud.SetVisibility(True)

    def _set_cloud(self, cloud: Cloud) -> None:
        k = len(cloud.points)
        fresh = poly(np.asarray(cloud.points, np.float64), verts=point_cells(k))
        rgba = np.empty((k, 4), np.uint8)
        rgba[:, :3] = hex_rgb(estimator_color3d(LIMIT))
        rgba[:, 3] = np.clip(np.round(255.0 * cloud.alpha), 1, 255).astype(np.uint8)
        arr = numpy_to_vtk(rgba, deep=1)
        arr.SetName("rgba")
        fresh.GetPointData().AddArray(arr)
        self.cloud_mesh.ShallowCopy(fresh)
        self.cloud_n = k

    def hide(self) -> None:
        self.draw(None)
