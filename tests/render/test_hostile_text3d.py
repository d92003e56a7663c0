"""Scene text in the 3D figures and the 3D view is drawn as written (issue 35 item 10,
issue 36 item 10), a tiny eye radius draws (issue 36 item 8), and the 3D geometry leaks
no RuntimeWarning to stderr (issue 36 item 13)."""

from __future__ import annotations

import re
import warnings

import numpy as np
import pytest

from eyeviz.model import scene as scene_mod

TITLE = r"cost $5 and $6 $\undefinedcmd$"
NAMES = ("$x^$", r"$\frac{a}{$")


def _scene(h: float = 40.0, l: float = 20.0, nside: int = 8) -> scene_mod.Scene:  # noqa: E741
    fs = [
        scene_mod.Feature(NAMES[0], 0.0, 600.0, 60.0, "#D55E00", 50.0),
        scene_mod.Feature(NAMES[1], 200.0, 900.0, 60.0, "#0072B2", 0.0),
    ]
    layers = ["eyes", "features", "bfv", "bitmaps", "readout", "labels", "plane"]
    return scene_mod.Scene(scene_mod.Eyes(h, l, nside=nside), fs, layers, title=TITLE)


def _svg_texts(path) -> list[str]:
    import html

    body = path.read_text(encoding="utf-8")
    return [html.unescape(t) for t in re.findall(r"<text[^>]*>([^<]*)</text>", body)]


def test_a_3d_figure_draws_titles_and_names_literally(tmp_path):
    from eyeviz.render.mpl.figure3d import export3d

    out = tmp_path / "f.svg"
    export3d(_scene(), out)  # raised pyparsing's grammar for "$x^$" before
    texts = _svg_texts(out)
    assert TITLE in texts  # "cost 5and6" before: mathtext ate the dollars
    for name in NAMES:
        assert any(name in t for t in texts), (name, texts)


def test_a_tiny_eye_radius_draws_a_3d_vector_figure(tmp_path):
    from eyeviz.render.mpl.figure3d import export3d

    out = tmp_path / "tiny.pdf"
    sc = _scene(l=1e-300)
    sc.layers = ["eyes", "features", "plane"]  # the plane's tiles asked for 1e302 lines
    export3d(sc, out)
    assert out.read_bytes().startswith(b"%PDF")


def test_vtk_measures_and_draws_dollar_signs_as_text(capfd):
    # the MathText backend pyvista's plotting loads (it parsed "$...$" with matplotlib)
    import vtkmodules.vtkRenderingMatplotlib  # noqa: F401
    from vtkmodules.vtkRenderingCore import vtkTextProperty

    from eyeviz.render.vtk.primitives import text_size

    tp = vtkTextProperty()
    tp.SetFontSize(14)
    capfd.readouterr()
    w_dollars = text_size(tp, "cost $5 and $6")
    w_plain = text_size(tp, "cost 5 and 6")
    for name in NAMES:
        assert text_size(tp, name) is not None
    err = capfd.readouterr().err
    assert "Warning" not in err and "ParseException" not in err, err  # 36 lines before
    assert w_dollars is not None and w_plain is not None
    assert w_dollars[0] > w_plain[0]  # the two "$" take room: drawn, not parsed away


def _no_warnings(fn, *args):
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        return fn(*args)


def test_a_ball_at_an_eye_centre_has_no_cone_and_no_warning():
    from eyeviz.model.shapes3d import tangent_cones

    apex = np.array([[-40.0, 0.0, 0.0], [40.0, 0.0, 0.0]])
    pts = _no_warnings(tangent_cones, apex, apex, np.array([5.0, 5.0]), 8)
    assert np.isfinite(pts).all()
    assert np.array_equal(pts.reshape(2, 9, 3), np.repeat(apex[:, None], 9, axis=1))


def test_triangulation_near_the_float_range_flags_rather_than_warns():
    from eyeviz.core import healpix
    from eyeviz.core.domain import Domain3D
    from eyeviz.estimators.analytic3d import estimate, triangulate

    nside = 8

    def lit(x: float, y: float):
        return np.array([0, 1]), np.array([healpix.vec2pix_ring(nside, x, y, 0.0)])

    # eyes 1e200 apart: the caps' rays meet 1e200 away, and |p|^2 overflowed in norm
    dom = Domain3D(h=1e200, l=1.0, nside=nside, r_min=1.0, r_max=2.0)
    r, az, el, flagged = _no_warnings(estimate, dom, lit(0.6, 0.8), lit(-0.6, 0.8))
    assert r.shape == (1,) and np.isfinite(az).all()
    u = np.array([[0.6, 0.8, 0.0], [1.0, 0.0, 0.0]])
    v = np.array([[-0.6, 0.8, 0.0], [-1.0, 0.0, 0.0]])
    p, ok = _no_warnings(triangulate, u, v, 1e308)
    assert not ok.any() and np.isnan(p).all()  # overflowed, and opposite: flagged
    p, ok = _no_warnings(triangulate, u[:1], v[:1], 40.0)
    assert ok.all() and np.allclose(p[0], [0.0, 40.0 / 0.75, 0.0])


def test_gnomonic_offsets_at_right_angles_give_no_warning():
    from eyeviz.estimators.limit3d import _Eye

    eye = object.__new__(_Eye)
    eye.c = np.array([[1.0, 0.0, 0.0]])
    eye.e1 = np.array([[0.0, 1.0, 0.0]])
    eye.e2 = np.array([[0.0, 0.0, 1.0]])
    out = _no_warnings(eye.gnomonic, np.array([[[0.0, 1.0, 0.0], [1.0, 0.0, 0.0]]]))
    assert np.isinf(out[0, 0, 0]) and np.array_equal(out[0, 1], [0.0, 0.0])


@pytest.mark.parametrize("nside", [8])
def test_the_3d_scene_file_keeps_its_text(nside):
    # a name or title is stored as written (the literal drawing starts from the file)
    text = scene_mod.dumps(_scene(nside=nside))
    back = scene_mod.loads(text)
    assert back.title == TITLE and [f.name for f in back.features] == list(NAMES)
