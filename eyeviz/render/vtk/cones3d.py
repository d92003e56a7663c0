"""The 3D view's ``cones`` layer (measured eyes, docs/measured.md): the selected ball's lit
facets' acceptance cones -- apex at each lit facet's lens, along its optical axis, of
half its acceptance angle, truncated at the ball's distance -- translucent in the ball's
colour, in both renderers. What a facet "sees" is its cone: the ball lights the facet iff
it meets the cone. One mesh, rebuilt when the selected ball or its lit sets change (a
drag frame: a few cones, :data:`eyeviz.model.shapes3d.MAX_ACCEPTANCE_CONES` at most per
eye).
"""

from __future__ import annotations

import numpy as np

from eyeviz.core.measured import MeasuredEyePair
from eyeviz.model import shapes3d
from eyeviz.model.facets3d import EyeSurface
from eyeviz.model.scene import Scene
from eyeviz.model.state3d import SceneState3D
from eyeviz.render.vtk.painter3d import Painter3D
from eyeviz.render.vtk.primitives import actor, poly
from eyeviz.render.vtk.style import rgbf

__all__ = ["ACCEPTANCE_OPACITY", "ConesPainter"]

ACCEPTANCE_OPACITY = 0.3
RES = 12


class ConesPainter(Painter3D):
    """The selected ball's lit acceptance cones (the module docstring)."""

    def __init__(self, scene_ren, eyes_ren) -> None:
        super().__init__(scene_ren, eyes_ren)
        self.mesh = poly()
        self.cone_actor = actor(self.mesh, (0.5, 0.5, 0.5))
        self.cone_actor.GetProperty().SetOpacity(ACCEPTANCE_OPACITY)
        self.cone_actor.GetProperty().LightingOff()
        self.add(self.cone_actor)
        self.drawn: dict[str, np.ndarray] = {}  # per eye, the facets whose cones are drawn
        self._last: tuple | None = None

    def update(
        self, scene: Scene, state: SceneState3D, selected: int | None, surface: EyeSurface
    ) -> None:
        pair = state.pair
        on = (
            scene.shows("cones")
            and isinstance(pair, MeasuredEyePair)
            and selected is not None
            and 0 <= selected < state.n
            and state.lit_a is not None
        )
        self.cone_actor.SetVisibility(bool(on))
        if not on:
            self._last = None
            return
        assert selected is not None and isinstance(pair, MeasuredEyePair)
        c = (float(state.x[selected]), float(state.y[selected]), float(state.z[selected]))
        lits = {e: state.lit(selected, e) for e in "AB"}
        key = (selected, c, scene.features[selected].color, lits["A"].tobytes(),
               lits["B"].tobytes(), surface.key)  # fmt: skip
        if key == self._last:
            return
        self._last = key
        pts, faces, self.drawn = [], [], {}
        base = 0
        ring = shapes3d.cone_faces(RES).reshape(RES, 4)
        for e in "AB":
            pos, ax, acc = pair.facets(e)
            idx = lits[e]
            p, take = shapes3d.acceptance_cones(pos[idx], ax[idx], acc[idx], c, RES)
            self.drawn[e] = idx[take]
            for k in range(take.size):
                faces.append(ring + np.array([0, 1, 1, 1]) * (base + k * (RES + 1)))
            pts.append(p)
            base += p.shape[0]
        if base == 0:
            self.mesh.ShallowCopy(poly())
        else:
            fresh = poly(np.concatenate(pts), np.concatenate(faces).ravel())
            self.mesh.ShallowCopy(fresh)
        self.cone_actor.GetProperty().SetColor(*rgbf(scene.features[selected].color))
