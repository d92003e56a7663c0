"""The ``posterior`` layer in the vector export (issue 10 item 5): one seamless mesh per
feature with its posterior, the limit's estimate marked, the legend says what it is."""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET

import numpy as np

from eyeviz.model import scene as sm
from eyeviz.model.frame import build_frame
from eyeviz.model.palette import POSTERIOR_COLOR, posterior_rgba
from eyeviz.model.posterior import posterior_of
from eyeviz.render.mpl import vector
from eyeviz.render.mpl.export import export

SVG = "{http://www.w3.org/2000/svg}"


def scene(layers=("eyes", "bfv", "features", "ambiguity", "posterior", "readout")):
    return sm.Scene(
        sm.Eyes(40.0, 20.0, 720),
        [
            sm.Feature("near", 0.0, 1500.0, 50.0, "#D55E00"),
            sm.Feature("side", 1700.0, 2200.0, 120.0, "#009E73"),
            sm.Feature("tiny", 0.0, 3000.0, 5.0, "#0072B2"),  # the prior cannot make it
        ],
        list(layers),
        view=sm.View((0.0, 2800.0), 7000.0),
    )


def test_svg_has_one_posterior_per_feature_that_has_one(tmp_path):
    sc = scene()
    out = export(sc, tmp_path / "post.svg", width="double")
    root = ET.parse(out).getroot()
    ids = {g.get("id") for g in root.iter(f"{SVG}g")}
    assert {"posterior-near", "posterior-side"} <= ids
    assert "posterior-tiny" not in ids and "posterior-estimate-tiny" not in ids
    assert {"posterior-estimate-near", "posterior-estimate-side"} <= ids
    groups = {g.get("id"): g for g in root.iter(f"{SVG}g")}
    pair = sc.eyes.pair()
    for name, f in (("near", sc.features[0]), ("side", sc.features[1])):
        post = posterior_of(pair, f.x, f.y, f.g)
        paths = list(groups[f"posterior-{name}"].iter(f"{SVG}path"))
        filled = [p for p in paths if "fill: none" not in (p.get("style") or "")]
        assert len(filled) == post.n  # one quad per cell with mass (masked cells unfilled)
        assert all(POSTERIOR_COLOR.lower() in p.get("style") for p in filled)
    texts = " ".join("".join(t.itertext()) for t in root.iter(f"{SVG}text"))
    assert "posterior of the centre" in texts and "limit's estimate" in texts
    # the table: where the mass is over every g, beside the own-g "same bitmaps" range
    lo, hi = posterior_of(pair, 1700.0, 2200.0, 120.0).r_interval(0.9)
    assert f"posterior over every g: 90 % at r \u2208 [{lo:.0f}, {hi:.0f}]" in texts
    assert "posterior: none (the prior never makes these bitmaps)" in texts


def test_figure_draws_the_frames_posterior_at_the_limits_estimate():
    sc = scene(("features", "posterior", "predictions"))
    sc.estimators = ["limit"]
    fig = vector.figure(sc, dpi=vector.VECTOR_DPI)
    fr = fig._eyeviz_frame
    assert set(fr.posterior) == {0, 1, 2} and fr.posterior[2] is None
    ax = fig.axes[0]
    meshes = {c.get_gid(): c for c in ax.collections if (c.get_gid() or "").startswith("post")}
    assert set(meshes) == {"posterior-near", "posterior-side"}
    post = fr.posterior[1]
    arr = meshes["posterior-side"].get_array()
    assert arr.shape[:2] == post.grid.shape or arr.size == post.grid.size
    assert int(np.ma.count(arr)) == post.n  # the cells with mass, the rest masked
    marks = {ln.get_gid(): ln for ln in ax.lines if (ln.get_gid() or "").startswith("post")}
    x, y = marks["posterior-estimate-side"].get_data()
    lim = fr.predictions["limit"]
    assert math.isclose(x[0], lim.x_hat[1], rel_tol=1e-6)
    assert math.isclose(y[0], lim.y_hat[1], rel_tol=1e-6)
    leg = ax.get_legend()
    labels = [t.get_text() for t in leg.get_texts()]
    assert labels[0] == "limit (predicted)" and "limit's estimate" in labels  # one legend


def test_shades_darken_with_density():
    a = posterior_rgba([0.0, 0.5, 1.0])
    assert a[0][3] < a[1][3] < a[2][3] <= 1.0
    c = POSTERIOR_COLOR.lstrip("#")
    assert a[2][:3] == tuple(int(c[i : i + 2], 16) / 255.0 for i in (0, 2, 4))


def test_frame_without_the_layer_computes_nothing():
    sc = scene(("features", "ambiguity"))
    assert build_frame(sc).posterior == {}


def test_posterior_table_lines_fit_a_single_column():
    sc = scene(("eyes", "bfv", "features", "ambiguity", "posterior", "readout", "labels"))
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    fig = vector.figure(sc, width="single")
    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    r = canvas.get_renderer()
    lines = [t for t in fig.findobj(lambda a: (getattr(a, "get_gid", lambda: "")() or "")
             .startswith("readout-posterior"))]  # fmt: skip
    assert len(lines) == 3
    for t in lines:
        bb = t.get_window_extent(r)
        assert t.get_fontsize() >= 6.0
        assert bb.x0 >= 0 and bb.x1 <= fig.bbox.width and bb.y0 >= 0, t.get_text()
