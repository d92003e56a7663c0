"""Scene -> VTK actors, updated in place (the app's 2D top view).

``SceneActors`` owns every actor of the main view and of the magnified inset of the eyes.
Each eye is ONE PolyData of m triangle cells (Figure 2: ommatidium k is the isosceles
triangle between the rim directions k*gamma and (k+1)*gamma, Eq. 6); lighting them only
writes the cell colour array in place (``mesh.cell_data[...][:] = ...``). Meshes are
rebuilt only when their structure changes (m, h or l; the number of features; the layers
shown). Derived geometry comes from the model: the BFV wedge, tangents and sector rays
from a :class:`eyeviz.model.frame.Frame` (painters in ``teaching.py``), colours and
feature positions from a :class:`eyeviz.model.state.SceneState`; what is built here is
only the meshes of the scene's own parameters (the eye triangles of Figure 2, discs).
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pyvista as pv
from vtkmodules.util.numpy_support import numpy_to_vtk, vtk_to_numpy
from vtkmodules.vtkCommonCore import vtkPoints
from vtkmodules.vtkCommonDataModel import vtkCellArray, vtkPolyData
from vtkmodules.vtkCommonMath import vtkMatrix4x4
from vtkmodules.vtkRenderingCore import (
    vtkActor,
    vtkActor2D,
    vtkBillboardTextActor3D,
    vtkCoordinate,
    vtkPolyDataMapper,
    vtkPolyDataMapper2D,
    vtkProp,
    vtkRenderer,
    vtkTextActor,
)

from eyeviz.model.frame import build_frame
from eyeviz.model.scene import Scene
from eyeviz.model.state import SceneState
from eyeviz.render.vtk.teaching import BfvPainter, SectorPainter, TangentPainter

__all__ = ["SceneActors", "hex_rgb", "eye_mesh", "inset_viewport"]

BACKGROUND = (1.0, 1.0, 1.0)
INSET_BACKGROUND = (0.965, 0.965, 0.955)
UNLIT = np.array([225, 225, 225], dtype=np.uint8)
INK = (0.15, 0.15, 0.15)
BFV_FILL = (0.93, 0.91, 0.80)
BFV_LINE = (0.45, 0.42, 0.30)
INSET_MIN_PX, INSET_MAX_PX, INSET_FRACTION = 230.0, 340.0, 0.3  # inset width on screen
INSET_ASPECT = 0.66  # height / width: the eyes, their labels and a line of text
FILL_ALPHA = 0.4
OUT_FILL = np.array([214, 214, 214], dtype=np.uint8)  # a feature outside the domain
OUT_LINE = np.array([140, 140, 140], dtype=np.uint8)
LABEL_ALL_MAX = 6  # more features than this: only the selected one is labelled
EDGE_MIN_PX = 7.0  # draw triangle edges when an ommatidium's rim is at least this wide
Z_BFV, Z_EYES, Z_FEAT, Z_LINE, Z_POINT = -3.0, 0.0, 1.0, 2.0, 3.0
_CIRCLE_N = 160


def _font_file() -> str | None:
    """DejaVu Sans Bold from matplotlib's data (has Greek; VTK's built-in Arial has not)."""
    import importlib.util
    from pathlib import Path

    spec = importlib.util.find_spec("matplotlib")
    if spec is None or spec.origin is None:
        return None
    f = Path(spec.origin).parent / "mpl-data" / "fonts" / "ttf" / "DejaVuSans-Bold.ttf"
    return str(f) if f.exists() else None


FONT_FILE = _font_file()


def style_text(tp, size: int, color) -> None:
    """Bold DejaVu Sans at ``size`` pixels in ``color``."""
    if FONT_FILE:
        tp.SetFontFamily(4)  # VTK_FONT_FILE
        tp.SetFontFile(FONT_FILE)
    tp.SetFontSize(size)
    tp.BoldOn()
    tp.SetColor(*color)


def inset_viewport(w: float, h: float) -> tuple[float, float, float, float]:
    """(xmin, ymin, xmax, ymax) of the eye inset in a w x h pixel view: the bottom-left
    corner (outside the BFV wedge of a view centred on the field of view), ~30 % wide."""
    wpx = min(max(INSET_FRACTION * w, INSET_MIN_PX), INSET_MAX_PX, 0.6 * w)
    hpx = min(INSET_ASPECT * wpx, 0.5 * h)
    return (0.0, 0.0, wpx / max(w, 1.0), hpx / max(h, 1.0))


def hex_rgb(color: str) -> tuple[int, int, int]:
    c = color.lstrip("#")
    return int(c[0:2], 16), int(c[2:4], 16), int(c[4:6], 16)


def _rgbf(color: str) -> tuple[float, float, float]:
    return tuple(v / 255.0 for v in hex_rgb(color))


def eye_mesh(cx: float, l: float, m: int, starts=None) -> pv.PolyData:
    """The m ommatidium triangles of the eye centred at (cx, 0) (Figure 2).

    Cell k spans the rim directions starts[k]*gamma .. starts[k+1]*gamma (default: one cell
    per ommatidium); pooled cells serve as the level of detail of a small eye.
    """
    if starts is None:
        starts = np.arange(m)
    n = len(starts)
    edges = np.append(starts, m)  # rim vertices at every cell boundary
    t = edges * (2.0 * math.pi / m)
    pts = np.zeros((n + 2, 3))
    pts[0] = (cx, 0.0, Z_EYES)
    pts[1:, 0] = cx + l * np.cos(t)
    pts[1:, 1] = l * np.sin(t)
    pts[1:, 2] = Z_EYES
    k = np.arange(n)
    faces = np.column_stack([np.full(n, 3), np.zeros(n, int), k + 1, k + 2]).ravel()
    mesh = pv.PolyData(pts, faces=faces)
    mesh.cell_data["rgb"] = np.tile(UNLIT, (n, 1))
    return mesh


def _pool(owner: np.ndarray, k: int) -> np.ndarray:
    """Owner of each run of k ommatidia: the last feature lighting any of them (or -1)."""
    return owner if k == 1 else np.maximum.reduceat(owner, np.arange(0, owner.shape[0], k))


def _actor(mesh, color=None, rgb: bool = False) -> vtkActor:
    mapper = vtkPolyDataMapper()
    mapper.SetInputData(mesh)
    if rgb:
        mapper.SetScalarModeToUseCellFieldData()
        mapper.SelectColorArray("rgb")
        mapper.SetColorModeToDirectScalars()
        mapper.ScalarVisibilityOn()
    else:
        mapper.ScalarVisibilityOff()
    actor = vtkActor()
    actor.SetMapper(mapper)
    prop = actor.GetProperty()
    prop.LightingOff()
    prop.SetAmbient(1.0)
    prop.SetDiffuse(0.0)
    if color is not None:
        prop.SetColor(*color)
    return actor


def _circle(n: int = _CIRCLE_N) -> np.ndarray:
    t = np.linspace(0.0, 2.0 * math.pi, n, endpoint=False)
    return np.column_stack([np.cos(t), np.sin(t)])


_UNIT = _circle()


def _ring(x: float, y: float, r: float, z: float) -> np.ndarray:
    pts = np.empty((_CIRCLE_N, 3))
    pts[:, 0] = x + r * _UNIT[:, 0]
    pts[:, 1] = y + r * _UNIT[:, 1]
    pts[:, 2] = z
    return pts


def _set_rgb(data, rgb: np.ndarray) -> None:
    """Set the uint8 "rgb" array of point or cell data (may be empty: pyvista refuses)."""
    arr = numpy_to_vtk(np.ascontiguousarray(rgb, dtype=np.uint8).reshape(-1, 3), deep=1)
    arr.SetName("rgb")
    data.AddArray(arr)


def _write_rgb(mesh, rgb: np.ndarray) -> None:
    """Overwrite a mesh's cell "rgb" array in place (a drag frame: pyvista's cell_data
    lookup cost ~0.1 ms a call, 5-6 calls a frame)."""
    arr = mesh.GetCellData().GetAbstractArray("rgb")
    vtk_to_numpy(arr)[:] = rgb
    arr.Modified()


def _unit_ring(z: float) -> pv.PolyData:
    """The closed unit circle at height z (an outline template)."""
    mesh = pv.PolyData(_ring(0.0, 0.0, 1.0, z))
    mesh.lines = np.concatenate([[_CIRCLE_N + 1], np.arange(_CIRCLE_N), [0]])
    return mesh


def _fans(idx: np.ndarray) -> np.ndarray:
    """Triangle fans (VTK cell array) over rings of point ids idx (n, c)."""
    j = np.arange(1, idx.shape[1] - 1)
    return np.stack(np.broadcast_arrays(3, idx[:, :1], idx[:, j], idx[:, j + 1]), axis=-1)


def _unit_fan() -> pv.PolyData:
    """The unit disc as one triangle fan (a fill template)."""
    mesh = pv.PolyData(_ring(0.0, 0.0, 1.0, 0.0))
    mesh.faces = _fans(np.arange(_CIRCLE_N)[None, :]).reshape(-1)
    return mesh


class SceneActors:
    """All actors of one scene in a main renderer and an inset renderer (the eyes, magnified).

    ``update(scene, state, selected)`` is the only entry point: it rebuilds what changed in
    structure and writes colours and coordinates in place otherwise.
    """

    def __init__(self, main: vtkRenderer, inset: vtkRenderer):
        self.main = main
        self.inset = inset
        self._eyes_key = None
        self._feat_key = None
        self.eye_meshes: list[pv.PolyData] = []
        self._eye_actors: list[vtkActor] = []  # [main A, main B, inset A, inset B]
        self._static: list[tuple[vtkRenderer, vtkProp]] = []
        self._lod: dict[tuple[int, int], pv.PolyData] = {}
        self._lod_k = {"main": 1, "inset": 1}
        self.fill_mesh: pv.PolyData | None = None
        self.line_mesh: pv.PolyData | None = None
        self._labels: list[vtkBillboardTextActor3D] = []
        self._feature_props: list[tuple[vtkRenderer, vtkProp]] = []
        self.centers_mesh: pv.PolyData | None = None
        # the selected (dragged) feature: template meshes placed by actor transforms, so a
        # drag uploads no geometry (a transform is a uniform, not a buffer)
        self.handle_mesh = pv.PolyData(np.zeros((1, 3)))
        self.handle_actor = self._points_actor(self.handle_mesh, 13, (0.35, 0.35, 0.35))
        # sight lines (-h, 0) -> (x, y) -> (h, 0): the template (-1, 0) -> (0, 1) -> (1, 0)
        # under the linear map [[h, x], [0, y]]
        self.sight_mesh = pv.PolyData(
            np.array([[-1.0, 0.0, Z_LINE], [0.0, 1.0, Z_LINE], [1.0, 0.0, Z_LINE]]),
            lines=[3, 0, 1, 2],
        )
        self.sight_matrix = vtkMatrix4x4()
        self.sight_actors = [_actor(self.sight_mesh, INK), _actor(self.sight_mesh, INK)]
        for a in self.sight_actors:
            a.GetProperty().SetLineWidth(2.0)
            a.GetProperty().SetLineStipplePattern(0xF0F0)
            a.SetUserMatrix(self.sight_matrix)
        self.sel_mesh = _unit_ring(0.0)
        self.sel_actor = _actor(self.sel_mesh, INK)
        self.sel_actor.GetProperty().SetLineWidth(5.0)
        self.live_fill = _actor(_unit_fan())
        self.live_line = _actor(_unit_ring(0.0))
        self.live_line.GetProperty().SetLineWidth(3.0)
        self.live_center = self._points_actor(pv.PolyData(np.zeros((1, 3))), 11, INK)
        self.live_actors = (self.live_fill, self.live_line, self.live_center)
        for a in self.live_actors:
            a.SetVisibility(False)
            self.main.AddActor(a)
        self.main.AddActor(self.sel_actor)
        self.main.AddActor(self.handle_actor)
        self.main.AddActor(self.sight_actors[0])
        # teaching overlays (Figures 3b, 5-6): tangent rays and sector boundaries
        self.tangents = TangentPainter(Z_LINE)
        self.sectors = SectorPainter(Z_LINE)
        self.tangent_mesh = self.tangents.mesh
        self.sector_mesh = self.sectors.mesh
        self.overlay_actors: dict[str, list[vtkActor]] = {}
        for name, mesh, width, color in (
            ("tangents", self.tangent_mesh, 2.5, INK),
            ("sectors", self.sector_mesh, 2.0, (0.45, 0.45, 0.45)),
        ):
            acts = []
            for ren in (self.main, self.inset):
                a = _actor(mesh, color)
                a.GetProperty().SetLineWidth(width)
                if name == "sectors":
                    a.GetProperty().SetLineStipplePattern(0xFF00)
                ren.AddActor(a)
                acts.append(a)
            self.overlay_actors[name] = acts
        # the tangent angles as a screen-space note under the title: never over the rays
        self.tangent_text = self._screen_text(20, INK, (0.015, 0.90), top=True)
        self.main.AddViewProp(self.tangent_text)
        # theta and psi of the BFV: a line in the inset, or in the main view without it
        self.bfv_text = {
            "inset": self._screen_text(14, BFV_LINE, (0.5, 0.03), center=True),
            "main": self._screen_text(20, BFV_LINE, (0.985, 0.02), right=True),
        }
        self.inset.AddViewProp(self.bfv_text["inset"])
        self.main.AddViewProp(self.bfv_text["main"])
        self.inset_shown = True
        self._main_eye_labels: list[vtkProp] = []
        self.inset.AddActor(self.sight_actors[1])
        self._inset_label = vtkTextActor()
        style_text(self._inset_label.GetTextProperty(), 16, INK)
        self._inset_label.GetTextProperty().SetVerticalJustificationToTop()
        self._inset_label.GetPositionCoordinate().SetCoordinateSystemToNormalizedViewport()
        self._inset_label.SetPosition(0.03, 0.96)
        self.inset.AddViewProp(self._inset_label)
        self._inset_border = self._border_actor()
        self.inset.AddViewProp(self._inset_border)
        self.edges_main = False
        self.edges_inset = False
        self.bfv: BfvPainter | None = None

    # --- construction ---------------------------------------------------------------
    @staticmethod
    def _text(size: int, color, center: bool = False) -> vtkBillboardTextActor3D:
        t = vtkBillboardTextActor3D()
        tp = t.GetTextProperty()
        style_text(tp, size, color)
        if center:
            tp.SetJustificationToCentered()
            tp.SetVerticalJustificationToCentered()
        return t

    @staticmethod
    def _screen_text(size, color, pos, top=False, center=False, right=False) -> vtkTextActor:
        t = vtkTextActor()
        tp = t.GetTextProperty()
        style_text(tp, size, color)
        if top:
            tp.SetVerticalJustificationToTop()
        if center:
            tp.SetJustificationToCentered()
        if right:
            tp.SetJustificationToRight()
        t.GetPositionCoordinate().SetCoordinateSystemToNormalizedViewport()
        t.SetPosition(*pos)
        return t

    def set_inset_shown(self, shown: bool) -> None:
        """Labels of the eyes and of the BFV go to the inset when it is shown, else to the
        main view (where the eyes are then large enough to carry them)."""
        self.inset_shown = bool(shown)
        for t in self._main_eye_labels:
            t.SetVisibility(not shown)
        self._place_bfv_text()

    def _place_bfv_text(self) -> None:
        has = bool(self.bfv_text["main"].GetInput())
        self.bfv_text["inset"].SetVisibility(has and self.inset_shown)
        self.bfv_text["main"].SetVisibility(has and not self.inset_shown)

    @staticmethod
    def _points_actor(mesh, size: float, color) -> vtkActor:
        a = _actor(mesh, color)
        p = a.GetProperty()
        p.SetRepresentationToPoints()
        p.SetPointSize(size)
        p.RenderPointsAsSpheresOn()
        return a

    @staticmethod
    def _border_actor() -> vtkActor2D:
        pts = vtkPoints()
        for x, y in ((0.002, 0.004), (0.998, 0.004), (0.998, 0.996), (0.002, 0.996)):
            pts.InsertNextPoint(x, y, 0)
        lines = vtkCellArray()
        lines.InsertNextCell(5)
        for i in (0, 1, 2, 3, 0):
            lines.InsertCellPoint(i)
        poly = vtkPolyData()
        poly.SetPoints(pts)
        poly.SetLines(lines)
        coord = vtkCoordinate()
        coord.SetCoordinateSystemToNormalizedViewport()
        mapper = vtkPolyDataMapper2D()
        mapper.SetInputData(poly)
        mapper.SetTransformCoordinate(coord)
        actor = vtkActor2D()
        actor.SetMapper(mapper)
        actor.GetProperty().SetColor(*INK)
        actor.GetProperty().SetLineWidth(3)
        return actor

    def _add(self, store, renderer, prop) -> None:
        renderer.AddActor(prop)
        store.append((renderer, prop))

    def _clear(self, store) -> None:
        for renderer, prop in store:
            renderer.RemoveActor(prop)
        store.clear()

    def _build_static(self, scene: Scene) -> None:
        """Eyes, outlines, origin and BFV wedge: depend on h, l, m and the layers only."""
        self._clear(self._static)
        self.eye_meshes, self._eye_actors = [], []
        self._owners = None
        pair = scene.eyes.pair()
        h, l, m = pair.h, pair.l, pair.m
        self.bfv = None
        self._bfv_scene = None
        if scene.shows("bfv"):
            self._bfv_scene = dataclasses.replace(scene, features=[], layers=["bfv"])
            self.bfv = BfvPainter(
                (self.main, self.inset), BFV_FILL, BFV_LINE, Z_BFV, Z_LINE, _actor
            )
            for ren, a in self.bfv.actors:
                self._add(self._static, ren, a)
            self.fit_bfv()
        if scene.shows("eyes"):
            for cx in (-h, h):
                self.eye_meshes.append(eye_mesh(cx, l, m))
            self._lod = {}
            self._lod_k = {"main": 1, "inset": 1}
            for ren in (self.main, self.inset):
                for mesh in self.eye_meshes:
                    a = _actor(mesh, rgb=True)
                    a.GetProperty().SetEdgeColor(0.35, 0.35, 0.35)
                    a.GetProperty().SetLineWidth(1.0)
                    self._add(self._static, ren, a)
                    self._eye_actors.append(a)
            for cx in (-h, h):
                ring = pv.PolyData(_ring(cx, 0.0, l, Z_LINE))
                ring.lines = np.concatenate([[_CIRCLE_N + 1], np.arange(_CIRCLE_N), [0]])
                for ren in (self.main, self.inset):
                    ra = _actor(ring, INK)
                    ra.GetProperty().SetLineWidth(2.0)
                    self._add(self._static, ren, ra)
        origin = pv.PolyData(np.array([[0.0, 0.0, Z_POINT]]))
        self._add(self._static, self.main, self._points_actor(origin, 9, INK))
        self._add(self._static, self.inset, self._points_actor(origin, 9, INK))
        self._main_eye_labels = []
        if scene.shows("labels"):
            for text, (x, y) in (
                ("A", (-h, -1.35 * l)),
                ("B", (h, -1.35 * l)),
                ("O", (0, -1.35 * l)),
            ):
                for ren in (self.inset, self.main):
                    t = self._text(22, INK, center=True)
                    t.SetInput(text)
                    t.SetPosition(x, y, Z_POINT)
                    self._add(self._static, ren, t)
                    if ren is self.main:
                        t.SetVisibility(not self.inset_shown)
                        self._main_eye_labels.append(t)
        self._inset_label.SetInput("")
        text = f"m = {m}"
        if scene.shows("bfv") and scene.shows("labels"):
            deg = 180.0 / math.pi
            text += f"  θ = {pair.theta * deg:.4g}°  ψ = {pair.psi * deg:.4g}°"
        self.bfv_text["inset"].SetInput(text)
        self.bfv_text["main"].SetInput(text if "θ" in text else "")
        self._place_bfv_text()

    def _build_features(self, scene: Scene) -> None:
        """All discs but the selected one in ONE fill mesh and ONE outline mesh (cell
        colours): few draw calls. The selected disc is drawn by the live actors."""
        self._clear(self._feature_props)
        self._labels = []
        self.centers_mesh = self.fill_mesh = self.line_mesh = None
        self._merged_key = None
        if not scene.shows("features") or not scene.features:
            return
        n, c = len(scene.features), _CIRCLE_N
        cols = np.array([hex_rgb(f.color) for f in scene.features], dtype=np.float64)
        # an opaque tint, not alpha: translucency costs whole extra passes in software GL
        tint = np.round(FILL_ALPHA * cols + (1 - FILL_ALPHA) * 255).astype(np.uint8)
        self._feat_rgb = (tint, cols.astype(np.uint8))
        self._rgb_now = self._feat_rgb
        self.grey = np.zeros(n, bool)
        pts = vtkPoints()
        pts.SetDataTypeToDouble()  # features lie far from the origin: keep float64
        pts.SetNumberOfPoints(n * c)
        self._idx = np.arange(n * c).reshape(n, c)
        # triangle fans, not c-gons: VTK would re-triangulate every polygon at each upload
        self._fan_cells = _fans(self._idx)
        self._fan = c - 2
        self.fill_mesh = pv.PolyData()
        self.fill_mesh.SetPoints(pts)
        self.line_mesh = pv.PolyData()
        self.line_mesh.SetPoints(pts)
        fa = _actor(self.fill_mesh, rgb=True)
        la = _actor(self.line_mesh, rgb=True)
        la.GetProperty().SetLineWidth(3.0)
        self._add(self._feature_props, self.main, fa)
        self._add(self._feature_props, self.main, la)
        if scene.shows("labels"):
            for f in scene.features:
                label = vtkBillboardTextActor3D()
                tp = label.GetTextProperty()
                style_text(tp, 22, _rgbf(f.color))
                tp.SetJustificationToLeft()
                tp.SetVerticalJustificationToBottom()
                self._add(self._feature_props, self.main, label)
                self._labels.append(label)
        self.centers_mesh = pv.PolyData(np.zeros((n, 3)))
        self._centers_actor = self._points_actor(self.centers_mesh, 11, None)
        mapper = self._centers_actor.GetMapper()
        mapper.SetScalarModeToUsePointFieldData()
        mapper.SelectColorArray("rgb")
        mapper.SetColorModeToDirectScalars()
        mapper.ScalarVisibilityOn()
        self._add(self._feature_props, self.main, self._centers_actor)

    # --- updates ----------------------------------------------------------------------
    def update(self, scene: Scene, state: SceneState, selected: int | None) -> None:
        eyes_key = (scene.eyes.h, scene.eyes.l, scene.eyes.m, tuple(scene.layers))
        feat_key = (tuple((f.name, f.color) for f in scene.features), tuple(scene.layers))
        if eyes_key != self._eyes_key:
            self._build_static(scene)
            self._eyes_key = eyes_key
        if feat_key != self._feat_key:
            self._build_features(scene)
            self._feat_key = feat_key
        self._update_eyes(scene, state)
        self._update_features(scene, state, selected)
        self._update_overlays(scene, state, selected)

    def _update_overlays(self, scene: Scene, state: SceneState, selected: int | None) -> None:
        """Tangents (Prop. 2, Figure 3b) and sector rays (Eq. 8, 11) of the selected
        feature, from the Frame's TangentFrame / SectorFrame (no geometry here)."""
        ok = selected is not None and 0 <= selected < state.n
        want = [name for name in ("tangents", "sectors") if ok and scene.shows(name)]
        show_t = show_s = False
        if want:
            light = dataclasses.replace(scene, layers=want, estimators=[], trajectory=None)
            frame = build_frame(light, state, rect=(0.0, 1.0, 0.0, 1.0))
            show_t = "tangents" in want and self.tangents.update(frame, selected)
            show_s = "sectors" in want and self.sectors.update(frame, selected)
        for a in self.overlay_actors["tangents"]:
            a.SetVisibility(show_t)
        for a in self.overlay_actors["sectors"]:
            a.SetVisibility(show_s)
        self.tangent_text.SetVisibility(show_t and bool(self.tangents.text))
        if show_t and self.tangents.text:
            self.tangent_text.SetInput(self.tangents.text)

    def _update_eyes(self, scene: Scene, state: SceneState) -> None:
        if not self.eye_meshes:
            return
        colors = tuple(f.color for f in scene.features)
        same_palette = getattr(self, "_palette", None) is not None and colors == self._colors
        if not same_palette:  # built when a colour changes, not every drag frame
            self._colors = colors
            self._palette = np.vstack([UNLIT] + [hex_rgb(c) for c in colors]).astype(np.uint8)
        palette = self._palette
        old = getattr(self, "_owners", None)
        for e, (mesh, owner) in enumerate(
            zip(self.eye_meshes, (state.owner_a, state.owner_b), strict=True)
        ):
            if same_palette and old is not None and np.array_equal(old[e], owner):
                continue  # unchanged: no colour write, so no buffer upload at the next render
            _write_rgb(mesh, palette[owner + 1])
            for (eye, k), lod in self._lod.items():
                if eye == e:
                    _write_rgb(lod, palette[_pool(owner, k) + 1])
        self._owners = (state.owner_a, state.owner_b)

    def _update_features(self, scene: Scene, state: SceneState, selected: int | None) -> None:
        n = len(scene.features)
        has_sel = selected is not None and 0 <= selected < n and scene.shows("features")
        sel = selected if has_sel and self.fill_mesh is not None else None
        if self.fill_mesh is not None:
            self._grey(scene, state)
            tint, cols = self._rgb_now
            others = np.ones(n, bool)
            if sel is not None:
                others[sel] = False
            geo = np.column_stack([state.x, state.y, state.g])[others]
            key = (sel, geo.tobytes(), tint.tobytes(), cols.tobytes())
            if key != self._merged_key:  # not while only the selected feature moves
                self._merged_key = key
                self._write_merged(state, others, tint, cols)
            few = n <= LABEL_ALL_MAX
            for i, (label, f) in enumerate(zip(self._labels, scene.features, strict=False)):
                label.SetVisibility(few or i == selected)
                label.SetInput(f" {f.name}")  # no-op (no Modified) when unchanged
                label.SetPosition(f.x + f.g * 0.75, f.y + f.g * 0.75, Z_POINT)
        for a in self.live_actors:
            a.SetVisibility(sel is not None)
        self.handle_actor.SetVisibility(has_sel)
        self.sel_actor.SetVisibility(has_sel)
        for a in self.sight_actors:
            a.SetVisibility(has_sel)
        if has_sel:
            f = scene.features[selected]
            x, y, g = float(state.x[selected]), float(state.y[selected]), float(state.g[selected])
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
            h = scene.eyes.h
            mat = self.sight_matrix
            if (mat.GetElement(0, 0), mat.GetElement(0, 1), mat.GetElement(1, 1)) != (h, x, y):
                mat.SetElement(0, 0, h)
                mat.SetElement(0, 1, x)
                mat.SetElement(1, 1, y)
                mat.Modified()
            col = _rgbf(f.color)
            self.sel_actor.GetProperty().SetColor(*col)
            for a in self.sight_actors:
                a.GetProperty().SetColor(*col)

    def _write_merged(self, state: SceneState, others: np.ndarray, tint, cols) -> None:
        """The merged fill/outline/centre meshes of every feature but the selected one."""
        n = state.n
        zf = Z_FEAT + 0.9 * np.arange(n) / n
        ring = np.empty((n, _CIRCLE_N, 3))
        ring[..., 0] = state.x[:, None] + state.g[:, None] * _UNIT[None, :, 0]
        ring[..., 1] = state.y[:, None] + state.g[:, None] * _UNIT[None, :, 1]
        ring[..., 2] = zf[:, None]
        pts = self.fill_mesh.GetPoints()
        vtk_to_numpy(pts.GetData())[:] = ring.reshape(-1, 3)
        pts.Modified()
        idx = self._idx[others]
        self.fill_mesh.faces = self._fan_cells[others].reshape(-1)
        _set_rgb(self.fill_mesh.GetCellData(), np.repeat(tint[others], self._fan, axis=0))
        self.line_mesh.lines = np.column_stack(
            [np.full(len(idx), _CIRCLE_N + 1), idx, idx[:, :1]]
        ).ravel()
        _set_rgb(self.line_mesh.GetCellData(), cols[others])
        self.fill_mesh.Modified()
        self.line_mesh.Modified()
        centers = pv.PolyData(np.column_stack([state.x, state.y, np.full(n, Z_POINT)])[others])
        _set_rgb(centers.GetPointData(), cols[others])
        self.centers_mesh = centers
        self._centers_actor.GetMapper().SetInputData(centers)

    def fill_rgb(self, i: int) -> np.ndarray:
        """The fill colour feature i is drawn in."""
        return self._rgb_now[0][i]

    def _grey(self, scene: Scene, state: SceneState) -> None:
        """With the predictions layer, features outside the networks' domain (not in the
        BFV or not seen by both eyes) are drawn grey."""
        grey = None
        if scene.shows("predictions") and state.in_bfv is not None and state.n:
            grey = ~state.in_domain()
        if grey is None or not grey.any():
            self._rgb_now = self._feat_rgb
            self.grey = np.zeros(state.n, bool)
            return
        tint, cols = (a.copy() for a in self._feat_rgb)
        tint[grey] = OUT_FILL
        cols[grey] = OUT_LINE
        self._rgb_now = (tint, cols)
        self.grey = grey

    def visible_rect(self) -> tuple[float, float, float, float]:
        """(x0, x1, y0, y1) covering what the main view and the inset show (their cameras)."""
        xs, ys = [], []
        for ren in (self.main, self.inset):
            cam = ren.GetActiveCamera()
            cx, cy, _ = cam.GetFocalPoint()
            half_h = cam.GetParallelScale()
            half_w = half_h * max(ren.GetTiledAspectRatio(), 1e-3)
            xs += [cx - half_w, cx + half_w]
            ys += [cy - half_h, cy + half_h]
        pad = 0.02 * max(max(xs) - min(xs), max(ys) - min(ys))
        return (min(xs) - pad, max(xs) + pad, min(ys) - pad, max(ys) + pad)

    def fit_bfv(self) -> None:
        """The BFV wedge as the Frame clips it to the visible rectangle (drawn to the
        view's edge at any zoom or pan; issue 12 item 5), points in place."""
        if self.bfv is None:
            return
        self.bfv.update(build_frame(self._bfv_scene, rect=self.visible_rect()))

    def set_zoom(self, main_px_per_unit: float, inset_px_per_unit: float, l: float, m: int):
        """Level of detail by on-screen size: where the eye's rim is narrower than m/2 pixels,
        neighbouring ommatidia are pooled (a pooled cell is lit if any of its ommatidia is, in
        the colour of the last feature lighting it); edges only where a cell is wide enough.
        """
        self.fit_bfv()
        if not self.eye_meshes:
            return
        rim_px = {
            "main": 2 * math.pi * l * main_px_per_unit,
            "inset": 2 * math.pi * l * inset_px_per_unit,
        }
        for which, ren_actors in (("main", self._eye_actors[:2]), ("inset", self._eye_actors[2:])):
            k = max(1, math.ceil(m / max(2.0 * rim_px[which], 8.0)))
            self._lod_k[which] = k
            for e, a in enumerate(ren_actors):
                mesh = self.eye_meshes[e] if k == 1 else self._lod_mesh(e, k)
                if a.GetMapper().GetInput() is not mesh:
                    a.GetMapper().SetInputData(mesh)
                cell_px = rim_px[which] * k / m
                a.GetProperty().SetEdgeVisibility(cell_px >= EDGE_MIN_PX)
        self.edges_main = self._eye_actors[0].GetProperty().GetEdgeVisibility()
        self.edges_inset = self._eye_actors[2].GetProperty().GetEdgeVisibility()
        used = {(e, k) for k in self._lod_k.values() for e in (0, 1)}
        for key in [key for key in self._lod if key not in used]:
            del self._lod[key]

    def _lod_mesh(self, e: int, k: int) -> pv.PolyData:
        if (e, k) not in self._lod:
            src = self.eye_meshes[e]
            cx = float(src.points[0, 0])
            m = src.n_cells
            l = float(np.hypot(src.points[1, 0] - cx, src.points[1, 1]))
            mesh = eye_mesh(cx, l, m, np.arange(0, m, k))
            if getattr(self, "_owners", None) is not None:
                mesh.cell_data["rgb"][:] = self._palette[_pool(self._owners[e], k) + 1]
            self._lod[(e, k)] = mesh
        return self._lod[(e, k)]
