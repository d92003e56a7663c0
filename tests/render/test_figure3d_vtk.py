"""The vector 3D view and the VTK PNG show the same picture (issue 22 item 6).

The PNG is VTK's off-screen render (:func:`eyeviz.render.vtk.scene3d.render_png3d`); the
vector view is :func:`eyeviz.render.mpl.perspective3d.draw_panel` on a figure of the same
pixel size, written as SVG (true vector: checked) and rasterised by saving the SAME figure
through Agg (matplotlib cannot read SVG and cairosvg is not installed). Per part of the
view (the eyes close up, the scene) and per ball colour, the pixels of that hue (lit
facets and balls, shaded differently by VTK's lights and the vector headlight, so matched
by hue, not by value) must lie at the same place: centroids within 1 % of the width and
intersection over union at least 0.6. The same check with the camera turned by 6 degrees
must fail: the comparison can tell a wrong camera.

The PNG that ``eyeviz snapshot`` writes is the whole figure (:func:`export_png3d`: the view
rendered by VTK at the view box's pixel size, the maps and the readout drawn by matplotlib):
it is compared with the SVG's figure rasterised through Agg at the same dpi; outside the
view's box (title, maps, table) the pixels must be the same, inside it the per-colour check
above holds and fails for a turned camera.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("pyvista")

import matplotlib.image as mpimg  # noqa: E402
from matplotlib.backends.backend_agg import FigureCanvasAgg  # noqa: E402
from matplotlib.colors import rgb_to_hsv, to_rgb  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402

from eyeviz.model.camera3d import Camera3D  # noqa: E402
from eyeviz.model.scene import load  # noqa: E402
from eyeviz.model.state3d import compute_state3d  # noqa: E402
from eyeviz.render.mpl.figure3d import figure3d  # noqa: E402
from eyeviz.render.mpl.perspective3d import (  # noqa: E402
    default_camera,
    draw_panel,
    split_viewports,
)
from eyeviz.render.vtk.png3d import export_png3d  # noqa: E402
from eyeviz.render.vtk.scene3d import render_png3d  # noqa: E402

SCENES = Path(__file__).resolve().parents[2] / "assets" / "scenes"
SVG = "{http://www.w3.org/2000/svg}"
CENTROID = 0.01  # of the width
IOU = 0.6
MIN_PX = 40  # a colour seen on fewer pixels in both pictures is not compared


def _vector(sc, st, cam, size, svg: Path | None = None) -> np.ndarray:
    """The vector view, ``size`` (w, h) pixels, as rgb floats (Agg); written as SVG too
    when asked."""
    fig = Figure(figsize=(size[0] / 100, size[1] / 100), dpi=100, facecolor="white")
    draw_panel(fig, (0.0, 0.0, 1.0, 1.0), st, sc, cam)
    if svg is not None:
        fig.savefig(svg, format="svg")
    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    return np.asarray(canvas.buffer_rgba())[..., :3] / 255.0


def _masks(img: np.ndarray, colors) -> list[np.ndarray]:
    """Per colour, the pixels of its hue (saturated, not dark)."""
    hsv = rgb_to_hsv(np.clip(img, 0.0, 1.0))
    out = []
    for c in colors:
        hue = rgb_to_hsv(np.array(to_rgb(c)))[0]
        dh = np.abs(hsv[..., 0] - hue)
        dh = np.minimum(dh, 1.0 - dh)
        out.append((hsv[..., 1] > 0.3) & (hsv[..., 2] > 0.2) & (dh < 0.035))
    return out


def _agreement(a: np.ndarray, b: np.ndarray, colors) -> list[tuple[str, str, float, float]]:
    """(part, colour, centroid distance / width, IoU) for every ball colour seen (MIN_PX
    or more) in either picture, per part of the view."""
    rows = []
    H, W = a.shape[:2]
    for part, (x0, _y0, x1, _y1) in zip(("eyes", "scene"), split_viewports(W, H), strict=True):
        c0, c1 = round(x0 * W), round(x1 * W)
        for col, ma, mb in zip(
            colors, _masks(a[:, c0:c1], colors), _masks(b[:, c0:c1], colors), strict=True
        ):
            na, nb = int(ma.sum()), int(mb.sum())
            if max(na, nb) < MIN_PX:
                continue
            if min(na, nb) == 0:
                rows.append((part, col, math.inf, 0.0))
                continue
            d = np.linalg.norm(np.argwhere(ma).mean(0) - np.argwhere(mb).mean(0)) / W
            rows.append((part, col, float(d), float((ma & mb).sum() / (ma | mb).sum())))
    return rows


def _turned(cam: Camera3D, degrees: float) -> Camera3D:
    """``cam`` turned about the vertical through its focal point."""
    t = math.radians(degrees)
    rot = np.array([[math.cos(t), -math.sin(t), 0], [math.sin(t), math.cos(t), 0], [0, 0, 1]])
    f = np.asarray(cam.focal_point)
    pos = f + rot @ (np.asarray(cam.position) - f)
    return Camera3D(tuple(float(v) for v in pos), cam.focal_point, cam.view_up, cam.view_angle)


# nside 180's lit patches in the eyes' close-up need the larger picture to be compared
@pytest.mark.parametrize(
    ("name", "size"), [("sphere_teaching", (640, 360)), ("sphere_paper", (1280, 720))]
)
def test_the_png_and_the_vector_view_show_the_same_picture(name, size, tmp_path):
    sc = load(SCENES / f"{name}.toml")
    sc.layers = ["eyes", "features"]  # the opaque parts: lit facets and balls
    st = compute_state3d(sc)
    cam = default_camera(st)
    png = render_png3d(sc, tmp_path / "vtk.png", cam, *size, state=st)
    vtk_img = mpimg.imread(png)[..., :3]
    assert vtk_img.shape[:2] == size[::-1]
    svg = tmp_path / "view.svg"
    vec = _vector(sc, st, cam, size, svg)
    root = ET.parse(svg).getroot()
    assert not root.findall(f".//{SVG}image") and len(root.findall(f".//{SVG}path")) > 500
    colors = [f.color for f in sc.features]
    rows = _agreement(vtk_img, vec, colors)
    assert len(rows) >= 4, rows  # enough to compare: the test cannot pass on nothing
    assert {p for p, *_ in rows} == {"eyes", "scene"}
    bad = [r for r in rows if not (r[2] <= CENTROID and r[3] >= IOU)]
    assert not bad, bad
    # a wrong camera (turned 6 degrees) does not pass the same check
    wrong = _agreement(vtk_img, _vector(sc, st, _turned(cam, 6.0), size), colors)
    assert [r for r in wrong if not (r[2] <= CENTROID and r[3] >= IOU)], wrong


def _figure_rgb(fig, dpi: float, svg: Path | None = None) -> np.ndarray:
    """``fig`` rasterised through Agg at ``dpi``, rgb uint8 (written as SVG first when
    asked: the same figure)."""
    if svg is not None:
        fig.savefig(svg, format="svg")
    fig.set_dpi(dpi)
    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    return np.asarray(canvas.buffer_rgba())[..., :3].copy()


def _view_box(fig, shape) -> tuple[int, int, int, int]:
    """(row0, row1, col0, col1) pixels of the 3D view's box (its two parts' axes)."""
    exts = [a.get_window_extent() for a in fig.axes if a.get_gid() in PARTS]
    assert len(exts) == 2
    x0, x1 = min(e.x0 for e in exts), max(e.x1 for e in exts)
    y0, y1 = min(e.y0 for e in exts), max(e.y1 for e in exts)
    return shape[0] - round(y1), shape[0] - round(y0), round(x0), round(x1)


PARTS = ("perspective-eyes", "perspective-scene")
SAME = 8  # of 255: a pixel outside the view differs by less
SAME_FRACTION = 1e-4  # ... but on this fraction of them


# nside 180's lit patches in the close-up are compared at a double column (a view 2112 px
# wide; at a single one, IoU 0.62-0.8 at scales 1.2-1.6: patches of a few pixels)
@pytest.mark.slow
@pytest.mark.parametrize(
    ("name", "scale", "width"), [("sphere_teaching", 0.6, 3.5), ("sphere_paper", 1.0, 7.2)]
)
def test_the_png_is_the_whole_figure_with_the_vtk_view(name, scale, width, tmp_path):
    sc = load(SCENES / f"{name}.toml")
    sc.layers = ["eyes", "features", "labels", "bitmaps", "readout"]  # opaque view parts
    st = compute_state3d(sc)
    cam = default_camera(st, "default", 1.5)
    dpi = 300.0 * scale
    png = export_png3d(sc, tmp_path / "fig.png", scale, camera=cam, width=width)
    got = (mpimg.imread(png)[..., :3] * 255.0).round().astype(np.int16)
    svg = tmp_path / "fig.svg"
    fig = figure3d(sc, camera=cam, dpi=dpi, width=width)  # the SVG's figure, the PNG's pixels
    vec = _figure_rgb(fig, dpi, svg).astype(np.int16)
    assert not ET.parse(svg).getroot().findall(f".//{SVG}image")  # true vector
    assert got.shape == vec.shape and got.shape[1] == round(width * dpi)
    r0, r1, c0, c1 = _view_box(fig, got.shape)
    # the VTK view has the box's exact pixel size (VTK and mpl split its two parts alike)
    outside = np.ones(got.shape[:2], bool)
    outside[r0:r1, c0:c1] = False
    diff = np.abs(got - vec).max(axis=-1)
    assert (diff[outside] > SAME).mean() < SAME_FRACTION, (diff[outside] > SAME).mean()
    inside = diff[~outside]
    assert (inside > SAME).mean() > 0.005  # the view is VTK's, not the polygons again
    colors = [f.color for f in sc.features]
    rows = _agreement(got[r0:r1, c0:c1] / 255.0, vec[r0:r1, c0:c1] / 255.0, colors)
    assert len(rows) >= 4 and {p for p, *_ in rows} == {"eyes", "scene"}, rows
    bad = [r for r in rows if not (r[2] <= CENTROID and r[3] >= IOU)]
    assert not bad, bad
    # the maps are the same too: lit facets of every colour outside the view, identical
    outside_rows = np.flatnonzero(outside.all(axis=1))
    masks = _masks(got[outside_rows] / 255.0, colors)
    assert all(m.sum() > 20 for m in masks)
    # a turned camera in the vector figure fails the view's check
    turned = figure3d(sc, camera=_turned(cam, 6.0), dpi=dpi, width=width)
    wrong_img = _figure_rgb(turned, dpi)[r0:r1, c0:c1] / 255.0
    wrong = _agreement(got[r0:r1, c0:c1] / 255.0, wrong_img, colors)
    assert [r for r in wrong if not (r[2] <= CENTROID and r[3] >= IOU)], wrong


@pytest.mark.parametrize("k", [2, 3, 4])
def test_the_supersampled_view_is_averaged_by_alpha_weight(k):
    # each output pixel: alpha the block's mean, colour the alpha-weighted mean (0 where
    # the block is clear), rounded; summed in integers since issue 32.14
    from eyeviz.render.vtk.png3d import _downsample

    rng = np.random.default_rng(k)
    img = rng.integers(0, 256, (6 * k, 5 * k, 4), dtype=np.uint8)
    img[: 2 * k, :, 3] = 255  # opaque rows
    img[2 * k : 3 * k, :k, 3] = 0  # one clear block
    out = _downsample(img, k)
    f = img.astype(np.float64).reshape(6, k, 5, k, 4)
    a = f[..., 3].sum(axis=(1, 3))
    rgb = (f[..., :3] * f[..., 3:4]).sum(axis=(1, 3)) / np.maximum(a, 1)[..., None]
    want = np.concatenate([rgb, (a / (k * k))[..., None]], axis=-1)
    assert out.shape == (6, 5, 4) and out.dtype == np.uint8
    assert np.abs(out - want).max() <= 0.5 + 1e-9
    assert (out[2, 0] == 0).all()
