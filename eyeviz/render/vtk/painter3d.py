"""What the 3D view's per-layer painters share (:mod:`eyeviz.render.vtk.scene3d`).

A painter draws one layer (or a few that share actors) of a spherical-side scene in the
view's two renderers, ``scene`` and ``eyes`` (the close-up; None in an overlay view):
it builds its actors when its structure key changes and, every frame, writes positions
and colours in place (``update(scene, state, selected, surface)``). The eye model's
facets come from :func:`eyeviz.model.facets3d.surface_of`; nothing here computes
geometry.
"""

from __future__ import annotations

import numpy as np
from vtkmodules.vtkRenderingCore import vtkActor, vtkRenderer

from eyeviz.model.facets3d import EyeSurface
from eyeviz.model.scene import Scene
from eyeviz.model.state3d import SceneState3D
from eyeviz.render.vtk.primitives import Store
from eyeviz.render.vtk.style import UNLIT, hex_rgb

__all__ = ["Painter3D", "lit", "palette"]


def lit(a: vtkActor, ambient: float = 0.45, diffuse: float = 0.6) -> vtkActor:
    """``a`` shaded by the renderer's lights (no specular highlight)."""
    p = a.GetProperty()
    p.LightingOn()
    p.SetAmbient(ambient)
    p.SetDiffuse(diffuse)
    p.SetSpecular(0.0)
    return a


def palette(scene: Scene) -> np.ndarray:
    """(n + 1, 3) uint8: the balls' colours, then UNLIT (owner -1 indexes the last row)."""
    rows = [hex_rgb(f.color) for f in scene.features] + [tuple(int(v) for v in UNLIT)]
    return np.asarray(rows, dtype=np.uint8)


class Painter3D:
    """A layer's actors in the scene and the close-up renderers (see the module docstring)."""

    def __init__(self, scene_ren: vtkRenderer, eyes_ren: vtkRenderer | None) -> None:
        self.scene_ren = scene_ren
        self.eyes_ren = eyes_ren
        self.store = Store()
        self.key: tuple | None = None

    def add(self, a, scene: bool = True, eyes: bool = True) -> None:
        """Add ``a`` to the scene renderer and/or the close-up (when there is one)."""
        if scene:
            self.store.add(self.scene_ren, a)
        if eyes and self.eyes_ren is not None:
            self.store.add(self.eyes_ren, a)

    def update(
        self, scene: Scene, state: SceneState3D, selected: int | None, surface: EyeSurface
    ) -> None:
        raise NotImplementedError
