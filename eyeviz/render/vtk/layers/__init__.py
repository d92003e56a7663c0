"""The app view's layers, one module each; each draws only a
:class:`eyeviz.model.frame.Frame`.

A VTK painter (the ``vtk`` hook of the layer table, :mod:`eyeviz.model.layers`) is a class
made once per view as ``cls(main_renderer, inset_renderer)``; it adds its actors to the
renderers it draws in, and ``draw(frame, selected)`` draws the layer's part of the Frame,
or hides its actors when ``frame.layers`` does not show the layer. :func:`painters` makes
the painters of one stage of the view in the table's VTK order.
"""

from __future__ import annotations

from typing import Protocol

from eyeviz.model.frame import Frame
from eyeviz.model.layers import ordered, resolve

__all__ = ["Painter", "painters"]


class Painter(Protocol):
    def draw(self, frame: Frame, selected: int | None) -> None: ...


def painters(stage: str, main, inset) -> dict[str, Painter]:
    """name -> painter of every layer of the table whose ``vtk_stage`` is ``stage``
    ("scene" or "overlay"), made in the table's VTK order (that is the order their actors
    first enter the renderers)."""
    return {
        spec.name: resolve(spec.vtk)(main, inset)
        for spec in ordered("vtk")
        if spec.vtk_stage == stage
    }
