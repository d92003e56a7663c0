"""Scene -> VTK actors, updated in place (the app's 2D top view).

:class:`SceneActors` builds ONE :class:`eyeviz.model.frame.Frame` per update and hands it
to the layer painters of :mod:`eyeviz.render.vtk.layers` (``eyes``, ``features``,
``labels``, ``bfv``, ``tangents``, ``sectors``), in the main view and the magnified inset
of the eyes. Every position drawn is a Frame field: nothing here or in the layers computes
geometry (tests/render/test_vtk_layers.py injects changes into a Frame and finds them in
the actors' points). Meshes are rebuilt only when their structure changes (m, h or l; the
features' names and colours; the layers shown); otherwise colours and points are written
in place.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pyvista as pv
from vtkmodules.vtkRenderingCore import vtkRenderer

from eyeviz.model.frame import Frame, build_frame
from eyeviz.model.scene import Scene
from eyeviz.model.state import SceneState
from eyeviz.render.vtk.layers.bfv import BfvPainter
from eyeviz.render.vtk.layers.eyes import EyesLayer, mesh_of_rim
from eyeviz.render.vtk.layers.features import FeaturesLayer
from eyeviz.render.vtk.layers.labels import LabelsLayer
from eyeviz.render.vtk.layers.sectors import SectorPainter
from eyeviz.render.vtk.layers.tangents import TangentPainter
from eyeviz.render.vtk.primitives import actor, screen_text
from eyeviz.render.vtk.style import (  # noqa: F401  (the view's public style names)
    BACKGROUND,
    BFV_FILL,
    BFV_LINE,
    EDGE_MIN_PX,
    FILL_ALPHA,
    FONT_FILE,
    INK,
    INSET_BACKGROUND,
    LABEL_ALL_MAX,
    OUT_FILL,
    OUT_LINE,
    UNLIT,
    Z_BFV,
    Z_EYES,
    Z_FEAT,
    Z_LINE,
    Z_POINT,
    hex_rgb,
    style_text,
)

__all__ = ["SceneActors", "hex_rgb", "eye_mesh", "inset_viewport", "view_frame"]

_actor = actor  # the name other modules (e.g. a posterior layer) imported before the split

INSET_MIN_PX, INSET_MAX_PX, INSET_FRACTION = 230.0, 340.0, 0.3  # inset width on screen
INSET_ASPECT = 0.66  # height / width: the eyes, their labels and a line of text
_NOT_HERE = ("ambiguity", "trajectory", "posterior")  # overlays.py, posterior.py draw these


def inset_viewport(w: float, h: float) -> tuple[float, float, float, float]:
    """(xmin, ymin, xmax, ymax) of the eye inset in a w x h pixel view: the bottom-left
    corner (outside the BFV wedge of a view centred on the field of view), ~30 % wide."""
    wpx = min(max(INSET_FRACTION * w, INSET_MIN_PX), INSET_MAX_PX, 0.6 * w)
    hpx = min(INSET_ASPECT * wpx, 0.5 * h)
    return (0.0, 0.0, wpx / max(w, 1.0), hpx / max(h, 1.0))


def eye_mesh(cx: float, l: float, m: int, starts=None) -> pv.PolyData:
    """The m ommatidium triangles of the eye centred at (cx, 0) (Figure 2), between the
    rim points of :func:`eyeviz.model.frame.rim_points` (cell k spans starts[k]*gamma ..
    starts[k+1]*gamma; default one cell per ommatidium)."""
    from eyeviz.model.frame import rim_points

    return mesh_of_rim((cx, 0.0), rim_points((cx, 0.0), l, m, starts))


def view_frame(scene: Scene, state: SceneState, selected: int | None) -> Frame:
    """The Frame of the view's own layers (eyes, features, labels, teaching layers of the
    selected feature; the predictions layer only greys features here; the bfv layer gives
    the labels psi and theta, its wedge is drawn by :meth:`SceneActors.fit_bfv` from a
    Frame clipped to the visible rectangle)."""
    light = dataclasses.replace(
        scene,
        layers=[n for n in scene.layers if n not in _NOT_HERE],
        estimators=[],
        trajectory=None,
    )
    return build_frame(light, state, rect=(0.0, 1.0, 0.0, 1.0), predictions={}, only=selected)


class SceneActors:
    """All actors of one scene in a main renderer and an inset renderer (the eyes, magnified).

    ``update(scene, state, selected)`` builds the Frame and calls ``draw(frame, selected)``:
    it rebuilds what changed in structure and writes colours and points in place otherwise.
    """

    def __init__(self, main: vtkRenderer, inset: vtkRenderer):
        self.main = main
        self.inset = inset
        self._eyes_key: tuple | None = None
        self._feat_key: tuple | None = None
        self.eyes = EyesLayer(main, inset)
        self.features = FeaturesLayer(main)
        self.labels = LabelsLayer(main, inset)
        # teaching overlays (Figures 3b, 5-6): tangent rays and sector boundaries
        self.tangents = TangentPainter(Z_LINE)
        self.sectors = SectorPainter(Z_LINE)
        self.overlay_actors: dict[str, list] = {}
        for name, mesh, width, color in (
            ("tangents", self.tangents.mesh, 2.5, INK),
            ("sectors", self.sectors.mesh, 2.0, (0.45, 0.45, 0.45)),
        ):
            acts = []
            for ren in (self.main, self.inset):
                a = actor(mesh, color)
                a.GetProperty().SetLineWidth(width)
                if name == "sectors":
                    a.GetProperty().SetLineStipplePattern(0xFF00)
                ren.AddActor(a)
                acts.append(a)
            self.overlay_actors[name] = acts
        # the tangent angles as a screen-space note under the title: never over the rays
        self.tangent_text = screen_text(20, INK, (0.015, 0.90), top=True)
        self.main.AddViewProp(self.tangent_text)
        inset.AddActor(self.features.sight_actors[1])
        self.bfv: BfvPainter | None = None
        self._bfv_actors: list = []
        self._bfv_scene: Scene | None = None
        self._bfv_key: tuple | None = None
        self.frame: Frame | None = None

    # --- entry points -----------------------------------------------------------------
    def update(self, scene: Scene, state: SceneState, selected: int | None) -> None:
        self._set_bfv(scene)
        self.draw(view_frame(scene, state, selected), selected)

    def draw(self, frame: Frame, selected: int | None) -> None:
        """Draw ``frame`` (the only source of what is drawn)."""
        self.frame = frame
        layers = tuple(sorted(frame.layers))
        pair = frame.pair
        eyes_key = (pair.h, pair.l, pair.m, layers)
        feat_key = (tuple(frame.names), tuple(frame.colors), layers)
        if eyes_key != self._eyes_key:
            self.eyes.build(frame)
            self.labels.build_eyes(frame)
            self._eyes_key = eyes_key
        if feat_key != self._feat_key:
            self.features.build(frame)
            self.labels.build_features(frame)
            self._feat_key = feat_key
        self.eyes.update(frame)
        self.features.update(frame, selected)
        self.labels.update(frame, selected)
        self._draw_teaching(frame, selected)

    def _draw_teaching(self, frame: Frame, selected: int | None) -> None:
        """Tangents (Prop. 2, Figure 3b) and sector rays (Eq. 8, 11) of the selected
        feature, from the Frame's TangentFrame / SectorFrame."""
        ok = selected is not None and 0 <= selected < frame.n
        show_t = ok and "tangents" in frame.layers and self.tangents.update(frame, selected)
        show_s = ok and "sectors" in frame.layers and self.sectors.update(frame, selected)
        for a in self.overlay_actors["tangents"]:
            a.SetVisibility(show_t)
        for a in self.overlay_actors["sectors"]:
            a.SetVisibility(show_s)
        self.tangent_text.SetVisibility(show_t and bool(self.tangents.text))
        if show_t and self.tangents.text:
            self.tangent_text.SetInput(self.tangents.text)

    # --- the BFV wedge (its own Frame: clipped to the visible rectangle) ----------------
    def _set_bfv(self, scene: Scene) -> None:
        key = (scene.eyes.h, scene.eyes.l, scene.eyes.m, scene.shows("bfv"))
        if self._bfv_scene is not None and key == self._bfv_key:
            return
        self._bfv_key = key
        for ren, a in self._bfv_actors:
            ren.RemoveActor(a)
        self._bfv_actors = []
        self.bfv = None
        self._bfv_scene = dataclasses.replace(scene, features=[], layers=["bfv"])
        if scene.shows("bfv"):
            self.bfv = BfvPainter((self.main, self.inset), BFV_FILL, BFV_LINE, Z_BFV, Z_LINE, actor)
            for ren, a in self.bfv.actors:
                ren.AddActor(a)
                self._bfv_actors.append((ren, a))
            self.fit_bfv()

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
        if self.bfv is None or self._bfv_scene is None:
            return
        self.bfv.update(build_frame(self._bfv_scene, rect=self.visible_rect()))

    # --- the window's other entry points -------------------------------------------------
    def set_zoom(self, main_px_per_unit: float, inset_px_per_unit: float, l: float, m: int):
        """Refit the wedge; the eyes' level of detail (:meth:`EyesLayer.set_zoom`)."""
        self.fit_bfv()
        self.eyes.set_zoom(main_px_per_unit, inset_px_per_unit, l, m)

    def set_inset_shown(self, shown: bool, main_eye_labels: bool | None = None) -> None:
        """Labels of the eyes and of the BFV go to the inset when it is shown, else to the
        main view; the eyes' A, O, B there only where ``main_eye_labels`` (the eyes large
        enough on screen to carry them; default: whenever the inset is hidden)."""
        self.labels.set_inset_shown(shown, main_eye_labels)

    @property
    def inset_shown(self) -> bool:
        return self.labels.inset_shown

    def fill_rgb(self, i: int) -> np.ndarray:
        """The fill colour feature i is drawn in."""
        return self.features.fill_rgb(i)

    # --- read by tests (the layers own these) ---------------------------------------------
    @property
    def eye_meshes(self) -> list[pv.PolyData]:
        return self.eyes.meshes

    @property
    def _eye_actors(self) -> list:
        return self.eyes.actors

    @property
    def _lod_k(self) -> dict[str, int]:
        return self.eyes.lod_k

    @property
    def edges_main(self) -> bool:
        return self.eyes.edges_main

    @property
    def edges_inset(self) -> bool:
        return self.eyes.edges_inset

    @property
    def fill_mesh(self) -> pv.PolyData | None:
        return self.features.fill_mesh

    @property
    def line_mesh(self) -> pv.PolyData | None:
        return self.features.line_mesh

    @property
    def centers_mesh(self) -> pv.PolyData | None:
        return self.features.centers_mesh

    @property
    def _fan(self) -> int:
        return self.features.fan

    @property
    def live_fill(self):
        return self.features.live_fill

    @property
    def grey(self) -> np.ndarray:
        return self.features.grey

    @property
    def tangent_mesh(self) -> pv.PolyData:
        return self.tangents.mesh

    @property
    def sector_mesh(self) -> pv.PolyData:
        return self.sectors.mesh
