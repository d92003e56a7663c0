"""VTK building blocks shared by the layers: unlit actors, point and text actors, unit
circle templates, triangle fans. Drawing primitives only: no scene geometry is derived
here (every position a layer draws comes from a :class:`eyeviz.model.frame.Frame`)."""

from __future__ import annotations

import math

import numpy as np
import vtkmodules.vtkRenderingFreeType  # noqa: F401  (vtkTextRenderer's FreeType override)
from vtkmodules.util.numpy_support import numpy_to_vtk, numpy_to_vtkIdTypeArray, vtk_to_numpy
from vtkmodules.vtkCommonCore import vtkPoints
from vtkmodules.vtkCommonDataModel import vtkCellArray, vtkPolyData
from vtkmodules.vtkCommonTransforms import vtkTransform
from vtkmodules.vtkFiltersGeneral import vtkTransformFilter
from vtkmodules.vtkFiltersSources import vtkSphereSource
from vtkmodules.vtkRenderingCore import (
    vtkActor,
    vtkActor2D,
    vtkBillboardTextActor3D,
    vtkCoordinate,
    vtkPolyDataMapper,
    vtkPolyDataMapper2D,
    vtkTextActor,
    vtkTextProperty,
    vtkTextRenderer,
)

from eyeviz.render.vtk.style import INK, style_text

# Text from a scene is drawn as written, as the figures draw it (parse_math=False): VTK's
# text renderer (one instance for the process) sent a string with two "$" to its MathText
# backend, matplotlib's parser, so "cost $5 and $6" lost its dollars and a name "$x^$"
# printed 36 warning lines and no text (issues 35, 36). FreeType draws every string.
vtkTextRenderer().SetDefaultBackend(vtkTextRenderer.FreeType)

__all__ = [
    "CIRCLE_N",
    "UNIT",
    "actor",
    "fit_lines",
    "text_size",
    "points_actor",
    "text3d",
    "screen_text",
    "border_actor",
    "ring",
    "set_rgb",
    "poly",
    "point_cells",
    "polyline",
    "sphere",
    "write_rgb",
    "unit_ring",
    "unit_fan",
    "fans",
    "Store",
]

CIRCLE_N = 160  # vertices of a drawn circle


def actor(mesh, color=None, rgb: bool = False) -> vtkActor:
    """An unlit actor of ``mesh`` in ``color``, or coloured by its cell "rgb" array."""
    mapper = vtkPolyDataMapper()
    mapper.SetInputData(mesh)
    if rgb:
        mapper.SetScalarModeToUseCellFieldData()
        mapper.SelectColorArray("rgb")
        mapper.SetColorModeToDirectScalars()
        mapper.ScalarVisibilityOn()
    else:
        mapper.ScalarVisibilityOff()
    a = vtkActor()
    a.SetMapper(mapper)
    prop = a.GetProperty()
    prop.LightingOff()
    prop.SetAmbient(1.0)
    prop.SetDiffuse(0.0)
    if color is not None:
        prop.SetColor(*color)
    return a


def points_actor(mesh, size: float, color) -> vtkActor:
    a = actor(mesh, color)
    p = a.GetProperty()
    p.SetRepresentationToPoints()
    p.SetPointSize(size)
    p.RenderPointsAsSpheresOn()
    return a


def text3d(size: int, color, center: bool = False) -> vtkBillboardTextActor3D:
    t = vtkBillboardTextActor3D()
    tp = t.GetTextProperty()
    style_text(tp, size, color)
    if center:
        tp.SetJustificationToCentered()
        tp.SetVerticalJustificationToCentered()
    return t


def screen_text(size, color, pos, top=False, center=False, right=False) -> vtkTextActor:
    t = vtkTextActor()
    tp = t.GetTextProperty()
    style_text(tp, size, color)
    if top:
        tp.SetVerticalJustificationToTop()
    if center:
        tp.SetJustificationToCentered()
    if right:
        tp.SetJustificationToRight()
    t.GetPositionCoordinate().SetCoordinateSystemToNormalizedViewport()
    t.SetPosition(*pos)
    return t


def text_size(tp: vtkTextProperty, text: str, dpi: int = 72) -> tuple[int, int] | None:
    """Width and height in pixels of ``text`` drawn with ``tp`` at ``dpi`` (VTK's own text
    renderer, as a text actor draws it); None where it cannot say (an empty text)."""
    box = [0, 0, 0, 0]
    if not vtkTextRenderer().GetBoundingBox(tp, text, box, dpi):
        return None
    return box[1] - box[0], box[3] - box[2]


def fit_lines(
    tp: vtkTextProperty, text: str, width_px: float, dpi: int = 72, max_lines: int = 2
) -> str:
    """``text`` broken at spaces into lines that fit ``width_px`` pixels when drawn with
    ``tp`` at ``dpi`` (a title wider than its view would be cut at the view's edge); past
    ``max_lines`` the last line ends in "…". A word wider than the width stays whole."""
    if width_px <= 0 or not text:
        return text

    def width(s: str) -> int:
        size = text_size(tp, s, dpi)
        return size[0] if size else 0

    if width(text) <= width_px:
        return text
    lines: list[str] = []
    for para in text.split("\n"):
        line = ""
        for word in para.split(" "):
            cand = f"{line} {word}" if line else word
            if line and width(cand) > width_px:
                lines.append(line)
                line = word
            else:
                line = cand
        lines.append(line)
    if len(lines) > max_lines:
        last = " ".join(lines[max_lines - 1 :])
        while last and width(last + "…") > width_px:
            last = last[:-1]
        lines = lines[: max_lines - 1] + [last.rstrip() + "…"]
    return "\n".join(lines)


def border_actor() -> vtkActor2D:
    """A frame around a viewport (the inset's border)."""
    pts = vtkPoints()
    for x, y in ((0.002, 0.004), (0.998, 0.004), (0.998, 0.996), (0.002, 0.996)):
        pts.InsertNextPoint(x, y, 0)
    lines = vtkCellArray()
    lines.InsertNextCell(5)
    for i in (0, 1, 2, 3, 0):
        lines.InsertCellPoint(i)
    poly = vtkPolyData()
    poly.SetPoints(pts)
    poly.SetLines(lines)
    coord = vtkCoordinate()
    coord.SetCoordinateSystemToNormalizedViewport()
    mapper = vtkPolyDataMapper2D()
    mapper.SetInputData(poly)
    mapper.SetTransformCoordinate(coord)
    a = vtkActor2D()
    a.SetMapper(mapper)
    a.GetProperty().SetColor(*INK)
    a.GetProperty().SetLineWidth(3)
    return a


def _circle(n: int = CIRCLE_N) -> np.ndarray:
    t = np.linspace(0.0, 2.0 * math.pi, n, endpoint=False)
    return np.column_stack([np.cos(t), np.sin(t)])


UNIT = _circle()  # the unit circle's CIRCLE_N vertices


def ring(x: float, y: float, r: float, z: float) -> np.ndarray:
    """The CIRCLE_N vertices of the circle of radius r about (x, y) at height z."""
    pts = np.empty((CIRCLE_N, 3))
    pts[:, 0] = x + r * UNIT[:, 0]
    pts[:, 1] = y + r * UNIT[:, 1]
    pts[:, 2] = z
    return pts


def set_rgb(data, rgb: np.ndarray) -> None:
    """Set the uint8 "rgb" array of point or cell data (may be empty: pyvista refuses)."""
    arr = numpy_to_vtk(np.ascontiguousarray(rgb, dtype=np.uint8).reshape(-1, 3), deep=1)
    arr.SetName("rgb")
    data.AddArray(arr)


def read_rgb(mesh) -> np.ndarray:
    """A mesh's cell "rgb" array (a view, not a copy)."""
    return vtk_to_numpy(mesh.GetCellData().GetAbstractArray("rgb"))


def write_rgb(mesh, rgb: np.ndarray) -> None:
    """Overwrite a mesh's cell "rgb" array in place (a drag frame: pyvista's cell_data
    lookup costs ~0.1 ms a call)."""
    arr = mesh.GetCellData().GetAbstractArray("rgb")
    vtk_to_numpy(arr)[:] = rgb
    arr.Modified()


def write_points(mesh: vtkPolyData, pts: np.ndarray) -> None:
    """Overwrite a mesh's points in place and mark them modified."""
    points = mesh.GetPoints()
    data = points.GetData()
    vtk_to_numpy(data)[:] = pts
    data.Modified()
    points.Modified()


# Meshes are made with VTK alone, not pyvista: importing pyvista costs a 3D snapshot about
# 0.2 s (issue 32.14). poly, polyline and sphere make the very meshes pyvista's
# PolyData(points, faces, lines=, verts=), lines_from_points and Sphere make (point for
# point, cell for cell, normal for normal: tests/render/test_poly.py), so the pixels are
# the same.


def _cells(cells) -> vtkCellArray:
    """A cell array from VTK's legacy flat format (n, i0, ..., n, ...)."""
    ca = vtkCellArray()
    flat = np.ascontiguousarray(np.asarray(cells).ravel(), dtype=np.int64)
    ca.ImportLegacyFormat(numpy_to_vtkIdTypeArray(flat, deep=1))
    return ca


def point_cells(n: int) -> np.ndarray:
    """One vertex cell per point of n (pyvista's point-cloud cells), legacy format."""
    return np.column_stack([np.ones(n, np.int64), np.arange(n, dtype=np.int64)]).ravel()


def poly(points=None, faces=None, lines=None, verts=None) -> vtkPolyData:
    """The polydata ``pyvista.PolyData(points, faces, lines=lines, verts=verts)`` makes:
    the points (a copy, float kept, else float32), cells in the legacy flat format, and,
    given no cells at all, one vertex cell per point; no points: an empty polydata."""
    mesh = vtkPolyData()
    if points is None:
        return mesh
    pts = np.asarray(points)
    if not np.issubdtype(pts.dtype, np.floating):
        pts = pts.astype(np.float32)
    pts = np.ascontiguousarray(pts.reshape(-1, 3))
    vp = vtkPoints()
    vp.SetData(numpy_to_vtk(pts, deep=1))
    mesh.SetPoints(vp)
    if faces is None and lines is None and verts is None:
        verts = point_cells(len(pts))
    if verts is not None:
        mesh.SetVerts(_cells(verts))
    if faces is not None:
        mesh.SetPolys(_cells(faces))
    if lines is not None:
        mesh.SetLines(_cells(lines))
    return mesh


def polyline(points: np.ndarray) -> vtkPolyData:
    """``pyvista.lines_from_points``: one 2-point line per consecutive pair."""
    n = len(points)
    i = np.arange(n - 1, dtype=np.int64)
    return poly(points, lines=np.column_stack([np.full(n - 1, 2), i, i + 1]).ravel())


def _transformed(mesh: vtkPolyData, matrix: list[float]) -> vtkPolyData:
    t = vtkTransform()
    t.SetMatrix(matrix)
    f = vtkTransformFilter()
    f.SetInputData(mesh)
    f.SetTransform(t)
    f.Update()
    return f.GetOutput()


def sphere(
    radius: float, center=(0.0, 0.0, 0.0), theta_resolution: int = 30, phi_resolution: int = 30
) -> vtkPolyData:
    """``pyvista.Sphere(radius, center, theta_resolution=, phi_resolution=)`` (direction +z):
    VTK's sphere source turned as pyvista turns it (a quarter turn about y and back, which
    renormalises the normals) and moved to ``center`` in the points' float32."""
    src = vtkSphereSource()
    src.SetRadius(radius)
    src.SetThetaResolution(theta_resolution)
    src.SetPhiResolution(phi_resolution)
    src.Update()
    mesh = _transformed(src.GetOutput(), [0, 0, 1, 0, 0, 1, 0, 0, -1, 0, 0, 0, 0, 0, 0, 1])
    mesh = _transformed(mesh, [0, 0, -1, 0, 0, 1, 0, 0, 1, 0, 0, 0, 0, 0, 0, 1])
    if not np.allclose(center, [0.0, 0.0, 0.0]):
        data = mesh.GetPoints().GetData()
        pts = vtk_to_numpy(data)
        pts += np.array(center, dtype=pts.dtype)
        data.Modified()
    return mesh


def set_input(a: vtkActor, mesh) -> None:
    """Give an actor's polydata mapper new input."""
    mapper = a.GetMapper()
    assert isinstance(mapper, vtkPolyDataMapper)
    mapper.SetInputData(mesh)


def unit_ring(z: float) -> vtkPolyData:
    """The closed unit circle at height z (an outline template)."""
    lines = np.concatenate([[CIRCLE_N + 1], np.arange(CIRCLE_N), [0]])
    return poly(ring(0.0, 0.0, 1.0, z), lines=lines, verts=point_cells(CIRCLE_N))


def fans(idx: np.ndarray) -> np.ndarray:
    """Triangle fans (VTK cell array) over rings of point ids idx (n, c)."""
    j = np.arange(1, idx.shape[1] - 1)
    return np.stack(np.broadcast_arrays(3, idx[:, :1], idx[:, j], idx[:, j + 1]), axis=-1)


def unit_fan() -> vtkPolyData:
    """The unit disc as one triangle fan (a fill template)."""
    faces = fans(np.arange(CIRCLE_N)[None, :]).reshape(-1)
    return poly(ring(0.0, 0.0, 1.0, 0.0), faces, verts=point_cells(CIRCLE_N))


class Store:
    """Props added to renderers by one layer, removed together on a rebuild."""

    def __init__(self):
        self.items: list = []

    def add(self, renderer, prop) -> None:
        renderer.AddActor(prop)
        self.items.append((renderer, prop))

    def clear(self) -> None:
        for renderer, prop in self.items:
            renderer.RemoveActor(prop)
        self.items.clear()
