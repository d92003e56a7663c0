"""The 3D view's corner note saying where the camera looks from and which way round the
eyes are drawn (:func:`eyeviz.model.camera3d.view_side`): the view from ahead is the
mirror image of the facet maps, which show each eye from inside (issue 32)."""

from __future__ import annotations

from vtkmodules.vtkRenderingCore import vtkRenderer, vtkTextActor

from eyeviz.model.camera3d import Camera3D, view_side
from eyeviz.render.vtk.primitives import screen_text
from eyeviz.render.vtk.style import INK

__all__ = ["SIDE_PX", "SideNote"]

SIDE_PX = 15  # the note's text at text scale 1 (the presenter scales it with the rest)


class SideNote:
    """A text actor at the scene viewport's bottom-left corner, updated per camera."""

    def __init__(self, ren: vtkRenderer) -> None:
        self.actor: vtkTextActor = screen_text(SIDE_PX, INK, (0.01, 0.015))
        ren.AddViewProp(self.actor)

    def update(self, cam: Camera3D) -> None:
        """The note for ``cam`` (set only when its words change)."""
        text = view_side(cam)
        if self.actor.GetInput() != text:
            self.actor.SetInput(text)

    @property
    def text(self) -> str:
        return str(self.actor.GetInput() or "")
