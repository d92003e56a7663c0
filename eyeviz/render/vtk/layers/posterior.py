"""``posterior``: the selected feature's posterior density over centres (every g its
bitmaps allow; Frame ``posterior``, :mod:`eyeviz.model.posterior`) as shaded polar cells,
and the limit's estimate, drawn over the ambiguity region and under the features.

The model caches the posterior per key and the mesh is rebuilt only when the key changes,
so a drag that keeps the bitmaps costs one lookup.
"""

from __future__ import annotations

import numpy as np
import pyvista as pv

from eyeviz.model.frame import Frame
from eyeviz.model.palette import POSTERIOR_COLOR, posterior_rgba
from eyeviz.model.posterior import Posterior
from eyeviz.render.vtk.primitives import actor, set_input
from eyeviz.render.vtk.style import Z_POINT, hex_rgb

__all__ = ["PosteriorLayer", "Z_POSTERIOR"]

Z_POSTERIOR = -1.2  # above the ambiguity fill (-1.5), below the eyes (0) and features (1)


class PosteriorLayer:
    """Shaded cells (one quad each, RGBA: opacity grows with density) and a marker at the
    limit's estimate, in the main view."""

    def __init__(self, main, inset):
        self.main = main
        self.cells = actor(pv.PolyData(), rgb=True)
        self.mark = actor(pv.PolyData(), tuple(v / 255.0 for v in hex_rgb(POSTERIOR_COLOR)))
        mp = self.mark.GetProperty()
        mp.SetRepresentationToPoints()
        mp.SetPointSize(11)
        mp.SetRenderPointsAsSpheres(True)
        for a in (self.cells, self.mark):
            a.SetVisibility(False)
            main.AddActor(a)
        self.posterior: Posterior | None = None  # what is drawn (None: nothing)
        self.mesh = pv.PolyData()
        self._key: tuple | None = None

    def draw(self, frame: Frame, selected: int | None) -> None:
        """The Frame's posterior of feature ``selected`` when the layer is shown."""
        post = None
        if "posterior" in frame.layers and selected is not None:
            post = frame.posterior.get(selected)
        if post is None or post.empty:
            self.posterior = None
            self._key = None
            self.cells.SetVisibility(False)
            self.mark.SetVisibility(False)
            return
        self.posterior = post
        key = (post.domain, post.key, post.prior)
        if key != self._key:
            self._key = key
            self._build(post)
        self.cells.SetVisibility(True)
        self.mark.SetVisibility(True)

    def _build(self, post: Posterior) -> None:
        n = post.n
        pts = np.concatenate([post.cells.reshape(-1, 2), np.full((4 * n, 1), Z_POSTERIOR)], 1)
        faces = np.column_stack([np.full(n, 4), np.arange(4 * n).reshape(n, 4)]).ravel()
        mesh = pv.PolyData(pts.astype(np.float64), faces=faces)
        rgba = np.asarray(posterior_rgba(post.density)) * 255.0
        mesh.cell_data["rgb"] = np.round(rgba).astype(np.uint8)
        set_input(self.cells, mesh)
        self.mesh = mesh
        ex, ey = post.estimate
        set_input(self.mark, pv.PolyData(np.array([[ex, ey, Z_POINT - 0.1]])))
