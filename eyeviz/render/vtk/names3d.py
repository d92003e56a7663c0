"""The 3D view's names (balls', eyes') moved beside what they name before each render.

Each name is a billboard text anchored at its sphere's centre; before the renderer draws,
:func:`place_texts` asks :func:`eyeviz.model.labels3d.place_named` (the one placement the
exported figures use too) where each name's box goes through the renderer's camera, and
sets the text's display offset there (pixels, so no actor is rebuilt: a drag or a turn
of the camera only moves them). Text sizes come from VTK's own text renderer.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from vtkmodules.util.numpy_support import numpy_to_vtk
from vtkmodules.vtkCommonCore import vtkPoints
from vtkmodules.vtkCommonDataModel import vtkCellArray, vtkPolyData
from vtkmodules.vtkRenderingCore import (
    vtkActor2D,
    vtkBillboardTextActor3D,
    vtkCoordinate,
    vtkPolyDataMapper2D,
    vtkRenderer,
)

from eyeviz.model.camera3d import Camera3D
from eyeviz.model.labels3d import Named3D, discs, leaders, place_named
from eyeviz.render.vtk.primitives import text_size

__all__ = ["Leaders", "named_of", "place_texts"]


def named_of(
    labels: Sequence[vtkBillboardTextActor3D],
    centres: np.ndarray,
    radii: np.ndarray,
    others: np.ndarray,
    dpi: int,
    *,
    below: bool = False,
    first: int | None = None,
) -> tuple[list[int], Named3D]:
    """The shown names among ``labels`` (sphere i named by ``labels[i]``) as a
    :class:`Named3D`, ``first`` (the selected ball) placed first; the spheres whose names
    are hidden join ``others``. Returns (the shown labels' indices in placing order, it)."""
    shown = [i for i, t in enumerate(labels) if t.GetVisibility() and t.GetInput()]
    if first in shown:
        shown.remove(first)
        shown.insert(0, first)
    sizes = []
    for i in shown:
        s = text_size(labels[i].GetTextProperty(), labels[i].GetInput(), dpi)
        sizes.append(s if s is not None else (0, 0))
    c = np.asarray(centres, float).reshape(-1, 3)
    r = np.asarray(radii, float).reshape(-1)
    hidden = [i for i in range(len(labels)) if i not in shown]
    oth = np.concatenate(
        [np.asarray(others, float).reshape(-1, 4), np.column_stack([c[hidden], r[hidden]])]
    )
    named = Named3D(c[shown], r[shown], np.asarray(sizes, float).reshape(-1, 2), oth, below=below)
    return shown, named


def place_texts(
    ren: vtkRenderer,
    cam: Camera3D,
    labels: Sequence[vtkBillboardTextActor3D],
    named: Named3D,
    order: list[int],
    *,
    give_way: bool = True,
) -> np.ndarray:
    """Set each shown label's display offset so its box lands where
    :func:`place_named` puts it in ``ren``'s viewport (a name whose sphere is out of the
    viewport or behind the camera, or that gives way to an earlier name (``give_way``,
    as in :func:`eyeviz.model.labels3d.place_boxes`), made transparent); returns the
    boxes (pixels of the viewport, y up), one per ``order`` entry."""
    w, h = ren.GetSize()
    if w <= 0 or h <= 0 or not order:
        return np.zeros((0, 4))
    boxes = place_named(named, cam, float(w), float(h), give_way=give_way)
    at, _ = discs(cam, named.centres, named.radii, float(w), float(h))
    show_at(labels, order, boxes, at)
    return boxes


class Leaders:
    """The leader lines of a viewport's names (:func:`eyeviz.model.labels3d.leaders`):
    one 2D actor, its lines in the viewport's pixels, each in its name's colour."""

    def __init__(self, ren: vtkRenderer, width: float = 2.0) -> None:
        self.poly = vtkPolyData()
        coord = vtkCoordinate()
        coord.SetCoordinateSystemToViewport()
        mapper = vtkPolyDataMapper2D()
        mapper.SetInputData(self.poly)
        mapper.SetTransformCoordinate(coord)
        mapper.SetScalarModeToUseCellData()
        mapper.SetColorModeToDirectScalars()
        self.actor = vtkActor2D()
        self.actor.SetMapper(mapper)
        self.actor.GetProperty().SetLineWidth(width)
        self.segments = np.zeros((0, 4))
        ren.AddViewProp(self.actor)
        self.set(np.zeros((0, 4)), [])

    def set(self, segments: np.ndarray, colours: Sequence) -> None:
        """Draw ``segments`` (n, 4: x0, y0, x1, y1, pixels, y up; NaN rows skipped) in
        ``colours`` (n rgb triples, 0-1)."""
        seg = np.asarray(segments, float).reshape(-1, 4)
        keep = np.isfinite(seg).all(axis=1)
        seg = seg[keep]
        rgb = np.asarray(colours, float).reshape(-1, 3)[keep] if len(seg) else np.zeros((0, 3))
        self.segments = seg
        pts = vtkPoints()
        lines = vtkCellArray()
        for k, (x0, y0, x1, y1) in enumerate(seg):
            pts.InsertNextPoint(x0, y0, 0.0)
            pts.InsertNextPoint(x1, y1, 0.0)
            lines.InsertNextCell(2)
            lines.InsertCellPoint(2 * k)
            lines.InsertCellPoint(2 * k + 1)
        self.poly.SetPoints(pts)
        self.poly.SetLines(lines)
        cols = numpy_to_vtk(np.round(rgb * 255).astype(np.uint8).reshape(-1, 3), deep=True)
        cols.SetName("rgb")
        self.poly.GetCellData().SetScalars(cols)
        self.poly.Modified()
        self.actor.SetVisibility(bool(len(seg)))

    def draw_for(
        self, cam: Camera3D, named: Named3D, boxes: np.ndarray, colours: Sequence, size
    ) -> None:
        """The leaders of ``named``'s names placed at ``boxes`` (their order) through
        ``cam`` in a viewport of ``size`` (width, height) pixels."""
        w, h = float(size[0]), float(size[1])
        at, rad = discs(cam, named.centres, named.radii, w, h)
        oth = np.asarray(named.others, float).reshape(-1, 4)
        oc, orad = discs(cam, oth[:, :3], oth[:, 3], w, h)
        self.set(leaders(at, rad, boxes, np.column_stack([oc, orad])), colours)


def show_at(
    labels: Sequence[vtkBillboardTextActor3D], order: list[int], boxes: np.ndarray, at: np.ndarray
) -> None:
    """Draw label ``order[k]`` with its box's corner at ``boxes[k]`` (pixels, y up), offset
    from its sphere's disc centre ``at[k]``; a NaN box or centre is made transparent."""
    for k, i in enumerate(order):
        x0, y0 = boxes[k, 0], boxes[k, 1]
        drawn = bool(np.isfinite(x0) and np.isfinite(at[k, 0]))
        labels[i].GetTextProperty().SetOpacity(1.0 if drawn else 0.0)
        if not drawn:
            continue
        labels[i].SetDisplayOffset(int(round(x0 - at[k, 0])), int(round(y0 - at[k, 1])))
