"""A measured eye pair (the honeybee, AM_60185) in the 3D docks, real Qt window under Xvfb:
the Facets (Mollweide) panel draws each eye's Voronoi patches, lit ones in the ball's
colour where the ball's lit facets are, a real mouse move onto a patch names its facet
(index, axis, acceptance), and the readout shows r / azimuth / elevation and lit counts."""

from __future__ import annotations

import math

import numpy as np
import pytest
from matplotlib.colors import to_rgba
from PyQt5 import QtCore, QtGui
from PyQt5.QtTest import QTest

from eyeviz.app.panels.bitmaps3d import Bitmaps3DPanel, lit_owners
from eyeviz.app.panels.readout3d import Readout3DPanel
from eyeviz.measured import load_eyes, shipped_eye
from eyeviz.model.facet_patches import facet_patches
from eyeviz.model.scene import loads
from eyeviz.model.state3d import SceneState3D
from eyeviz.render.mpl.figure3d import readout_rows
from eyeviz.render.mpl.style import UNLIT

# balls ahead of and below the bee (mm): in its binocular field
BALLS = [("near", 0.0, 5.142, -6.128, 0.4, "#D55E00"), ("mid", 1.992, 11.297, -16.383, 1.0,
         "#0072B2"), ("far", -5.209, 29.544, -51.962, 3.0, "#009E73")]  # fmt: skip


def _scene(balls):
    text = "[eyes]\nh = 40.0\nl = 20.0\nnside = 2\n" + "".join(
        f'[[features]]\nname = "{n}"\nx = {x}\ny = {y}\nz = {z}\ng = {g}\ncolor = "{c}"\n'
        for n, x, y, z, g, c in balls
    )
    return loads(text + '[layers]\nshow = ["eyes", "features", "bitmaps", "readout"]\n')


def _state(pair, scene) -> SceneState3D:
    """The state a measured scene computes (eyeviz.model.state3d), built here from the
    pair's own calls."""
    f = scene.features
    x, y, z, g = (np.array([getattr(b, k) for b in f]) for k in "xyzg")
    horiz = np.hypot(x, y)
    st = SceneState3D(pair, x, y, z, g, r=np.hypot(horiz, z),
                      azimuth=np.mod(np.arctan2(y, x), 2 * np.pi),
                      elevation=np.arctan2(z, horiz))  # fmt: skip
    st.lit_a, st.lit_b = pair.lit_csr(x, y, z, g)
    st.facets_a, st.facets_b = np.diff(st.lit_a[0]), np.diff(st.lit_b[0])
    st.vis_a, st.vis_b = st.facets_a >= 2, st.facets_b >= 2
    st.in_bfv = pair.in_bfv(x, y, z, g)
    st.overlap_a, st.overlap_b = pair.overlaps_eye(x, y, z, g)
    return st


@pytest.fixture(scope="module")
def bee():
    return load_eyes(shipped_eye("AM_60185-real.eye"))


def _panel(qtbot, cls, w=460, h=600):
    p = cls()
    qtbot.addWidget(p)
    p.resize(w, h)
    p.show()
    qtbot.waitExposed(p)
    return p


def _canvas_px(panel, eye, i):
    x, y = panel.map_point(eye, i)
    dx, dy = panel.axes[eye].transData.transform((x, y))
    ratio = panel.canvas.devicePixelRatioF()
    return QtCore.QPoint(round(dx / ratio), round(panel.canvas.height() - dy / ratio))


def _color_at(panel, pt):
    c = QtGui.QColor(panel.canvas.grab().toImage().pixel(pt.x(), pt.y()))
    return c.red(), c.green(), c.blue()


def _near(a, color, tol=14):
    r, g, b, _ = to_rgba(color)
    return max(abs(u - round(255 * v)) for u, v in zip(a, (r, g, b), strict=True)) <= tol


def _middle(pair, eye, idx):
    """The lit facet nearest the middle of a ball's patch (surely its colour)."""
    c = facet_patches(pair, eye).centers(idx)
    return int(idx[np.argmax(c @ c.mean(axis=0))])


def test_measured_map_lights_the_balls_facets(qtbot, bee):
    sc = _scene(BALLS)
    st = _state(bee, sc)
    panel = _panel(qtbot, Bitmaps3DPanel)
    panel.set_state(st, sc, 1)
    qtbot.waitUntil(lambda: panel._bg is not None, timeout=5000)
    assert panel.nside is None and "3,187 (A) and 3,187 (B) measured facets" in panel.counts.text()
    for e, csr in zip("AB", (st.lit_a, st.lit_b), strict=True):
        np.testing.assert_array_equal(panel.lit_facets(e), lit_owners(csr)[0])
        # the unlit patches: every facet of the eye, each its own polygon
        ours = (*panel._lit[e], panel._halo[e], panel._covered[e])
        back = [c for c in panel.axes[e].collections if c not in ours]
        _, over, _ = __import__("eyeviz.render.mpl.facet_map", fromlist=["x"]).view_polys(
            facet_patches(bee, e), np.arange(3187)
        )
        assert len(back[0].get_paths()) == 3187 + over.sum()
    assert panel.outlined("A") >= len(st.lit(1, "A"))  # the selected ball's outline
    for i, ball in enumerate(sc.features):  # each ball's colour where its facets are
        for e in "AB":
            lit = st.lit(i, e)
            if len(lit) >= 3:
                pt = _canvas_px(panel, e, _middle(bee, e, lit))
                # facets ~3 px wide: the centre's pixel or one beside it (an edge's blend)
                around = [pt + QtCore.QPoint(dx, dy) for dx in (-1, 0, 1) for dy in (-1, 0, 1)]
                assert any(_near(_color_at(panel, q), ball.color) for q in around), (ball.name, e)
    # a ball moved out of the binocular field, up and to the right: eye A's patch goes grey
    far = _middle(bee, "A", st.lit(2, "A"))
    pt = _canvas_px(panel, "A", far)
    moved = [(*b[:1], 30.0, b[2], 20.0, *b[4:]) if b[0] == "far" else b for b in BALLS]
    sc2 = _scene(moved)
    st2 = _state(bee, sc2)
    panel.set_state(st2, sc2, 1)
    assert far not in set(panel.lit_facets("A").tolist())
    assert _near(_color_at(panel, pt), UNLIT)


def test_hover_names_the_measured_facet_under_the_mouse(qtbot, bee):
    sc = _scene(BALLS)
    st = _state(bee, sc)
    panel = _panel(qtbot, Bitmaps3DPanel)
    panel.set_state(st, sc)
    qtbot.waitUntil(lambda: panel._bg is not None, timeout=5000)
    i = _middle(bee, "B", st.lit(2, "B"))
    QTest.mouseMove(panel.canvas, _canvas_px(panel, "B", i))
    qtbot.waitUntil(lambda: f"facet {i:,}:" in panel.hover.text(), timeout=3000)
    text = panel.hover.text()
    ax = bee.eye("B").unit_axes[i]
    az = math.degrees(math.atan2(ax[1], ax[0])) % 360
    el = math.degrees(math.asin(ax[2]))
    assert text.startswith(f"eye B, facet {i:,}: axis azimuth {az:.2f}°, elevation {el:.2f}°")
    assert "acceptance 2.60°" in text and text.endswith("lit by 'far'")
    assert panel.hover_pix == ("B", i)
    # straight up, eye B (right) has no facet: no text
    x, y = panel.axes["B"].transData.transform((0.0, 1.35))
    ratio = panel.canvas.devicePixelRatioF()
    up = QtCore.QPoint(round(x / ratio), round(panel.canvas.height() - y / ratio))
    QTest.mouseMove(panel.canvas, up)
    qtbot.waitUntil(lambda: panel.hover.text() == "", timeout=3000)


def test_readout_shows_the_measured_scenes_balls(qtbot, bee):
    sc = _scene(BALLS)
    st = _state(bee, sc)
    panel = _panel(qtbot, Readout3DPanel, 380, 300)
    panel.set_state(st, sc)
    assert panel.table.rowCount() == 3
    rows = readout_rows(st, sc)
    for i, (name, x, y, z, _g, _c) in enumerate(BALLS):
        assert panel.text(i, "ball") == name
        assert panel.text(i, "r") == rows[i][1] == f"{math.sqrt(x * x + y * y + z * z):.3g}"
        assert panel.text(i, "el°") == f"{math.degrees(math.atan2(z, math.hypot(x, y))):.1f}"
        assert panel.text(i, "lit A/B") == f"{st.facets_a[i]}/{st.facets_b[i]}"
        assert st.facets_a[i] >= 2 and st.facets_b[i] >= 2
        assert panel.text(i, "BFV") == "yes"


def test_the_honeybee_scene_in_the_window_maps_its_lit_facets(make_window, qtbot):
    """bee.toml in the real window: the Facets dock's maps are the measured pair's, each
    ball's lit patches in its colour, and a real mouse move names a lit patch's facet."""
    from pathlib import Path

    from eyeviz.model.scene import load

    path = Path(__file__).resolve().parents[2] / "assets" / "scenes" / "bee.toml"
    win = make_window(load(path), path)
    host = win.host3d
    host.docks["bitmaps3d"].show()
    host.docks["bitmaps3d"].raise_()
    panel = host.bitmaps
    st = host.model.state
    qtbot.waitUntil(lambda: panel.canvas.isVisible() and panel._bg is not None, timeout=8000)
    assert panel.patches["A"] is facet_patches(st.pair, "A")
    for e, csr in zip("AB", (st.lit_a, st.lit_b), strict=True):
        np.testing.assert_array_equal(panel.lit_facets(e), lit_owners(csr)[0])
    owner = dict(zip(*lit_owners(st.lit_a), strict=True))
    i = 2  # "far": the largest patch
    mine = np.array([k for k, b in owner.items() if b == i])
    f = _middle(st.pair, "A", mine)
    pt = _canvas_px(panel, "A", f)
    # the patch's facets are 1-2 px wide with an edge stroke (the map grew when the
    # equator's label was measured instead of estimated): the ball's colour, blended with
    # the edges but apart from grey and the other balls' (blue is 63 away), within a pixel
    around = [pt + QtCore.QPoint(dx, dy) for dx in (-1, 0, 1) for dy in (-1, 0, 1)]
    colour = host.model.scene.features[i].color
    near = [_near(_color_at(panel, q), colour, tol=45) for q in around]
    assert any(near), [_color_at(panel, q) for q in around]
    QTest.mouseMove(panel.canvas, pt)
    want = f"eye A, facet {f:,}: axis "
    qtbot.waitUntil(lambda: panel.hover.text().startswith(want), timeout=3000)
    assert panel.hover.text().endswith(f"lit by {host.model.scene.features[i].name!r}")


def test_the_facets_caption_of_the_honeybee_fits_a_1280x720_window(make_window, qtbot):
    """bee.toml in a 1280 x 720 window: the Facets dock's first line was "3,187 (A) and
    3,187 (B) measured fac…"; it now takes a shorter form that fits, whole."""
    from pathlib import Path

    from PyQt5 import QtWidgets

    from eyeviz.model.facet_patches import patches_caption_forms
    from eyeviz.model.scene import load

    path = Path(__file__).resolve().parents[2] / "assets" / "scenes" / "bee.toml"
    win = make_window(load(path), path)
    win.resize(1280, 720)
    qtbot.waitUntil(lambda: win.width() == 1280, timeout=3000)
    host = win.host3d
    host.docks["bitmaps3d"].show()
    host.docks["bitmaps3d"].raise_()
    panel = host.bitmaps
    qtbot.waitUntil(lambda: panel.canvas.isVisible() and panel._bg is not None, timeout=8000)
    qtbot.wait(300)
    shown = QtWidgets.QLabel.text(panel.counts).split("\n")
    assert "\N{HORIZONTAL ELLIPSIS}" not in shown[0], shown
    assert shown[0] in patches_caption_forms(host.model.state.pair), shown
    room = panel.counts.contentsRect().width()
    assert panel.counts.fontMetrics().horizontalAdvance(shown[0]) <= room, (shown, room)
