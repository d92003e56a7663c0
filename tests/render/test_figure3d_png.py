"""The spherical figure's PNG takes its 3D view as a picture (the VTK render) placed pixel
for pixel in the view's box (eyeviz/render/mpl/figure3d.py, ``view_image``): no VTK here,
a noise picture stands in for it, so any resampling or a shift by one pixel shows."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from matplotlib.backends.backend_agg import FigureCanvasAgg

from eyeviz import EyevizError
from eyeviz.model.scene import load
from eyeviz.render.mpl.figure3d import figure3d

SCENES = Path(__file__).resolve().parents[2] / "assets" / "scenes"


def _noise(store: dict, seed: int = 0):
    rng = np.random.default_rng(seed)

    def view_image(cam, w, h):
        a = rng.integers(0, 256, (h, w, 4), dtype=np.uint8)
        a[..., 3] = 255
        store.update(img=a, cam=cam)
        return a

    return view_image


@pytest.mark.parametrize(("scale", "width"), [(1.0, 3.5), (0.37, 7.2), (0.25, 4.13)])
def test_the_view_picture_lands_pixel_for_pixel(scale, width):
    sc = load(SCENES / "sphere_teaching.toml")
    dpi = 300.0 * scale
    got: dict = {}
    fig = figure3d(sc, width=width, dpi=dpi, view_image=_noise(got))
    canvas = FigureCanvasAgg(fig)
    fig.set_dpi(dpi)
    canvas.draw()
    out = np.asarray(canvas.buffer_rgba())
    w_in, h_in = fig.get_size_inches()
    assert out.shape[:2] == (round(h_in * dpi), round(w_in * dpi))
    assert abs(w_in - width) * dpi <= 0.5  # whole pixels: the width moved by <= half a pixel
    img = got["img"]
    h, w = img.shape[:2]
    (box,) = [a for a in fig.axes if a.get_gid() == "perspective-image"]
    ext = box.get_window_extent()
    assert np.allclose((ext.width, ext.height), (w, h), atol=1e-6)  # the box's pixel size
    x0, y0 = round(ext.x0), out.shape[0] - round(ext.y1)
    assert np.allclose((x0, y0), (ext.x0, out.shape[0] - ext.y1), atol=1e-6)  # whole pixels
    same = (out[y0 : y0 + h, x0 : x0 + w, :3] == img[..., :3]).all(axis=-1)
    assert same.mean() > 0.93  # all but the captions and names drawn over it
    below = out[y0 + 1 : y0 + 1 + h, x0 : x0 + w, :3]
    shifted = (below == img[: below.shape[0], :, :3]).all(axis=-1)
    assert shifted.mean() < 0.05  # one pixel off matches nothing: the check can fail
    # the maps and the table are the vector figure's (same layout)
    vec = figure3d(sc, width=width, dpi=dpi)
    assert [a.get_gid() for a in vec.axes if a.get_gid() != "perspective-image"] == [
        a.get_gid() for a in fig.axes if a.get_gid() != "perspective-image"
    ]


def test_view_image_needs_the_dpi_and_the_box_size():
    sc = load(SCENES / "sphere_teaching.toml")
    with pytest.raises(EyevizError, match="dpi"):
        figure3d(sc, view_image=_noise({}))
    with pytest.raises(EyevizError, match="px for a"):
        figure3d(sc, dpi=100.0, view_image=lambda cam, w, h: np.zeros((h + 1, w, 3)))
