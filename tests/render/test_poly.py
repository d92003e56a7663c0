"""The meshes eyeviz/render/vtk/primitives.py makes with VTK alone (poly, polyline, sphere,
the unit templates) are the very meshes pyvista made before (issue 32.14: a 3D snapshot
no longer imports pyvista): the same points and their type, the same cells, the same
normals, bit for bit."""

from __future__ import annotations

import numpy as np
import pytest
import pyvista as pv
from vtkmodules.util.numpy_support import vtk_to_numpy

from eyeviz.render.vtk.primitives import (
    CIRCLE_N,
    fans,
    point_cells,
    poly,
    polyline,
    ring,
    sphere,
    unit_fan,
    unit_ring,
)


def _cells(ca) -> np.ndarray:
    return vtk_to_numpy(ca.GetOffsetsArray()).tolist(), vtk_to_numpy(
        ca.GetConnectivityArray()
    ).tolist()


def same(mine, theirs) -> None:
    assert mine.GetNumberOfPoints() == theirs.GetNumberOfPoints()
    if theirs.GetNumberOfPoints():
        a, b = mine.GetPoints().GetData(), theirs.GetPoints().GetData()
        assert a.GetDataType() == b.GetDataType()
        assert np.array_equal(vtk_to_numpy(a), vtk_to_numpy(b))
    for get in ("GetVerts", "GetLines", "GetPolys", "GetStrips"):
        assert _cells(getattr(mine, get)()) == _cells(getattr(theirs, get)()), get
    na, nb = mine.GetPointData().GetNormals(), theirs.GetPointData().GetNormals()
    assert (na is None) == (nb is None)
    if nb is not None:
        assert np.array_equal(vtk_to_numpy(na), vtk_to_numpy(nb))


def test_poly_is_pyvistas_polydata():
    rng = np.random.default_rng(3)
    pts = rng.normal(size=(6, 3))
    same(poly(), pv.PolyData())
    same(poly(pts), pv.PolyData(pts))  # a point cloud: one vertex per point
    same(poly(pts.astype(np.float32)), pv.PolyData(pts.astype(np.float32)))
    faces = np.array([3, 0, 1, 2, 4, 2, 3, 4, 5])
    same(poly(pts, faces), pv.PolyData(pts, faces))
    same(poly(pts, None), pv.PolyData(pts, None))
    same(poly(pts, lines=np.array([2, 0, 1])), pv.PolyData(pts, lines=np.array([2, 0, 1])))
    cloud = pv.PolyData(pts)
    cloud.verts = point_cells(6)
    same(poly(pts, verts=point_cells(6)), cloud)
    mesh = pv.PolyData(pts)  # lines set afterwards: the vertex cells stay
    mesh.lines = np.array([3, 0, 1, 2])
    same(poly(pts, lines=np.array([3, 0, 1, 2]), verts=point_cells(6)), mesh)
    same(polyline(pts), pv.lines_from_points(pts))


def test_poly_copies_its_points():
    pts = np.zeros((2, 3))
    mesh = poly(pts)
    pts[0, 0] = 1.0
    assert vtk_to_numpy(mesh.GetPoints().GetData())[0, 0] == 0.0


@pytest.mark.parametrize(
    "kw",
    [
        dict(radius=1.0, theta_resolution=40, phi_resolution=24),
        dict(radius=0.37, center=(1.5, -2.0, 0.3), theta_resolution=96, phi_resolution=48),
        dict(radius=12.5, center=(-40.0, 0.0, 7.25), theta_resolution=96, phi_resolution=48),
    ],
)
def test_sphere_is_pyvistas_sphere(kw):
    args = dict(kw)
    mine = sphere(args.pop("radius"), args.pop("center", (0.0, 0.0, 0.0)), **args)
    same(mine, pv.Sphere(**kw))


def test_unit_templates_are_pyvistas():
    ref = pv.PolyData(ring(0.0, 0.0, 1.0, 0.5))
    ref.lines = np.concatenate([[CIRCLE_N + 1], np.arange(CIRCLE_N), [0]])
    same(unit_ring(0.5), ref)
    ref = pv.PolyData(ring(0.0, 0.0, 1.0, 0.0))
    ref.faces = fans(np.arange(CIRCLE_N)[None, :]).reshape(-1)
    same(unit_fan(), ref)
