"""``predictions``: each estimator's ghost disc (radius g) at the Frame's (x_hat, y_hat)
(:class:`eyeviz.model.frame.PredictionFrame`) joined to the true centre, in the estimator's
fixed colour (:func:`eyeviz.model.palette.estimator_color`), never a feature's colour."""

from __future__ import annotations

import math

import numpy as np
import pyvista as pv

from eyeviz.model.frame import Frame
from eyeviz.model.palette import estimator_color
from eyeviz.render.vtk.primitives import actor
from eyeviz.render.vtk.style import Z_LINE, Z_POINT, hex_rgb

__all__ = ["PredictionsLayer", "GHOST_N", "Z_GHOST"]

Z_GHOST = Z_LINE + 0.3
GHOST_N = 96  # points of a ghost circle
_T = np.linspace(0.0, 2 * math.pi, GHOST_N, endpoint=False)
_COS, _SIN = np.cos(_T), np.sin(_T)


class PredictionsLayer:
    """Rings and truth links (one line mesh) and the ghost centres (one point mesh)."""

    def __init__(self, main):
        self.ghost_mesh = pv.PolyData()
        self.ghost_actor = actor(self.ghost_mesh, rgb=True)
        self.ghost_actor.GetProperty().SetLineWidth(3.0)
        self.ghost_points = pv.PolyData()
        self.ghost_point_actor = actor(self.ghost_points, rgb=True)
        gp = self.ghost_point_actor.GetProperty()
        gp.SetRepresentationToPoints()
        gp.SetPointSize(9)
        self.actors = (self.ghost_actor, self.ghost_point_actor)
        self.ghosts: dict[str, np.ndarray] = {}  # estimator -> (n, 2) ghost centres (NaN: none)

    def _hide(self) -> None:
        for a in self.actors:
            a.SetVisibility(False)

    def update(self, frame: Frame, skip=frozenset()) -> None:
        """Estimators in ``skip`` (made for other eyes) draw no ring."""
        self.ghosts = {}
        if "predictions" not in frame.layers or not frame.n:
            self._hide()
            return
        pts, lines, cols, centres, ccols = [], [], [], [], []
        k = 0
        for name, pf in frame.predictions.items():
            if name in skip or isinstance(pf, str):
                continue
            gx, gy = pf.x_hat, pf.y_hat
            self.ghosts[name] = np.column_stack([gx, gy])
            rgb = hex_rgb(estimator_color(name))
            for i in np.flatnonzero(np.isfinite(gx) & np.isfinite(gy)):
                g = frame.g[i]
                ring = np.column_stack(
                    [gx[i] + g * _COS, gy[i] + g * _SIN, np.full(GHOST_N, Z_GHOST)]
                )
                pts.append(ring)
                lines.append(np.concatenate([[GHOST_N + 1], k + np.arange(GHOST_N), [k]]))
                k += GHOST_N
                pts.append([[frame.x[i], frame.y[i], Z_GHOST], [gx[i], gy[i], Z_GHOST]])
                lines.append([2, k, k + 1])
                k += 2
                cols += [rgb, rgb]
                centres.append([gx[i], gy[i], Z_POINT])
                ccols.append(rgb)
        if not pts:
            self._hide()
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
        for a in self.actors:
            a.SetVisibility(True)
