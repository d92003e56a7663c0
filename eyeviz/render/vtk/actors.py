"""Scene -> VTK actors, updated in place (the app's 2D top view).

:class:`SceneActors` builds ONE :class:`eyeviz.model.frame.Frame` per update and hands it
to the VTK painter of every "scene"-stage layer of the layer table
(:mod:`eyeviz.model.layers`: ``bfv``, ``eyes``, ``features``, ``labels``, ``tangents``,
``sectors``, ``posterior`` and any layer registered before the view was made), in the main
view and the magnified inset of the eyes; the "overlay"-stage layers are
:class:`eyeviz.render.vtk.overlays.OverlayActors`'. Every position drawn is a Frame field:
nothing here or in the painters computes geometry (tests/render/test_vtk_layers.py injects
changes into a Frame and finds them in the actors' points). Meshes are rebuilt only when
their structure changes (m, h or l; the features' names and colours; the layers shown);
otherwise colours and points are written in place.
"""

from __future__ import annotations

import dataclasses
from typing import cast

import numpy as np
import pyvista as pv
from vtkmodules.vtkRenderingCore import vtkRenderer

from eyeviz.model.frame import Frame, build_frame
from eyeviz.model.scene import Scene
from eyeviz.model.state import SceneState
from eyeviz.render.vtk.layers import Painter, painters
from eyeviz.render.vtk.layers.bfv import BFVLayer
from eyeviz.render.vtk.layers.eyes import EyesLayer, mesh_of_rim
from eyeviz.render.vtk.layers.features import FeaturesLayer
from eyeviz.render.vtk.layers.labels import LabelsLayer
from eyeviz.render.vtk.layers.sectors import SectorsLayer
from eyeviz.render.vtk.layers.tangents import TangentsLayer
from eyeviz.render.vtk.style import LABEL_ALL_MAX

__all__ = ["SceneActors", "eye_mesh", "inset_viewport", "view_frame"]

INSET_MIN_PX, INSET_MAX_PX, INSET_FRACTION = 230.0, 340.0, 0.3  # inset width on screen
INSET_ASPECT = 0.66  # height / width: the eyes, their labels and a line of text


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


def view_frame(
    scene: Scene,
    state: SceneState,
    selected: int | None,
    rect: tuple[float, float, float, float] = (0.0, 1.0, 0.0, 1.0),
) -> Frame:
    """The Frame of the view's own layers: the teaching layers and the posterior of the
    selected feature only, the BFV wedge clipped to ``rect`` (the view passes what its
    cameras show); no estimator, ambiguity region or trajectory (the overlay stage's, from
    the app model: :mod:`eyeviz.render.vtk.overlays`), so the predictions layer only greys
    the features outside the estimators' domain here. Beyond LABEL_ALL_MAX features the
    labels layer names the selected feature alone (:mod:`eyeviz.render.vtk.layers.labels`),
    so the Frame holds that one name label (issue 25: 10^4 label objects a drag frame,
    and the garbage collections they caused, were a third of the frame)."""
    light = dataclasses.replace(scene, estimators=[], trajectory=None)
    many = len(scene.features) > LABEL_ALL_MAX
    # (feature 0's without a selection: the one label actor exists, hidden)
    named = [0 if selected is None else selected] if many else None
    return build_frame(
        light, state, rect=rect, predictions={}, ambiguity={}, only=selected, named=named
    )


class SceneActors:
    """All actors of one scene in a main renderer and an inset renderer (the eyes, magnified).

    ``update(scene, state, selected)`` builds the Frame and calls ``draw(frame, selected)``,
    which hands it to each layer's painter (``painters``, in the table's VTK order): they
    rebuild what changed in structure and write colours and points in place otherwise.
    """

    def __init__(self, main: vtkRenderer, inset: vtkRenderer):
        self.main = main
        self.inset = inset
        self.painters: dict[str, Painter] = painters("scene", main, inset)
        self._bfv_scene: Scene | None = None  # the eyes alone, showing bfv or not
        self._bfv_key: tuple | None = None  # (h, l, m, bfv shown) of _bfv_scene
        self._rect: tuple[float, float, float, float] | None = None  # the wedge's, last fit
        self.frame: Frame | None = None

    def layer(self, name: str) -> Painter:
        """The painter of layer ``name``."""
        return self.painters[name]

    @property
    def eyes(self) -> EyesLayer:
        return cast(EyesLayer, self.painters["eyes"])

    @property
    def features(self) -> FeaturesLayer:
        return cast(FeaturesLayer, self.painters["features"])

    @property
    def labels(self) -> LabelsLayer:
        return cast(LabelsLayer, self.painters["labels"])

    @property
    def bfv(self) -> BFVLayer:
        return cast(BFVLayer, self.painters["bfv"])

    @property
    def tangents(self) -> TangentsLayer:
        return cast(TangentsLayer, self.painters["tangents"])

    @property
    def sectors(self) -> SectorsLayer:
        return cast(SectorsLayer, self.painters["sectors"])

    # --- entry points -----------------------------------------------------------------
    def update(self, scene: Scene, state: SceneState, selected: int | None) -> None:
        e = scene.eyes
        key = (e.h, e.l, e.m, scene.shows("bfv"))
        if key != self._bfv_key:
            self._bfv_key = key
            self._bfv_scene = dataclasses.replace(
                scene, eyes=dataclasses.replace(e), features=[], layers=["bfv"] if key[3] else []
            )
        if self._rect is None:
            self._rect = self.visible_rect()
        # the wedge is clipped to the rectangle of the last fit (set_zoom refits it)
        self.draw(view_frame(scene, state, selected, self._rect), selected)

    def draw(self, frame: Frame, selected: int | None) -> None:
        """Draw ``frame`` (the only source of what is drawn)."""
        self.frame = frame
        for p in self.painters.values():
            p.draw(frame, selected)

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
        self._rect = self.visible_rect()
        if self._bfv_scene is None or not self._bfv_scene.shows("bfv"):
            return
        self.bfv.draw(build_frame(self._bfv_scene, rect=self._rect), None)

    # --- the window's other entry points -------------------------------------------------
    def set_zoom(self, main_px_per_unit: float, inset_px_per_unit: float, l: float, m: int):
        """Refit the wedge; the eyes' level of detail (:meth:`EyesLayer.set_zoom`)."""
        self.fit_bfv()
        self.eyes.set_zoom(main_px_per_unit, inset_px_per_unit, l, m)
        self.features.refit()  # the discs' level of detail (issue 25)
        self.labels.place_bfv_text()  # the "m, θ, ψ" line steps aside for a name

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
