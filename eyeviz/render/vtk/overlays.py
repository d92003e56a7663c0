"""Issue 6 layers in the app's main view: prediction ghosts, ambiguity region, trajectory.

Each layer is one or two actors whose PolyData is replaced when its content changes (a
few hundred points at most); nothing is drawn for a layer the scene does not show.
Colours are fixed by estimator name (:func:`eyeviz.model.palette.estimator_color`), never
by list position and never a feature's colour.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pyvista as pv
from vtkmodules.vtkRenderingCore import vtkRenderer

from eyeviz.model.frame import build_frame
from eyeviz.model.palette import estimator_color
from eyeviz.render.vtk.actors import INK, Z_LINE, Z_POINT, _actor, hex_rgb

__all__ = ["OverlayActors", "Z_AMBIGUITY", "GHOST_N"]

Z_AMBIGUITY = -1.5  # above the BFV wedge, below the eyes and the features
Z_GHOST = Z_LINE + 0.3
GHOST_N = 96  # points of a ghost circle


def _mix(rgb, amount: float) -> tuple[float, float, float]:
    """``rgb`` (0..255) blended with white: opaque light tints (no translucent passes)."""
    return tuple((amount * c + (1 - amount) * 255) / 255.0 for c in rgb)


def _dark(rgb) -> tuple[float, float, float]:
    return tuple(0.7 * c / 255.0 for c in rgb)


class OverlayActors:
    """Prediction ghosts (rings at (r_hat, phi_hat) joined to the truth), the selected
    feature's ambiguity polygon and the trajectory path, in the main renderer."""

    def __init__(self, main: vtkRenderer):
        self.main = main
        self.ghost_mesh = pv.PolyData()
        self.ghost_actor = _actor(self.ghost_mesh, rgb=True)
        self.ghost_actor.GetProperty().SetLineWidth(3.0)
        self.ghost_points = pv.PolyData()
        self.ghost_point_actor = _actor(self.ghost_points, rgb=True)
        gp = self.ghost_point_actor.GetProperty()
        gp.SetRepresentationToPoints()
        gp.SetPointSize(9)
        self.amb_fill = _actor(pv.PolyData())
        self.amb_line = _actor(pv.PolyData())
        self.amb_line.GetProperty().SetLineWidth(3.5)
        self.path_actor = _actor(pv.PolyData(), (0.35, 0.35, 0.35))
        self.path_actor.GetProperty().SetLineWidth(2.5)
        for a in (
            self.amb_fill,
            self.amb_line,
            self.path_actor,
            self.ghost_actor,
            self.ghost_point_actor,
        ):
            a.SetVisibility(False)
            main.AddActor(a)
        self.ghosts: dict[str, np.ndarray] = {}  # estimator -> (n, 2) ghost centres (NaN: none)
        self.amb_polygon: np.ndarray | None = None
        self._path_key = None

    # --- predictions ------------------------------------------------------------------
    def update_predictions(
        self, scene, state, preds: dict, colors: dict[str, str], skip=frozenset()
    ) -> None:
        """Ghost discs of radius g at each estimator's (r_hat, phi_hat), linked to the truth.

        Each estimator is drawn in its own colour, fixed by name (``colors`` is ignored);
        estimators in ``skip`` (made for other eyes) draw no ring.
        """
        self.ghosts = {}
        show = scene.shows("predictions") and bool(scene.features)
        if not show:
            self.ghost_actor.SetVisibility(False)
            self.ghost_point_actor.SetVisibility(False)
            return
        t = np.linspace(0.0, 2 * math.pi, GHOST_N, endpoint=False)
        pts, lines, cols, centres, ccols = [], [], [], [], []
        k = 0
        light = dataclasses.replace(scene, layers=["predictions"], trajectory=None)
        frame = build_frame(light, state, rect=(0.0, 1.0, 0.0, 1.0), predictions=preds)
        for name in scene.estimators:
            pf = frame.predictions.get(name)
            if name in skip or pf is None or isinstance(pf, str):
                continue
            gx, gy = pf.x_hat, pf.y_hat  # the Frame's (r_hat, phi_hat) in the plane
            self.ghosts[name] = np.column_stack([gx, gy])
            rgb = hex_rgb(estimator_color(name))
            for i in np.flatnonzero(np.isfinite(gx) & np.isfinite(gy)):
                g = state.g[i]
                ring = np.column_stack(
                    [gx[i] + g * np.cos(t), gy[i] + g * np.sin(t), np.full(GHOST_N, Z_GHOST)]
                )
                pts.append(ring)
                lines.append(np.concatenate([[GHOST_N + 1], k + np.arange(GHOST_N), [k]]))
                k += GHOST_N
                pts.append([[state.x[i], state.y[i], Z_GHOST], [gx[i], gy[i], Z_GHOST]])
                lines.append([2, k, k + 1])
                k += 2
                cols += [rgb, rgb]
                centres.append([gx[i], gy[i], Z_POINT])
                ccols.append(rgb)
        if not pts:
            self.ghost_actor.SetVisibility(False)
            self.ghost_point_actor.SetVisibility(False)
            return
        mesh = pv.PolyData(
            np.vstack(pts).astype(np.float64),
            lines=np.concatenate([np.asarray(li) for li in lines]),
        )
        mesh.cell_data["rgb"] = np.array(cols, dtype=np.uint8)
        self.ghost_actor.GetMapper().SetInputData(mesh)
        self.ghost_mesh = mesh
        cp = pv.PolyData(np.array(centres, dtype=np.float64))
        cp.point_data["rgb"] = np.array(ccols, dtype=np.uint8)
        mapper = self.ghost_point_actor.GetMapper()
        mapper.SetInputData(cp)
        mapper.SetScalarModeToUsePointFieldData()
        mapper.SelectColorArray("rgb")
        mapper.SetColorModeToDirectScalars()
        mapper.ScalarVisibilityOn()
        self.ghost_points = cp
        self.ghost_actor.SetVisibility(True)
        self.ghost_point_actor.SetVisibility(True)

    # --- ambiguity --------------------------------------------------------------------
    def update_ambiguity(self, scene, amb: dict | None, color: str | None) -> None:
        poly = None if amb is None else amb["polygon"]
        ok = scene.shows("ambiguity") and poly is not None and len(poly) >= 3
        self.amb_polygon = poly if ok else None
        self.amb_fill.SetVisibility(ok)
        self.amb_line.SetVisibility(ok)
        if not ok:
            return
        k = len(poly)
        pts = np.column_stack([poly, np.full(k, Z_AMBIGUITY)])
        fill = pv.PolyData(pts, faces=np.concatenate([[k], np.arange(k)]))
        line = pv.PolyData(
            pts + [0, 0, Z_LINE + 0.1 - Z_AMBIGUITY],  # over the discs
            lines=np.concatenate([[k + 1], np.arange(k), [0]]),
        )
        self.amb_fill.GetMapper().SetInputData(fill)
        self.amb_line.GetMapper().SetInputData(line)
        rgb = hex_rgb(color or "#555555")
        self.amb_fill.GetProperty().SetColor(*_mix(rgb, 0.28))
        self.amb_line.GetProperty().SetColor(*_dark(rgb))

    # --- trajectory -------------------------------------------------------------------
    def update_trajectory(self, scene, path) -> None:
        """The path of the animated feature (x, y arrays), or hidden."""
        ok = scene.shows("trajectory") and path is not None and path.n >= 2
        self.path_actor.SetVisibility(ok)
        if not ok:
            return
        key = (id(path), path.n)
        if key == self._path_key:
            return
        self._path_key = key
        pts = np.column_stack([path.x, path.y, np.full(path.n, Z_LINE - 0.2)])
        mesh = pv.PolyData(pts, lines=np.concatenate([[path.n], np.arange(path.n)]))
        self.path_actor.GetMapper().SetInputData(mesh)
        self.path_actor.GetProperty().SetColor(*INK)
