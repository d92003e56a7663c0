"""docs/extending.md, "A new eye model", its last step: the app's view of the toy model in
space (``ToyEyes``, tests/conftest.py; the display-free steps: tests/test_toy_model.py).
The toy written as an eye file opens from a scene in the 3D page, and the facets drawn lit
on its eyes are the toy's own lit sets, in each ball's colour."""

from __future__ import annotations

import numpy as np

from eyeviz.measured import save_eyes
from eyeviz.model.scene import load
from eyeviz.render.vtk.primitives import read_rgb
from eyeviz.render.vtk.style import UNLIT, hex_rgb

# two balls in the toy's binocular field (each lights >= 2 facets of both eyes)
BALLS = [("near", 0.3, 2.5, 0.1, 0.25, "#D55E00"), ("far", -0.4, 4.5, -0.3, 0.5, "#0072B2")]


def _scene(tmp_path, toy_eyes):
    save_eyes(toy_eyes, tmp_path / "toy.eye")
    text = 'title = "A toy eye model: seven facets per eye"\n[eyes]\nfile = "toy.eye"\n'
    for name, x, y, z, g, color in BALLS:
        text += f'[[features]]\nname = "{name}"\nx = {x}\ny = {y}\nz = {z}\ng = {g}\n'
        text += f'color = "{color}"\n'
    text += '[layers]\nshow = ["eyes", "features", "bitmaps", "readout", "labels", "cones"]\n'
    path = tmp_path / "toy.toml"
    path.write_text(text, encoding="utf-8")
    return path


def test_the_toy_model_opens_in_the_3d_page_with_its_own_lit_facets(
    make_window, tmp_path, toy_eyes
):
    _, x, y, z, g, _ = np.array([b[:5] + (0,) for b in BALLS], dtype=object).T
    x, y, z, g = (np.asarray(v, float) for v in (x, y, z, g))
    assert toy_eyes.in_bfv(x, y, z, g).all()  # the scene's balls are in the toy's field
    path = _scene(tmp_path, toy_eyes)
    win = make_window(load(path), path)
    host = win.host3d
    assert host.active and host.view.isVisible() and not win.plotter.isVisible()
    st = host.model.state
    assert st.facet_counts == (7, 7)
    assert [m.GetNumberOfCells() for m in host.actors.eyes.meshes] == [7, 7]
    want = toy_eyes.bitmaps(x, y, z, g)
    for e, eye in enumerate("AB"):
        rgb = read_rgb(host.actors.eyes.meshes[e])
        for i in range(len(BALLS)):
            assert np.array_equal(st.lit(i, eye), np.flatnonzero(want[e][i]))
        for i, ball in enumerate(BALLS):  # a shared facet shows the later ball's colour
            later = want[e][i + 1 :].any(axis=0)
            mine = np.flatnonzero(want[e][i] & ~later)
            assert mine.size and (rgb[mine] == hex_rgb(ball[5])).all()
        unlit = np.flatnonzero(~want[e].any(axis=0))
        assert unlit.size and (rgb[unlit] == UNLIT).all()
    sel = host.model.selected
    assert np.array_equal(host.actors.cones.drawn["A"], np.flatnonzero(want[0][sel]))
    assert np.array_equal(host.actors.cones.drawn["B"], np.flatnonzero(want[1][sel]))
