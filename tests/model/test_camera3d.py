"""The 3D camera: presets, and a projection that lands where VTK draws (real off-screen render)."""

from __future__ import annotations

import numpy as np
import pytest

from eyeviz import EyevizError
from eyeviz.model.camera3d import (
    PRESETS,
    Camera3D,
    basis,
    eyes_camera,
    preset,
    project,
    to_pixels,
)


def _render_marker(cam: Camera3D, centre, width: int, height: int, radius: float):
    """A red sphere at ``centre`` on black, rendered off-screen by VTK through ``cam``."""
    pv = pytest.importorskip("pyvista")
    pl = pv.Plotter(off_screen=True, window_size=(width, height))
    try:
        pl.set_background("black")
        pl.add_mesh(
            pv.Sphere(radius=radius, center=centre, theta_resolution=24, phi_resolution=24),
            color="red",
            lighting=False,
        )
        pl.camera.position = cam.position
        pl.camera.focal_point = cam.focal_point
        pl.camera.up = cam.view_up
        pl.camera.view_angle = cam.view_angle
        pl.renderer.ResetCameraClippingRange()
        img = pl.screenshot(return_img=True)
    finally:
        pl.close()
    return np.asarray(img)


def _centroid(img: np.ndarray) -> tuple[float, float]:
    red = (img[..., 0] > 128) & (img[..., 1] < 80) & (img[..., 2] < 80)
    assert red.sum() > 10, "the marker was not drawn"
    rows, cols = np.nonzero(red)
    return float(cols.mean()) + 0.5, float(rows.mean()) + 0.5


@pytest.mark.parametrize(
    ("cam", "point", "size"),
    [
        (preset("default", 40.0, 20.0, 3000.0), (700.0, 2100.0, 600.0), (400, 300)),
        (preset("top", 40.0, 20.0, 3000.0), (-900.0, 400.0, 0.0), (320, 480)),
        (
            Camera3D((300.0, -500.0, 250.0), (10.0, 80.0, -30.0), (0.2, 0.1, 1.0), 47.0),
            (-60.0, 150.0, 40.0),
            (500, 260),
        ),
    ],
)
def test_project_lands_where_vtk_draws(cam, point, size):
    width, height = size
    xy, depth = project(cam, np.array([point]), width / height)
    assert depth[0] > 0
    col, row = to_pixels(xy, width, height)[0]
    assert 5 < col < width - 5 and 5 < row < height - 5  # on screen: the test can fail
    # a sphere about 6 pixels in radius
    radius = 6.0 * depth[0] * np.tan(np.radians(cam.view_angle) / 2.0) * 2.0 / height
    img = _render_marker(cam, point, width, height, radius=radius)
    c, r = _centroid(img)
    assert abs(c - col) < 1.5 and abs(r - row) < 1.5, (c, r, col, row)


def test_project_moves_with_the_point():
    cam = preset("front", 40.0, 20.0, 2000.0)
    right, up, back = basis(cam)
    base = np.asarray(cam.focal_point)
    xy0, _ = project(cam, base, 1.0)
    xy1, _ = project(cam, base + 10.0 * right, 1.0)
    xy2, _ = project(cam, base + 10.0 * up, 1.0)
    np.testing.assert_allclose(xy0, [0.0, 0.0], atol=1e-12)
    assert xy1[0] > 0 and abs(xy1[1]) < 1e-12
    assert xy2[1] > 0 and abs(xy2[0]) < 1e-12
    # a point behind the camera has negative depth
    _, d = project(cam, np.asarray(cam.position) + 5.0 * back, 1.0)
    assert d < 0


def test_presets_look_where_they_say():
    h, l, ext = 40.0, 20.0, 3000.0
    for name in PRESETS:
        cam = preset(name, h, l, ext)
        assert isinstance(cam, Camera3D)
        pos, foc = np.asarray(cam.position), np.asarray(cam.focal_point)
        assert np.linalg.norm(pos - foc) > ext  # far enough to see the region
    top = preset("top", h, l, ext)
    assert top.position[2] > top.focal_point[2]
    right, up, _ = basis(top)
    np.testing.assert_allclose(right, [1, 0, 0], atol=1e-12)  # x right
    np.testing.assert_allclose(up, [0, 1, 0], atol=1e-12)  # y up, as the planar view
    side = preset("side", h, l, ext)
    right, up, _ = basis(side)
    np.testing.assert_allclose(right, [0, 1, 0], atol=1e-12)  # forward to the right
    front = preset("front", h, l, ext)
    assert front.position[1] > front.focal_point[1]  # from ahead, looking back
    a, b = preset("eye_a", h, l, ext), preset("eye_b", h, l, ext)
    assert a.focal_point == (-h, 0.0, 0.0) and b.focal_point == (h, 0.0, 0.0)
    assert a.position[0] == -h and b.position[0] == h  # on the eye's forward axis


def test_unknown_preset_is_one_line():
    with pytest.raises(EyevizError, match=r"^view must be one of .*got 'back'$"):
        preset("back", 40.0, 20.0, 100.0)
    with pytest.raises(EyevizError, match="extent"):
        preset("top", 40.0, 20.0, -1.0)


def test_eyes_camera_frames_the_eyes_from_the_same_direction():
    cam = preset("default", 40.0, 20.0, 3000.0)
    ins = eyes_camera(cam, 40.0, 20.0)
    d0 = np.subtract(cam.position, cam.focal_point)
    d1 = np.subtract(ins.position, ins.focal_point)
    np.testing.assert_allclose(d0 / np.linalg.norm(d0), d1 / np.linalg.norm(d1), atol=1e-12)
    # both eye centres +- l on screen, inside the view
    pts = np.array([[-60.0, 0, 0], [60.0, 0, 0], [0, 0, 20.0], [0, 0, -20.0]])
    xy, depth = project(ins, pts, 1.0)
    assert np.all(depth > 0) and np.all(np.abs(xy) < 1.0)
    one = eyes_camera(preset("eye_b", 40.0, 20.0, 3000.0), 40.0, 20.0)
    assert one.focal_point == (40.0, 0.0, 0.0)
    xy, _ = project(one, np.array([[20.0, 0, 0], [60.0, 0, 0]]), 1.0)
    assert np.all(np.abs(xy) < 1.0) and np.all(np.abs(xy[:, 0]) > 0.4)  # the eye fills it


def test_project_checks_its_input():
    cam = preset("top", 40.0, 20.0, 100.0)
    with pytest.raises(EyevizError, match=r"points must have shape"):
        project(cam, np.zeros((3, 2)), 1.0)
    with pytest.raises(EyevizError, match="aspect"):
        project(cam, np.zeros(3), 0.0)
    with pytest.raises(EyevizError, match="view_up"):
        basis(Camera3D((0, 0, 10.0), (0, 0, 0), (0, 0, 1.0)))


def test_an_eye_preset_stands_back_by_half_the_extent_more():
    """eye_a / eye_b: the fitting distance radius / sin(half angle) plus extent / 2."""
    import math

    h, l, extent = 40.0, 20.0, 3000.0
    cam = preset("eye_a", h, l, extent)
    radius = max(0.6 * extent, h + l)
    want = radius / math.sin(math.radians(15.0)) + extent / 2
    d = np.asarray(cam.position) - np.asarray(cam.focal_point)
    assert tuple(cam.focal_point) == (-h, 0.0, 0.0)
    assert float(np.linalg.norm(d)) == pytest.approx(want, rel=1e-12)


def test_the_close_up_frames_one_eye_only_for_a_camera_on_that_eyes_centre():
    """A focal point at x = h but off the eye's centre (y or z not 0) is no eye preset:
    the close-up frames both eyes about the origin."""
    h, l = 40.0, 20.0
    on = eyes_camera(preset("eye_b", h, l, 3000.0), h, l)
    assert tuple(on.focal_point) == (h, 0.0, 0.0)
    for foc in ((h, 500.0, 0.0), (h, 0.0, 30.0), (-h, 500.0, 0.0)):
        cam = Camera3D((h, 2000.0, 300.0), foc, (0.0, 0.0, 1.0))
        assert tuple(eyes_camera(cam, h, l).focal_point) == (0.0, 0.0, 0.0), foc
