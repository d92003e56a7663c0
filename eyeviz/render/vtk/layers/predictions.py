"""``predictions``: each estimator's ghost disc (radius g) at the Frame's (x_hat, y_hat)
(:class:`eyeviz.model.frame.PredictionFrame`) joined to the true centre, in the estimator's
fixed colour (:func:`eyeviz.model.palette.estimator_color`), never a feature's colour.

The meshes and actors are made once and kept. A drag frame rewrites, in place, only the
points of the rings whose inputs changed (the prediction x_hat, y_hat, the radius g or the
true centre: the dragged feature's; the Predictor answers the others from its row cache,
unchanged); the cells and colours are rebuilt only when the set of drawn rings changes
(an estimator added or dropped, a feature entering or leaving the networks' domain). The
mappers' inputs are never replaced (a new input would make VTK rebuild the shaders).
"""

from __future__ import annotations

import math

import numpy as np
import pyvista as pv
from vtkmodules.util.numpy_support import vtk_to_numpy
from vtkmodules.vtkCommonCore import vtkPoints

from eyeviz.model.frame import Frame
from eyeviz.model.palette import estimator_color
from eyeviz.render.vtk.primitives import actor, set_rgb
from eyeviz.render.vtk.style import Z_LINE, Z_POINT, hex_rgb

__all__ = ["PredictionsLayer", "GHOST_N", "Z_GHOST"]

Z_GHOST = Z_LINE + 0.3
GHOST_N = 96  # points of a ghost circle
_T = np.linspace(0.0, 2 * math.pi, GHOST_N, endpoint=False)
_COS, _SIN = np.cos(_T), np.sin(_T)
_BLOCK = GHOST_N + 2  # points per drawn ghost: its ring, then the truth link's two ends


def _blocks(geo: np.ndarray) -> np.ndarray:
    """(k, _BLOCK, 3) points of k ghosts from rows (x_hat, y_hat, g, x, y): the ring of
    radius g about (x_hat, y_hat), then the link from the true centre (x, y) to it."""
    gx, gy, g, x, y = (geo[:, j : j + 1] for j in range(5))
    out = np.empty((len(geo), _BLOCK, 3))
    out[:, :GHOST_N, 0] = gx + g * _COS
    out[:, :GHOST_N, 1] = gy + g * _SIN
    out[:, GHOST_N, 0], out[:, GHOST_N, 1] = x[:, 0], y[:, 0]
    out[:, GHOST_N + 1, 0], out[:, GHOST_N + 1, 1] = gx[:, 0], gy[:, 0]
    out[..., 2] = Z_GHOST
    return out


def _points(k: int) -> tuple[vtkPoints, np.ndarray]:
    """k float64 VTK points and a numpy view of them (written in place)."""
    pts = vtkPoints()
    pts.SetDataTypeToDouble()  # ghosts lie far from the origin: keep float64
    pts.SetNumberOfPoints(k)
    return pts, vtk_to_numpy(pts.GetData())


class PredictionsLayer:
    """Rings and truth links (one line mesh) and the ghost centres (one point mesh).

    Read by tests: ``builds`` counts structure rebuilds (new cells and colours) and
    ``written`` holds, per estimator, the features whose ring the last update wrote.
    ``skip``: estimators that draw no ring (made for other eyes; the view sets it).
    """

    def __init__(self, main, inset):
        self.ghost_mesh = pv.PolyData()
        self.ghost_actor = actor(self.ghost_mesh, rgb=True)
        self.ghost_actor.GetProperty().SetLineWidth(3.0)
        self.ghost_points = pv.PolyData()
        self.ghost_point_actor = actor(self.ghost_points, rgb=True)
        gp = self.ghost_point_actor.GetProperty()
        gp.SetRepresentationToPoints()
        gp.SetPointSize(9)
        mapper = self.ghost_point_actor.GetMapper()
        mapper.SetScalarModeToUsePointFieldData()
        self.actors = (self.ghost_actor, self.ghost_point_actor)
        for a in self.actors:
            a.SetVisibility(False)
            main.AddActor(a)
        self.skip: frozenset[str] = frozenset()
        self.ghosts: dict[str, np.ndarray] = {}  # estimator -> (n, 2) ghost centres (NaN: none)
        self.builds = 0
        self.written: dict[str, np.ndarray] = {}
        self._key: tuple | None = None  # the drawn rings: ((name, feature indices), ...)
        self._geo: dict[str, np.ndarray] = {}  # name -> (k, 5) rows drawn (see _blocks)
        self._view = np.zeros((0, 3))  # the line mesh's points
        self._cview = np.zeros((0, 3))  # the centre mesh's points

    def draw(self, frame: Frame, selected: int | None) -> None:
        self.update(frame, self.skip)

    def hide(self) -> None:
        """Nothing drawn (the next update rebuilds)."""
        for a in self.actors:
            a.SetVisibility(False)
        self.ghosts = {}
        self.written = {}
        self._key = None

    def update(self, frame: Frame, skip=frozenset()) -> None:
        """Estimators in ``skip`` (made for other eyes) draw no ring."""
        if "predictions" not in frame.layers or not frame.n:
            self.hide()
            return
        ghosts: dict[str, np.ndarray] = {}
        drawn: list[tuple[str, np.ndarray, np.ndarray]] = []  # name, features, rows
        for name, pf in frame.predictions.items():
            if name in skip or isinstance(pf, str):
                continue
            gx, gy = pf.x_hat, pf.y_hat
            ghosts[name] = np.column_stack([gx, gy])
            i = np.flatnonzero(np.isfinite(gx) & np.isfinite(gy))
            if i.size:
                rows = np.column_stack([gx[i], gy[i], frame.g[i], frame.x[i], frame.y[i]])
                drawn.append((name, i, rows.astype(np.float64)))
        if not drawn:
            self.hide()
            self.ghosts = ghosts
            return
        self.ghosts = ghosts
        key = tuple((name, i.tobytes()) for name, i, _ in drawn)
        if key != self._key:
            self._build(drawn)
            self._key = key
        else:
            self._write(drawn)
        for a in self.actors:
            a.SetVisibility(True)

    def _build(self, drawn: list[tuple[str, np.ndarray, np.ndarray]]) -> None:
        """New cells and colours for the rings in ``drawn``; every point written."""
        self.builds += 1
        geo = np.vstack([rows for _, _, rows in drawn])
        k = len(geo)
        pts, self._view = _points(k * _BLOCK)
        self._view[:] = _blocks(geo).reshape(-1, 3)
        base = _BLOCK * np.arange(k)[:, None]
        ring = base + np.arange(GHOST_N)
        lines = np.column_stack(
            [
                np.full(k, GHOST_N + 1),
                ring,
                ring[:, :1],
                np.full(k, 2),
                base + GHOST_N,
                base + GHOST_N + 1,
            ]
        )
        rgb = np.vstack(
            [np.tile(hex_rgb(estimator_color(name)), (len(i), 1)) for name, i, _ in drawn]
        )
        mesh = self.ghost_mesh
        mesh.SetPoints(pts)
        mesh.lines = lines.ravel()  # per ghost: its ring (closed), then its link
        set_rgb(mesh.GetCellData(), np.repeat(rgb, 2, axis=0))
        mesh.Modified()
        cpts, self._cview = _points(k)
        self._cview[:] = np.column_stack([geo[:, 0], geo[:, 1], np.full(k, Z_POINT)])
        cp = self.ghost_points
        cp.SetPoints(cpts)
        cp.verts = np.column_stack([np.ones(k, np.int64), np.arange(k)]).ravel()
        set_rgb(cp.GetPointData(), rgb)
        cp.Modified()
        self._geo = {name: rows for name, _, rows in drawn}
        self.written = {name: i for name, i, _ in drawn}

    def _write(self, drawn: list[tuple[str, np.ndarray, np.ndarray]]) -> None:
        """Same rings as drawn: rewrite the points of those whose rows changed."""
        self.written = {}
        at = 0  # first ghost of this estimator in the meshes
        changed = False
        for name, i, rows in drawn:
            new = np.flatnonzero((rows != self._geo[name]).any(axis=1))
            self.written[name] = i[new]
            if new.size:
                changed = True
                self._geo[name] = rows
                blocks = _blocks(rows[new])
                view = self._view.reshape(-1, _BLOCK, 3)
                view[at + new] = blocks
                self._cview[at + new, 0] = rows[new, 0]
                self._cview[at + new, 1] = rows[new, 1]
            at += len(i)
        if changed:
            self.ghost_mesh.GetPoints().Modified()
            self.ghost_mesh.Modified()
            self.ghost_points.GetPoints().Modified()
            self.ghost_points.Modified()
