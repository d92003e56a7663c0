"""The 3D view drawn from the model (eyeviz/render/mpl/perspective3d.py) and the spherical
figure's vector export through a camera (eyeviz/render/mpl/figure3d.py, issue 22 item 6)."""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest
from matplotlib.collections import PolyCollection

from eyeviz.core import healpix
from eyeviz.model.camera3d import Camera3D, preset, project
from eyeviz.model.scene import load
from eyeviz.model.state3d import compute_state3d
from eyeviz.render.mpl.figure3d import export3d, figure3d
from eyeviz.render.mpl.perspective3d import default_camera, scene_polygons

SCENES = Path(__file__).resolve().parents[2] / "assets" / "scenes"
SVG = "{http://www.w3.org/2000/svg}"
ALL = ["eyes", "features", "tangents", "plane", "bfv"]


def _teaching(layers=ALL):
    sc = load(SCENES / "sphere_teaching.toml")
    sc.layers = list(layers)
    return sc, compute_state3d(sc)


def test_polygons_are_painted_far_to_near_and_back_faces_culled():
    sc, st = _teaching()
    cam = default_camera(st)
    polys = scene_polygons(st, sc, cam, 1.5)
    assert len(polys) > 1000
    assert np.all(np.diff(polys.depth) <= 0)  # far first
    assert set(polys.kind) == {"eye", "ball", "cone", "plane", "bfv", "line"}
    # every eye facet drawn faces the camera: n . (camera - facet) > 0
    pos = np.asarray(cam.position)
    eyes = polys.kind == "eye"
    assert 0.35 * 2 * st.pair.npix < eyes.sum() < 0.6 * 2 * st.pair.npix
    # without culling the eyes would be twice as many: count the facets facing away
    c = healpix.boundaries(8, np.arange(768), 2).mean(axis=1)  # the outlines' centroids
    away = 0
    for cx in (-st.pair.h, st.pair.h):
        mid = np.array([cx, 0, 0]) + st.pair.l * c
        away += int((((pos - mid) * c).sum(axis=1) <= 0).sum())
    assert eyes.sum() == 2 * st.pair.npix - away


def test_a_ball_lands_where_the_camera_projects_it():
    """Each ball's polygons surround the projection of its centre; another camera moves
    them there."""
    sc, st = _teaching(["features"])
    for cam in (
        default_camera(st),
        Camera3D((900.0, -300.0, 500.0), (0.0, 200.0, 0.0), (0.0, 0.0, 1.0), 40.0),
    ):
        polys = scene_polygons(st, sc, cam, 1.2)
        balls = np.concatenate([v for v, k in zip(polys.verts, polys.kind, strict=True)
                                if k == "ball"])  # fmt: skip
        seen = 0
        for f in sc.features:
            (xy,), (depth,) = project(cam, np.array([[f.x, f.y, f.z]]), 1.2)
            if depth <= 0 or max(abs(xy)) > 0.9:
                continue
            radius = f.g / (depth * math.tan(math.radians(cam.view_angle) / 2))
            d = balls - xy
            d[:, 0] *= 1.2  # NDC x is divided by the aspect
            near = balls[np.linalg.norm(d, axis=1) < 1.05 * radius]
            # the ball's front: a disc of vertices of one projected radius about its centre
            assert len(near) > 100
            assert np.linalg.norm(near.mean(axis=0) - xy) < 0.2 * radius
            seen += 1
        assert seen >= 2


def test_the_camera_is_the_views_and_a_preset_changes_the_picture(tmp_path):
    sc, st = _teaching(["eyes", "features"])
    top = preset("top", st.pair.h, st.pair.l, 600.0)
    a = scene_polygons(st, sc, default_camera(st), 1.0)
    b = scene_polygons(st, sc, top, 1.0)
    assert len(a) != len(b) or not np.allclose(a.verts[0], b.verts[0])
    # the figure takes the camera: the scene part of a figure drawn through ``top`` holds
    # the polygons scene_polygons gives for that camera and that part's aspect
    fig = figure3d(sc, camera=top, table=False, bitmaps=False, title=False)
    ax = next(a for a in fig.axes if a.get_gid() == "perspective-scene")
    (coll,) = [c for c in ax.collections if isinstance(c, PolyCollection)]
    box = ax.get_position()
    aspect = box.width * fig.get_figwidth() / (box.height * fig.get_figheight())
    ref = scene_polygons(st, sc, top, aspect, "scene")
    assert len(coll.get_paths()) == len(ref)
    np.testing.assert_allclose(coll.get_paths()[-1].vertices[:-1], ref.verts[-1], atol=1e-9)


@pytest.mark.slow
@pytest.mark.parametrize("fmt", ["svg", "pdf"])
def test_vector_export_is_true_vector_and_sane_in_size(tmp_path, fmt):
    """nside 180 with every view layer: polygons only (no raster image), a few MB."""
    sc = load(SCENES / "sphere_paper.toml")
    sc.layers = [*sc.layers, "tangents", "plane"]
    out = export3d(sc, tmp_path / f"p.{fmt}", camera=preset("front", 40.0, 20.0, 5000.0))
    data = out.read_bytes()
    if fmt == "svg":
        root = ET.fromstring(data)
        assert not root.findall(f".//{SVG}image")
        assert len(root.findall(f".//{SVG}path")) > 2000
    else:
        assert data.startswith(b"%PDF") and b"/Subtype /Image" not in data
    assert len(data) < 8_000_000, len(data)


def test_eyes_and_balls_behind_the_camera_are_left_out():
    """A camera between the eyes and the balls, looking at the balls: nothing behind it
    is drawn (a projection of points behind the camera would mirror them into view)."""
    sc, st = _teaching(["eyes", "features"])
    cam = Camera3D((0.0, 150.0, 0.0), (0.0, 400.0, 0.0), (0.0, 0.0, 1.0), 60.0)
    polys = scene_polygons(st, sc, cam, 1.0)
    assert "eye" not in set(polys.kind)  # the eyes are behind
    assert np.all(polys.depth > 0)
    ahead = [f for f in sc.features if f.y - f.g > 150.0]
    assert ahead and "ball" in set(polys.kind)
    assert math.isfinite(float(np.concatenate(polys.verts).max()))
