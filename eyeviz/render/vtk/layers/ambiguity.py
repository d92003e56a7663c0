"""``ambiguity``: the selected feature's ambiguity region (Frame ``ambiguity``, from
:mod:`eyeviz.core.ambiguity`): an opaque light tint of its colour, outlined over the discs."""

from __future__ import annotations

import numpy as np
import pyvista as pv

from eyeviz.model.frame import Frame
from eyeviz.render.vtk.primitives import actor
from eyeviz.render.vtk.style import Z_AMBIGUITY, Z_LINE, hex_rgb

__all__ = ["AmbiguityLayer"]


def _mix(rgb, amount: float) -> tuple[float, float, float]:
    """``rgb`` (0..255) blended with white: opaque light tints (no translucent passes)."""
    r, g, b = ((amount * c + (1 - amount) * 255) / 255.0 for c in rgb)
    return r, g, b


def _dark(rgb) -> tuple[float, float, float]:
    r, g, b = (0.7 * c / 255.0 for c in rgb)
    return r, g, b


class AmbiguityLayer:
    """One fill and one outline mesh, made once: a new polygon is written into them (the
    mappers' inputs are never replaced); an unchanged polygon and colour write nothing."""

    def __init__(self, main, inset):
        self.fill = pv.PolyData()
        self.line = pv.PolyData()
        self.amb_fill = actor(self.fill)
        self.amb_line = actor(self.line)
        self.amb_line.GetProperty().SetLineWidth(3.5)
        self.actors = (self.amb_fill, self.amb_line)
        for a in self.actors:
            a.SetVisibility(False)
            main.AddActor(a)
        self.polygon: np.ndarray | None = None
        self._key: tuple | None = None

    def draw(self, frame: Frame, selected: int | None) -> None:
        self.update(frame, selected)

    def update(self, frame: Frame, selected: int | None) -> None:
        amb = frame.ambiguity.get(selected) if selected is not None else None
        poly = None if amb is None else amb["polygon"]
        ok = "ambiguity" in frame.layers and poly is not None and len(poly) >= 3
        self.polygon = poly if ok else None
        self.amb_fill.SetVisibility(ok)
        self.amb_line.SetVisibility(ok)
        if not ok or poly is None or selected is None:
            return
        color = frame.colors[selected] if 0 <= selected < frame.n else "#555555"
        poly = np.asarray(poly, dtype=np.float64)
        key = (poly.shape, poly.tobytes(), color)
        if key == self._key:
            return
        self._key = key
        k = len(poly)
        pts = np.column_stack([poly, np.full(k, Z_AMBIGUITY)])
        self.fill.points = pts
        self.fill.faces = np.concatenate([[k], np.arange(k)])
        self.line.points = pts + [0, 0, Z_LINE + 0.1 - Z_AMBIGUITY]  # over the discs
        self.line.lines = np.concatenate([[k + 1], np.arange(k), [0]])
        rgb = hex_rgb(color)
        self.amb_fill.GetProperty().SetColor(*_mix(rgb, 0.28))
        self.amb_line.GetProperty().SetColor(*_dark(rgb))
