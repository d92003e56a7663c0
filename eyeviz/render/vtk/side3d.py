"""The 3D view's corner note saying where the camera looks from and which way round the
eyes are drawn (:func:`eyeviz.model.camera3d.view_side`): the view from ahead is the
mirror image of the facet maps, which show each eye from inside (issue 32)."""

from __future__ import annotations

from vtkmodules.vtkCommonCore import vtkCommand
from vtkmodules.vtkRenderingCore import vtkRenderer, vtkTextActor, vtkTextProperty

from eyeviz.model.camera3d import Camera3D, view_side
from eyeviz.render.vtk.primitives import fit_lines, screen_text, text_size
from eyeviz.render.vtk.style import INK

__all__ = ["SIDE_PX", "SideNote"]

SIDE_PX = 15  # the note's text at text scale 1 (the presenter scales it with the rest)


def _fit_line(tp: vtkTextProperty, line: str, avail: float, dpi: int) -> str:
    """``line`` as it is where it fits ``avail`` pixels, else without "seen ", else that
    broken at spaces into the lines it needs (never cut with "…": "from front, right,…"
    at F11 + F5 + 175 % in 1280 x 720; :func:`eyeviz.render.vtk.primitives.fit_lines`)."""
    for form in (line, line.removeprefix("seen ")):
        size = text_size(tp, form, dpi)
        if size is None or size[0] <= avail:
            return form
    return fit_lines(tp, form, avail, dpi, max_lines=form.count(" ") + 1)


class SideNote:
    """A text actor at the scene viewport's bottom-left corner, updated per camera, its
    lines broken to fit the viewport's width before each render (at F11 + F5 + 175 % in
    1280 x 720, "seen from front, right, above" was cut at the right of sphere_lecture's
    533 px view in steps 2-5): each line as it is, else without "seen ", else broken at
    spaces (then "from front, right,…" was cut in steps 4-5's 450 px view: a line more
    beats a cut word; the names are placed clear of the note as it is drawn)."""

    def __init__(self, ren: vtkRenderer) -> None:
        self.actor: vtkTextActor = screen_text(SIDE_PX, INK, (0.01, 0.015))
        ren.AddViewProp(self.actor)
        self._ren, self._full = ren, ""
        self._fit: tuple | None = None  # what the lines were fitted to
        # before the names are placed clear of it (scene3d's observers, priority 0)
        ren.AddObserver(vtkCommand.StartEvent, self._fit_width, 1.0)

    def update(self, cam: Camera3D) -> None:
        """The note for ``cam`` (set only when its words change)."""
        text = view_side(cam)
        if self._full != text:
            self._full, self._fit = text, None
            self.actor.SetInput(text)

    def show_for(self, cam: Camera3D) -> None:
        """The note for ``cam``, its lines fitted now (before a framing measures it)."""
        self.update(cam)
        self._fit_width()

    def _fit_width(self, *_args) -> None:
        win, width = self._ren.GetRenderWindow(), self._ren.GetSize()[0]
        tp, dpi = self.actor.GetTextProperty(), win.GetDPI() if win is not None else 72
        key = (width, tp.GetFontSize(), dpi, self._full)
        if key == self._fit or width <= 0 or not self._full:
            return
        self._fit = key
        avail = width * (1.0 - 2.0 * self.actor.GetPosition()[0]) - 4.0
        self.actor.SetInput("\n".join(_fit_line(tp, x, avail, dpi) for x in self._full.split("\n")))

    @property
    def text(self) -> str:
        """The whole note (the lines drawn may break it further)."""
        return self._full or str(self.actor.GetInput() or "")
