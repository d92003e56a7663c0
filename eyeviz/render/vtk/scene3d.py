"""A spherical scene -> VTK actors, updated in place (the app's 3D view and its PNG).

:class:`Scene3DActors` draws a :class:`eyeviz.model.state3d.SceneState3D` in two
renderers side by side: ``scene`` (the balls, the eyes, the binocular field's cones, the
tangent cones and the plane z = 0, through the view's camera) and ``eyes`` (the two eyes
close up, seen from the same direction: at the paper's distances an eye is a few pixels
in the scene, so its facets are shown again where they can be seen;
:func:`eyeviz.model.camera3d.eyes_camera`). Every position drawn comes from
:mod:`eyeviz.model.shapes3d` or the state; nothing here computes geometry.

Layers (:data:`eyeviz.model.scene.SPHERICAL_LAYERS`): ``eyes`` (the facets, lit in the
colour of the ball they see; a facet lit by several balls takes the last one's), ``features``
(the balls, the selected one ringed), ``bfv`` (the 3D field's boundary cones, translucent),
``tangents`` (the tangent cone from each eye centre to each ball), ``plane`` (the plane z = 0
and each eye's equator: that row of facets is the planar eye), ``labels`` (names).

Level of detail: up to :data:`eyeviz.model.shapes3d.FULL_MAX_NSIDE` each eye is one mesh
with one cell per facet, and a frame rewrites its cell colours in place. Beyond (nside 180:
388,800 facets per eye, each under a pixel) the unlit sphere is a smooth mesh drawn once,
and each ball's lit facets are a small mesh of their own (one cell per lit facet at the
scene's nside) rebuilt only when that ball's lit set changes. Balls and their labels move
by their actors' transforms; cones by writing their points in place.
"""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np
import pyvista as pv
from vtkmodules.vtkCommonCore import vtkCommand
from vtkmodules.vtkRenderingCore import vtkActor, vtkRenderer

from eyeviz.files.atomic import atomic_output
from eyeviz.model import shapes3d
from eyeviz.model.camera3d import Camera3D, eyes_camera
from eyeviz.model.predictions3d import Predictions3D
from eyeviz.model.scene import Scene
from eyeviz.model.state3d import SceneState3D, compute_state3d
from eyeviz.render.style3d import (  # the looks the vector view shares (one place)
    BFV_OPACITY,
    BFV_RGB,
    CONE_OPACITY,
    EDGE_RGB,
    EDGES_MAX_NSIDE,
    EYE_CONE,
    EYES_FRACTION,
    PLANE_RGB,
)
from eyeviz.render.vtk.ghosts3d import Ghosts3D, make_overlay
from eyeviz.render.vtk.primitives import (
    Store,
    actor,
    fit_lines,
    screen_text,
    set_rgb,
    text3d,
    text_size,
    write_points,
    write_rgb,
)
from eyeviz.render.vtk.style import BACKGROUND, INK, INSET_BACKGROUND, UNLIT, hex_rgb, rgbf

__all__ = [
    "EYES_FRACTION",
    "LABEL_MARGIN_PX",
    "PNG_ASPECT",
    "Scene3DActors",
    "apply_camera",
    "camera_of",
    "fit_labels",
    "default_camera",
    "png_size",
    "render_png3d",
    "split_viewports",
]

SELECT_RGB = INK
CONE_RES = 40
#: the lit patch of ball i lies at radius l (1 + PATCH_LIFT (1 + i / n)): above the
#: unlit sphere, a later ball's above an earlier one's (the last one's colour wins)
PATCH_LIFT = 0.004
LABEL_PX = 20


def split_viewports(w: float, h: float) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """(eyes, scene) viewports (xmin, ymin, xmax, ymax) of a ``w`` x ``h`` pixel view."""
    f = EYES_FRACTION if w >= 2.0 * h * EYES_FRACTION else 0.5
    return (0.0, 0.0, f, 1.0), (f, 0.0, 1.0, 1.0)


def apply_camera(ren: vtkRenderer, cam: Camera3D) -> None:
    """Put a :class:`Camera3D` into a VTK renderer (clipping range fitted to its props)."""
    c = ren.GetActiveCamera()
    c.SetPosition(*cam.position)
    c.SetFocalPoint(*cam.focal_point)
    c.SetViewUp(*cam.view_up)
    c.SetViewAngle(cam.view_angle)
    c.OrthogonalizeViewUp()
    ren.ResetCameraClippingRange()


def camera_of(ren: vtkRenderer) -> Camera3D:
    """A VTK renderer's camera as a :class:`Camera3D`."""
    c = ren.GetActiveCamera()
    return Camera3D(
        tuple(float(v) for v in c.GetPosition()),  # type: ignore[arg-type]
        tuple(float(v) for v in c.GetFocalPoint()),  # type: ignore[arg-type]
        tuple(float(v) for v in c.GetViewUp()),  # type: ignore[arg-type]
        float(c.GetViewAngle()),
    )


def default_camera(state: SceneState3D, name: str = "default", aspect: float = 1.0) -> Camera3D:
    """The preset ``name`` framing the scene's balls (:func:`shapes3d.scene_extent`) in a
    viewport ``aspect`` (width / height) wide."""
    return shapes3d.view_camera(state, name, aspect)


#: The ball labels' margin to the scene viewport's edges when a preset frames the scene.
LABEL_MARGIN_PX = 6


def fit_labels(
    cam: Camera3D,
    labels: list[tuple[tuple[float, float, float], float, float]],
    size: tuple[float, float],
    margin: float = LABEL_MARGIN_PX,
    steps: int = 16,
) -> Camera3D:
    """``cam`` moved back along its line of sight (10 % of the distance a step, at most
    ``steps``) until every label is inside the viewport of ``size`` (width, height px)
    with ``margin`` pixels to spare. ``labels``: per label its anchor (the model point
    its text's bottom-left corner is drawn at, as the balls' names) and its text's width
    and height in pixels. The presets frame the balls; a name drawn beside a ball at the
    view's edge was cut (sphere_predictions at its default framing)."""
    from eyeviz.model.camera3d import project, to_pixels

    if not labels:
        return cam
    w, h = size
    anchors = np.array([a for a, _, _ in labels], dtype=float)
    tw = np.array([t for _, t, _ in labels], dtype=float)
    th = np.array([t for _, _, t in labels], dtype=float)
    pos, focal = np.asarray(cam.position, float), np.asarray(cam.focal_point, float)
    for _ in range(steps + 1):
        xy, depth = project(cam, anchors, w / max(h, 1.0))
        px = to_pixels(xy, int(round(w)), int(round(h)))
        front = depth > 0
        inside = (
            (px[:, 0] >= margin)
            & (px[:, 0] + tw <= w - margin)
            & (px[:, 1] - th >= margin)
            & (px[:, 1] <= h - margin)
        )
        if bool(np.all(inside | ~front)):
            return cam
        pos = focal + 1.1 * (pos - focal)
        x, y, z = (float(v) for v in pos)
        cam = Camera3D((x, y, z), cam.focal_point, cam.view_up, cam.view_angle)
    return cam


def _great_circles(r: float, n: int = 96) -> pv.PolyData:
    """Three great circles of radius ``r`` (the selected ball's marker)."""
    t = np.linspace(0.0, 2.0 * math.pi, n + 1)
    c, s, z = r * np.cos(t), r * np.sin(t), 0.0 * t
    pts = np.concatenate([np.column_stack(v) for v in ((c, s, z), (c, z, s), (z, c, s))])
    lines = np.concatenate(
        [np.r_[n + 1, np.arange(k * (n + 1), (k + 1) * (n + 1))] for k in range(3)]
    )
    mesh = pv.PolyData(pts)
    mesh.lines = lines
    return mesh


def _aspect(ren: vtkRenderer) -> float:
    """A renderer's width / height in pixels (1 before it has a window)."""
    w, h = ren.GetSize()
    return w / h if w > 0 and h > 0 else 1.0


def _lit(a: vtkActor, ambient: float = 0.45, diffuse: float = 0.6) -> vtkActor:
    p = a.GetProperty()
    p.LightingOn()
    p.SetAmbient(ambient)
    p.SetDiffuse(diffuse)
    p.SetSpecular(0.0)
    return a


def _palette(scene: Scene) -> np.ndarray:
    """(n + 1, 3) uint8: the balls' colours, then UNLIT (owner -1 indexes the last row)."""
    rows = [hex_rgb(f.color) for f in scene.features] + [tuple(int(v) for v in UNLIT)]
    return np.asarray(rows, dtype=np.uint8)


class Scene3DActors:
    """The actors of one 3D view (see the module docstring); ``update`` after each change."""

    def __init__(self, scene_ren: vtkRenderer, eyes_ren: vtkRenderer | None) -> None:
        self.scene_ren = scene_ren
        self.eyes_ren = eyes_ren
        self.renderers = [r for r in (scene_ren, eyes_ren) if r is not None]
        self._eyes_key: tuple | None = None
        self._balls_key: tuple | None = None
        self.eye_store = Store()
        self.field_store = Store()
        self._field_key: tuple | None = None
        self.ball_store = Store()
        self.eye_meshes: list[pv.PolyData] = []  # full LOD: one per eye, cell i = facet i
        self.patches: list[list[tuple[pv.PolyData, vtkActor, np.ndarray]]] = []
        self.ball_actors: list[vtkActor] = []
        self.ball_labels: list = []
        self.cones: pv.PolyData | None = None
        self.cone_actor: vtkActor | None = None
        self.near_cones = pv.PolyData()
        self.near_cone_actor: vtkActor = actor(self.near_cones)
        self.select_actor: vtkActor | None = None
        self.equators: list[vtkActor] = []
        self.eye_labels: list = []
        self.bfv_actor: vtkActor | None = None
        self.plane_actors: list[vtkActor] = []
        self._owner: list[np.ndarray] = []
        self._last: tuple | None = None  # (x, y, z, g) drawn last, per ball
        self.title = screen_text(22, INK, (0.01, 0.985), top=True)
        scene_ren.AddViewProp(self.title)
        # the title is broken into lines that fit the view, checked before each render
        # (the view's width and the title's font size change with the window and F5/Ctrl+=)
        self._title_text = ""
        self._title_fit: tuple | None = None
        scene_ren.AddObserver(vtkCommand.StartEvent, self._fit_title)
        self.eyes_caption = screen_text(16, (0.35, 0.35, 0.35), (0.03, 0.985), top=True)
        if eyes_ren is not None:
            eyes_ren.AddViewProp(self.eyes_caption)
        self.unit_ball = pv.Sphere(radius=1.0, theta_resolution=40, phi_resolution=24)
        self.unit_ring = _great_circles(1.3)
        self.nside = 0
        self.full = True
        # the predictions layer: a renderer over the scene's, made on first use
        self.overlay: vtkRenderer | None = None
        self.ghosts: Ghosts3D | None = None

    # --- structure ---------------------------------------------------------------------
    def _add(self, store: Store, a, scene: bool = True, eyes: bool = True) -> None:
        if scene:
            store.add(self.scene_ren, a)
        if eyes and self.eyes_ren is not None:
            store.add(self.eyes_ren, a)

    def _build_eyes(self, scene: Scene, state: SceneState3D) -> None:
        self.eye_store.clear()
        pair = state.pair
        n = pair.nside
        self.nside = n
        self.full = n <= shapes3d.FULL_MAX_NSIDE
        self.eye_meshes = []
        self._owner = []
        self.equators = []
        self.eye_labels = []
        for cx in (-pair.h, pair.h):
            centre = (cx, 0.0, 0.0)
            if self.full:
                pts, faces = shapes3d.facet_mesh(n, centre, pair.l)
                mesh = pv.PolyData(pts, faces)
                set_rgb(mesh.GetCellData(), np.broadcast_to(UNLIT, (mesh.n_cells, 3)))
                a = _lit(actor(mesh, rgb=True))
                if n <= EDGES_MAX_NSIDE:
                    p = a.GetProperty()
                    p.EdgeVisibilityOn()
                    p.SetEdgeColor(*EDGE_RGB)
                    p.SetLineWidth(1.0)
                self.eye_meshes.append(mesh)
                self._owner.append(np.full(pair.npix, -1, dtype=np.int32))
                self._add(self.eye_store, a)
            # a smooth unlit sphere just inside the facets: the whole eye beyond
            # FULL_MAX_NSIDE, and behind the facets' polygons (which share no points, so
            # the rasteriser leaves pixel cracks between them) up to it
            sphere = pv.Sphere(
                # (inside the flat facets' centres: a facet's sagitta is < 1 - cos(1.2 / n))
                radius=pair.l * (min(0.997, math.cos(1.2 / n)) if self.full else 0.999),
                center=centre,
                theta_resolution=96,
                phi_resolution=48,
            )
            self._add(self.eye_store, _lit(actor(sphere, rgbf("#E1E1E1"))))
            # the equator (plane layer): that ring of facets is the planar eye
            t = np.linspace(0.0, 2.0 * math.pi, 241)
            r = pair.l * 1.012
            ring = pv.lines_from_points(np.column_stack([cx + r * np.cos(t), r * np.sin(t), 0 * t]))
            eq = actor(ring, (0.1, 0.1, 0.1))
            eq.GetProperty().SetLineWidth(2.0)
            self._add(self.eye_store, eq)
            self.equators.append(eq)
            if self.eyes_ren is not None:
                lab = text3d(LABEL_PX, INK, center=True)
                lab.SetInput(f"eye {'A' if cx < 0 else 'B'}")
                lab.SetPosition(cx, 0.0, -1.55 * pair.l)
                self.eye_store.add(self.eyes_ren, lab)
                self.eye_labels.append(lab)
        self.eyes_caption.SetInput(
            f"the eyes close up: nside {n}\n{pair.npix:,} facets each"
            + ("" if self.full else ",\nthe lit ones drawn")
        )

    def _build_field(self, state: SceneState3D, reach: float) -> None:
        """The BFV's cones and the plane z = 0, out to ``reach`` (rebuilt when the balls'
        extent changes by about 40 %, not every frame)."""
        self.field_store.clear()
        pair = state.pair
        pts, faces = shapes3d.bfv_cones(pair.h, pair.l, reach)
        self.bfv_actor = actor(pv.PolyData(pts, faces), BFV_RGB)
        self.bfv_actor.GetProperty().SetOpacity(BFV_OPACITY)
        self._add(self.field_store, self.bfv_actor, eyes=False)
        corners, segs = shapes3d.plane_z0(-reach * 0.8, reach * 0.8, -0.2 * reach, reach)
        quad = pv.PolyData(corners, np.array([4, 0, 1, 2, 3]))
        fill = actor(quad, PLANE_RGB)
        fill.GetProperty().SetOpacity(0.10)
        grid = pv.PolyData(segs.reshape(-1, 3))
        grid.lines = np.column_stack(
            [np.full(len(segs), 2), 2 * np.arange(len(segs)), 2 * np.arange(len(segs)) + 1]
        ).ravel()
        lines = actor(grid, PLANE_RGB)
        lines.GetProperty().SetOpacity(0.6)
        self.plane_actors = [fill, lines]
        for a in self.plane_actors:
            self._add(self.field_store, a, eyes=False)

    def _build_balls(self, scene: Scene, state: SceneState3D) -> None:
        self.ball_store.clear()
        self.ball_actors, self.ball_labels, self.patches = [], [], [[], []]
        self._last = None
        for f in scene.features:
            mapper_mesh = self.unit_ball
            a = _lit(actor(mapper_mesh, rgbf(f.color)), 0.35, 0.7)
            self._add(self.ball_store, a, eyes=False)
            self.ball_actors.append(a)
            lab = text3d(LABEL_PX, rgbf(f.color))
            lab.GetTextProperty().SetJustificationToLeft()
            lab.GetTextProperty().SetVerticalJustificationToBottom()
            lab.SetInput(f" {f.name}")
            self._add(self.ball_store, lab, eyes=False)
            self.ball_labels.append(lab)
        n = len(scene.features)
        sel = actor(self.unit_ring, SELECT_RGB)
        sel.GetProperty().SetLineWidth(2.0)
        self._add(self.ball_store, sel, eyes=False)
        self.select_actor = sel
        # the tangent cones: 2 per ball, cells coloured by ball
        res = CONE_RES
        faces = shapes3d.cone_faces(res).reshape(res, 4)
        allf = np.concatenate(
            [faces + np.array([0, 1, 1, 1]) * k * (res + 1) for k in range(2 * n)]
            or [np.zeros((0, 4), dtype=int)]
        )
        self.cones = pv.PolyData(
            np.zeros((max(2 * n, 1) * (res + 1), 3)), allf.ravel() if n else None
        )
        if n:
            cols = np.repeat(_palette(scene)[:n], res, axis=0)
            set_rgb(self.cones.GetCellData(), np.concatenate([cols, cols]))
        self.cone_actor = actor(self.cones, rgb=bool(n))
        self.cone_actor.GetProperty().SetOpacity(CONE_OPACITY)
        self._add(self.ball_store, self.cone_actor, eyes=False)
        # in the eyes' close-up, the cones' first EYE_CONE eye radii only
        # (a mesh of its own: a shallow copy would share the points written in place)
        self.near_cones = pv.PolyData(np.array(self.cones.points), allf.ravel() if n else None)
        if n:
            set_rgb(self.near_cones.GetCellData(), np.concatenate([cols, cols]))
        self.near_cone_actor = actor(self.near_cones, rgb=bool(n))
        self.near_cone_actor.GetProperty().SetOpacity(CONE_OPACITY)
        self._add(self.ball_store, self.near_cone_actor, scene=False)
        if not self.full:
            for e in range(2):
                for _ in range(n):
                    mesh = pv.PolyData()
                    a = _lit(actor(mesh, (0.5, 0.5, 0.5)))
                    self._add(self.ball_store, a)
                    self.patches[e].append((mesh, a, np.empty(0, np.int64)))

    def label_boxes(self) -> list[tuple[tuple[float, float, float], float, float]]:
        """Each shown ball label's anchor (model point) and text width and height in
        pixels (VTK's own text renderer), for :func:`fit_labels`."""
        dpi = self._dpi()
        out = []
        for lab in self.ball_labels:
            if not lab.GetVisibility() or not lab.GetInput():
                continue
            size = text_size(lab.GetTextProperty(), lab.GetInput(), dpi)
            if size is None:
                continue
            pos = tuple(float(v) for v in lab.GetPosition())
            out.append((pos, float(size[0]), float(size[1])))
        return out  # type: ignore[return-value]

    def _dpi(self) -> int:
        win = self.scene_ren.GetRenderWindow()
        return win.GetDPI() if win is not None else 72

    # --- per frame ---------------------------------------------------------------------
    def _fit_title(self, *_args) -> None:
        """Break the title into lines that fit the scene's viewport (at most two, then
        "…"); refitted only when the view's width, the font size or the title change."""
        ren = self.scene_ren
        width = ren.GetSize()[0]
        tp = self.title.GetTextProperty()
        dpi = self._dpi()
        key = (width, tp.GetFontSize(), dpi)
        if key == self._title_fit or width <= 0:
            return
        self._title_fit = key
        avail = width * (1.0 - 2.0 * self.title.GetPosition()[0]) - 4.0
        self.title.SetInput(fit_lines(tp, self._title_text, avail, dpi))

    def update(self, scene: Scene, state: SceneState3D, selected: int | None) -> None:
        """Draw ``state`` (of ``scene``): structure rebuilt only when it changed."""
        pair = state.pair
        eyes_key = (pair.h, pair.l, pair.nside)
        # the field's reach in steps of 2^0.5 (a drag does not rebuild it every frame)
        step = round(2.0 * math.log2(1.1 * shapes3d.scene_extent(state)))
        field_key = (pair.h, pair.l, step)
        if field_key != self._field_key:
            self._build_field(state, 2.0 ** (step / 2.0 + 0.5))
            self._field_key = field_key
        balls_key = (
            tuple((f.name, f.color) for f in scene.features),
            pair.nside,
        )
        if eyes_key != self._eyes_key:
            self._build_eyes(scene, state)
            self._eyes_key = eyes_key
            self._balls_key = None
        if balls_key != self._balls_key:
            self._build_balls(scene, state)
            self._balls_key = balls_key
        if scene.title != self._title_text:
            self._title_text = scene.title
            self._title_fit = None
            self.title.SetInput(scene.title)
        shows = scene.shows
        n = state.n
        pal = _palette(scene)
        # eyes
        show_eyes = shows("eyes")
        for a in (p for _r, p in self.eye_store.items):
            a.SetVisibility(show_eyes)
        csrs = (state.lit_a, state.lit_b)
        if self.full:
            for e, mesh in enumerate(self.eye_meshes):
                own = self._owner[e]
                shapes3d.facet_owner(state, "AB"[e], own)
                write_rgb(mesh, pal[own])
        else:
            for e in range(2):
                csr = csrs[e]
                for i, (mesh, a, was) in enumerate(self.patches[e]):
                    pix = csr[1][csr[0][i] : csr[0][i + 1]] if csr is not None else was[:0]
                    a.SetVisibility(show_eyes and pix.size > 0)
                    if pix.size == was.size and np.array_equal(pix, was):
                        continue
                    cx = (-pair.h, pair.h)[e]
                    lift = pair.l * (1.0 + PATCH_LIFT * (1.0 + i / max(n, 1)))
                    dn, dpix = shapes3d.patch_facets(pair.nside, pix)
                    pts, faces = shapes3d.facet_mesh(dn, (cx, 0.0, 0.0), lift, dpix, step=1)
                    fresh = pv.PolyData(pts, faces) if pix.size else pv.PolyData()
                    mesh.ShallowCopy(fresh)
                    a.GetProperty().SetColor(*(pal[i] / 255.0))
                    self.patches[e][i] = (mesh, a, pix.copy())
        for eq in self.equators:
            eq.SetVisibility(show_eyes and shows("plane"))
        for lab in self.eye_labels:
            lab.SetVisibility(show_eyes and shows("labels"))
        # balls
        show_f = shows("features")
        for i, a in enumerate(self.ball_actors):
            a.SetVisibility(show_f)
            a.SetPosition(state.x[i], state.y[i], state.z[i])
            a.SetScale(state.g[i])
            lab = self.ball_labels[i]
            lab.SetVisibility(show_f and shows("labels"))
            lab.SetPosition(state.x[i], state.y[i], state.z[i] + state.g[i])
        sel = self.select_actor
        if sel is not None:
            on = show_f and selected is not None and 0 <= selected < n
            sel.SetVisibility(on)
            if on:
                assert selected is not None
                sel.SetPosition(state.x[selected], state.y[selected], state.z[selected])
                sel.SetScale(state.g[selected])
        # cones
        if self.cones is not None and self.cone_actor is not None:
            on = shows("tangents") and n > 0
            self.cone_actor.SetVisibility(on)
            self.near_cone_actor.SetVisibility(on)
            if on:
                apex = np.zeros((2 * n, 3))
                apex[:n, 0], apex[n:, 0] = -pair.h, pair.h
                c = np.column_stack([state.x, state.y, state.z])
                pts = shapes3d.tangent_cones(
                    apex, np.concatenate([c, c]), np.concatenate([state.g, state.g]), CONE_RES
                )
                write_points(self.cones, pts)
                write_points(
                    self.near_cones, shapes3d.shorten_cones(pts, CONE_RES, EYE_CONE * pair.l)
                )
        if self.bfv_actor is not None:
            self.bfv_actor.SetVisibility(shows("bfv"))
        for a in self.plane_actors:
            a.SetVisibility(shows("plane"))

    def draw_predictions(self, preds: Predictions3D | None) -> None:
        """The predictions layer (:mod:`eyeviz.render.vtk.ghosts3d`): ``preds``' ghosts
        and cloud over the scene; None hides them."""
        if preds is None and self.ghosts is None:
            return
        if self.ghosts is None:
            self.overlay = make_overlay(self.scene_ren)
            if self.overlay is None:
                return
            self.ghosts = Ghosts3D(self.overlay)
        self.sync_overlay()
        self.ghosts.draw(preds)

    def sync_overlay(self) -> None:
        """The predictions' renderer keeps the scene's viewport."""
        if self.overlay is not None:
            self.overlay.SetViewport(*self.scene_ren.GetViewport())

    def set_cameras(self, cam: Camera3D) -> None:
        """The scene through ``cam``; the eyes from the same direction, framed."""
        apply_camera(self.scene_ren, cam)
        self.sync_overlay()
        if hasattr(self.scene_ren, "camera_set"):  # pyvista's: no reset at its first render
            self.scene_ren.camera_set = True
        if self.eyes_ren is not None and self._eyes_key is not None:
            h, l = self._eyes_key[0], self._eyes_key[1]
            apply_camera(self.eyes_ren, eyes_camera(cam, h, l, _aspect(self.eyes_ren)))

    def sync_eyes_camera(self, h: float, l: float) -> None:
        """The eyes' camera follows the scene camera's direction (after a rotation)."""
        self.sync_overlay()
        if self.eyes_ren is not None:
            cam = eyes_camera(camera_of(self.scene_ren), h, l, _aspect(self.eyes_ren))
            apply_camera(self.eyes_ren, cam)


def make_renderers(ren_win, scene_ren: vtkRenderer) -> vtkRenderer:
    """Add the eyes' renderer beside ``scene_ren`` in ``ren_win``; returns it."""
    eyes = vtkRenderer()
    eyes.SetUseOIT(False)
    eyes.SetUseDepthPeeling(False)
    eyes.SetBackground(*INSET_BACKGROUND)
    eyes.InteractiveOff()  # the mouse over it turns the scene's camera (it follows)
    eyes.AutomaticLightCreationOn()
    ren_win.AddRenderer(eyes)
    scene_ren.SetBackground(*BACKGROUND)
    return eyes


def layout(scene_ren: vtkRenderer, eyes_ren: vtkRenderer, w: float, h: float) -> None:
    left, right = split_viewports(w, h)
    eyes_ren.SetViewport(*left)
    scene_ren.SetViewport(*right)


#: A PNG's height / width when none is given (the app's window is about as wide).
PNG_ASPECT = 9.0 / 16.0


def png_size(width_px: float, aspect: float | None = None) -> tuple[int, int]:
    """(width, height) pixels of a PNG ``width_px`` wide, ``aspect`` (height / width,
    default :data:`PNG_ASPECT`) high; EyevizError (one line) beyond 64 ... 8192 pixels."""
    from eyeviz import EyevizError

    a = PNG_ASPECT if aspect is None else float(aspect)
    w, h = int(round(width_px)), int(round(width_px * a))
    if not (64 <= w <= 8192 and 64 <= h <= 8192):
        raise EyevizError(
            f"a 3D PNG must be 64 to 8192 pixels wide and high, got {w} x {h} "
            "(change --scale, --width or --aspect)"
        )
    return w, h


def offscreen_view(width: int, height: int) -> tuple[pv.Plotter, Scene3DActors]:
    """An off-screen plotter laid out as the app's 3D view (the scene, the eyes' close-up),
    with no multisampling and no depth peeling, and its empty actors: what
    :func:`render_png3d` and :mod:`eyeviz.render.vtk.png3d` render with. The caller
    closes the plotter."""
    pl = pv.Plotter(off_screen=True, window_size=[width, height], lighting="light kit")
    try:
        ren_win = pl.ren_win
        assert ren_win is not None
        ren_win.SetMultiSamples(0)
        main = pl.renderer
        main.SetUseOIT(False)
        main.SetUseDepthPeeling(False)
        eyes = make_renderers(ren_win, main)
        layout(main, eyes, width, height)
        return pl, Scene3DActors(main, eyes)
    except BaseException:
        pl.close()
        raise


def shoot(pl: pv.Plotter, actors: Scene3DActors, camera: Camera3D, transparent: bool) -> np.ndarray:
    """Render ``pl`` (from :func:`offscreen_view`) through ``camera`` and return its pixels."""
    actors.set_cameras(camera)
    pl.renderer.camera.is_set = True  # else pyvista's first render resets it (an isometric fit)
    return np.asarray(pl.screenshot(return_img=True, transparent_background=transparent))


def render_png3d(
    scene: Scene,
    path: str | os.PathLike,
    camera: Camera3D | None = None,
    width: int = 1600,
    height: int = 900,
    *,
    state: SceneState3D | None = None,
    selected: int | None = None,
    transparent: bool = False,
    predictions: Predictions3D | None = None,
) -> Path:
    """Render a spherical scene off-screen (no display: EGL) to a PNG at ``camera`` (the
    default preset framing the balls when None), ``width`` x ``height`` pixels, written
    atomically; the same picture as the app's 3D view (``transparent``: no background;
    ``predictions``: the predictions layer's content, drawn when the scene shows it)."""
    from eyeviz import EyevizError
    from eyeviz.core.validation import check_int

    if Path(path).suffix.lower() != ".png":
        raise EyevizError(f"render_png3d writes .png files, got {str(path)!r}")
    width = check_int("width", width, ge=64, le=8192)
    height = check_int("height", height, ge=64, le=8192)
    target = Path(path)
    if not (target.parent if str(target.parent) else Path(".")).is_dir():
        raise EyevizError(f"{target}: directory {target.parent} does not exist")
    st = compute_state3d(scene) if state is None else state
    pl, actors = offscreen_view(width, height)
    try:
        actors.update(scene, st, selected)
        actors.draw_predictions(predictions if scene.shows("predictions") else None)
        if camera is None:
            left, _ = split_viewports(width, height)
            camera = default_camera(st, aspect=(1.0 - left[2]) * width / height)
        img = shoot(pl, actors, camera, transparent)
    finally:
        pl.close()
    from PIL import Image

    with atomic_output(target) as tmp:
        Image.fromarray(np.asarray(img)).save(str(tmp), format="PNG")
    return target
