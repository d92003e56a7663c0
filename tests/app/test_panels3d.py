"""The spherical scene's panels in a real Qt window (issue 22 items 4 and 5): the Mollweide
bitmaps (eyeviz/app/panels/bitmaps3d.py) follow the state, hovering a facet names it, and
the readout (eyeviz/app/panels/readout3d.py) shows the figure's rows."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from matplotlib.colors import to_rgba
from PyQt5 import QtCore, QtGui
from PyQt5.QtTest import QTest

from eyeviz.app.panels.bitmaps3d import Bitmaps3DPanel, lit_owners
from eyeviz.app.panels.readout3d import Readout3DPanel
from eyeviz.core import healpix
from eyeviz.model.scene import load
from eyeviz.model.state3d import compute_state3d
from eyeviz.render.mpl.facet_map import mollweide, mollweide_inverse, view_lonlat
from eyeviz.render.mpl.figure3d import readout_rows
from eyeviz.render.mpl.healpix_map import pixel_at
from eyeviz.render.mpl.style import UNLIT

SCENES = Path(__file__).resolve().parents[2] / "assets" / "scenes"


def _panel(qtbot, cls, w=420, h=560):
    p = cls()
    qtbot.addWidget(p)
    p.resize(w, h)
    p.show()
    qtbot.waitExposed(p)
    return p


def _union(st, eye):
    return np.unique(np.concatenate([st.lit(i, eye) for i in range(st.n)]))


def _canvas_px(panel, eye, pix):
    """The canvas widget pixel (Qt, top-left origin) of facet ``pix``'s centre."""
    x, y = panel.map_point(eye, pix)
    dx, dy = panel.axes[eye].transData.transform((x, y))
    ratio = panel.canvas.devicePixelRatioF()
    return QtCore.QPoint(round(dx / ratio), round(panel.canvas.height() - dy / ratio))


def _color_at(panel, point) -> tuple[int, int, int]:
    img = panel.canvas.grab().toImage()
    c = QtGui.QColor(img.pixel(point.x(), point.y()))
    return c.red(), c.green(), c.blue()


def _rgb(color: str) -> tuple[int, int, int]:
    r, g, b, _ = to_rgba(color)
    return round(255 * r), round(255 * g), round(255 * b)


def _near(a, b, tol=12) -> bool:
    return max(abs(x - y) for x, y in zip(a, b, strict=True)) <= tol


def _settle(qtbot, panel):
    """Let the canvas finish its first full draw (the kept background)."""
    qtbot.waitUntil(lambda: panel._bg is not None, timeout=5000)


def _interior_facet(panel, eye, pix_set, st_nside):
    """A lit facet away from the map's edge whose pixel is surely its colour: at nside
    <= 32 (facets many pixels wide) any such facet, above (facets under a pixel wide) the
    one at the middle of the ball's lit patch."""
    pix_set = np.asarray(pix_set)
    if st_nside > 32:
        c = healpix.centers(st_nside, pix_set)
        mid = c.mean(axis=0)
        return int(pix_set[np.argmax(c @ mid)])
    for p in pix_set:
        x, _ = panel.map_point(eye, int(p))
        if abs(x) < 2.0:
            return int(p)
    raise AssertionError("no lit facet away from the map's edge")


def test_bitmaps_follow_the_state(qtbot):
    """Teaching scene (nside 8): the lit facets drawn are the state's; moving a ball
    changes them, in the panel's data and in its pixels (drawn by blitting)."""
    sc = load(SCENES / "sphere_teaching.toml")
    st = compute_state3d(sc)
    panel = _panel(qtbot, Bitmaps3DPanel)
    panel.set_state(st, sc)
    _settle(qtbot, panel)
    for eye in "AB":
        np.testing.assert_array_equal(panel.lit_facets(eye), _union(st, eye))
        inner, edge = panel._lit[eye]
        drawn = sum(int((p.codes == p.MOVETO).sum()) for c in (inner, edge) for p in c.get_paths())
        pix, _ = lit_owners((st.lit_a, st.lit_b)["AB".index(eye)])
        assert drawn >= pix.size  # + the facets across the edge, drawn twice
    ahead = sc.features[0]
    before = _interior_facet(panel, "A", st.lit(0, "A"), 8)
    pt = _canvas_px(panel, "A", before)
    assert _near(_color_at(panel, pt), _rgb(ahead.color))
    # the ball moves far to the right: its old facets go grey, new ones light
    moved = sc.copy()
    moved.features[0].x += 260.0
    st2 = compute_state3d(moved)
    panel.set_state(st2, moved)
    assert not np.array_equal(panel.lit_facets("A"), _union(st, "A"))
    np.testing.assert_array_equal(panel.lit_facets("A"), _union(st2, "A"))
    assert before not in set(_union(st2, "A").tolist())
    assert _near(_color_at(panel, pt), _rgb(UNLIT))
    after = _interior_facet(panel, "A", st2.lit(0, "A"), 8)
    assert _near(_color_at(panel, _canvas_px(panel, "A", after)), _rgb(ahead.color))
    assert "A " in panel.counts.text() and "nside 8" in panel.counts.text()


def test_bitmaps_at_nside_180_draw_only_the_lit_facets(qtbot):
    """Facets under a pixel wide: no polygons; the lit facets are painted as pixels (each
    pixel the facet under its centre, and each lit facet's centre pixel) in their balls'
    colours, and nothing else of the map changes colour."""
    sc = load(SCENES / "sphere_paper.toml")
    st = compute_state3d(sc)
    panel = _panel(qtbot, Bitmaps3DPanel)
    panel.set_state(st, sc)
    _settle(qtbot, panel)
    ax = panel.axes["A"]
    ours = (*panel._lit["A"], panel._halo["A"], panel._covered["A"])
    (back,) = [c for c in ax.collections if c not in ours]
    assert len(back.get_paths()) == 1  # the unlit sphere: one solid ellipse
    inner, edge = panel._lit["A"]
    assert not inner.get_paths() and not edge.get_paths()  # painted as pixels instead
    ras = panel._raster["A"]
    union = _union(st, "A")
    np.testing.assert_array_equal(ras.pix, union)
    far = [f.name for f in sc.features].index("far")  # the largest patch, off the equator
    target = _interior_facet(panel, "A", st.lit(far, "A"), 180)
    assert _near(_color_at(panel, _canvas_px(panel, "A", target)), _rgb(sc.features[far].color))
    # every lit facet shows: its centre's pixel has its ball's colour (the last ball
    # lighting the facet; another lit facet sharing the pixel may be painted after it)
    r, c = ras._centres(union)
    buf = np.asarray(panel.canvas.buffer_rgba())
    colors = {_rgb(f.color) for f in sc.features}
    eq = buf.shape[0] - 1 - int(ax.transData.transform((0.0, 0.0))[1])  # drawn over
    shown = [tuple(int(v) for v in buf[i, j, :3]) for i, j in zip(r, c, strict=True)]
    assert (
        all(
            any(_near(rgb, k, 4) for k in colors)
            for rgb, i in zip(shown, r, strict=True)
            if abs(i - eq) > 2
        )
        and (np.abs(r - eq) > 2).sum() > 100
    )
    # the map's unlit pixels keep the background: one painted pixel per lit facet at most,
    # plus the pixels whose centres lie in lit facets
    painted = ras.paint(buf.copy(), np.zeros(4, np.uint8))
    assert union.size <= painted <= 2 * union.size + 2000


def test_hidden_bitmaps_layer_hides_the_maps(qtbot):
    sc = load(SCENES / "sphere_teaching.toml")
    panel = _panel(qtbot, Bitmaps3DPanel)
    panel.set_state(compute_state3d(sc), sc)
    assert panel.canvas.isVisible()
    hidden = sc.copy()
    hidden.layers = [k for k in sc.layers if k != "bitmaps"]
    panel.set_state(compute_state3d(hidden), hidden)
    assert not panel.canvas.isVisible() and panel.message.text() == "bitmaps layer hidden"


@pytest.mark.parametrize(("name", "eye", "ball"), [("sphere_teaching", "B", 1),
                                                   ("sphere_paper", "A", 2)])  # fmt: skip
def test_hover_names_the_facet_under_the_mouse(qtbot, name, eye, ball):
    """A real mouse move (the X pointer warped by QTest) onto a facet's centre shows its
    index, direction and solid angle; off the map the text goes."""
    sc = load(SCENES / f"{name}.toml")
    st = compute_state3d(sc)
    panel = _panel(qtbot, Bitmaps3DPanel)
    panel.set_state(st, sc)
    _settle(qtbot, panel)
    nside = st.pair.nside
    pix = int(st.lit(ball, eye)[len(st.lit(ball, eye)) // 2])
    if nside > 32:  # a facet of nside 180 is ~0.4 px wide: hover what is under the pixel
        pt = _canvas_px(panel, eye, pix)
        ratio = panel.canvas.devicePixelRatioF()
        dx, dy = pt.x() * ratio, (panel.canvas.height() - pt.y()) * ratio
        x, y = panel.axes[eye].transData.inverted().transform((dx, dy))
        pix = int(pixel_at(nside, x, y))
    else:
        pt = _canvas_px(panel, eye, pix)
    QTest.mouseMove(panel.canvas, pt)
    qtbot.waitUntil(lambda: f"facet {pix:,}:" in panel.hover.text(), timeout=3000)
    text = panel.hover.text()
    assert text.startswith(f"eye {eye}, facet {pix:,}:")
    c = healpix.centers(nside, np.array([pix]))[0]
    az = math.degrees(math.atan2(c[1], c[0])) % 360
    el = math.degrees(math.asin(c[2]))
    assert f"azimuth {az:.2f}°, elevation {el:.2f}°" in text
    sr = 4 * math.pi / healpix.npix(nside)
    assert f"{sr:.3g} sr = {sr * (180 / math.pi) ** 2:.3g} deg²" in text
    if pix in set(_union(st, eye).tolist()):
        owner = dict(zip(*lit_owners((st.lit_a, st.lit_b)["AB".index(eye)]), strict=True))
        assert text.endswith(f"lit by {sc.features[int(owner[pix])].name!r}")
    assert panel.hover_pix == (eye, pix)
    QTest.mouseMove(panel.canvas, QtCore.QPoint(2, 2))  # outside both maps
    qtbot.waitUntil(lambda: panel.hover.text() == "", timeout=3000)


def test_readout_shows_the_figures_rows_and_follows_the_state(qtbot):
    sc = load(SCENES / "sphere_equator.toml")
    st = compute_state3d(sc)
    panel = _panel(qtbot, Readout3DPanel, 360, 300)
    panel.set_state(st, sc)
    rows = readout_rows(st, sc)
    assert panel.table.rowCount() == len(sc.features)
    shown = [
        tuple(panel.table.item(i, j).text() for j in range(panel.table.columnCount()))
        for i in range(panel.table.rowCount())
    ]
    assert shown == rows
    assert panel.text(0, "lit A/B") == "126/126" and panel.text(0, "BFV") == "yes"
    moved = sc.copy()
    moved.features[0].y = 3000.0
    moved.features[0].z = 900.0
    st2 = compute_state3d(moved)
    panel.set_state(st2, moved)
    assert panel.text(0, "r") == f"{math.hypot(3000, 900):.0f}"
    assert panel.text(0, "el°") == f"{math.degrees(math.atan2(900, 3000)):.1f}"
    assert panel.text(0, "lit A/B") == f"{st2.facets_a[0]}/{st2.facets_b[0]}" != "126/126"
    assert panel.text(1, "r") == rows[1][1]  # the other balls unchanged
    fewer = moved.copy()
    fewer.features = fewer.features[:2]
    panel.set_state(compute_state3d(fewer), fewer)
    assert panel.table.rowCount() == 2
    # fits a side dock: the columns' widths add up to a dock's width
    head = panel.table.horizontalHeader()
    assert sum(head.sectionSize(j) for j in range(head.count())) < 520


# --- the way back from a map point to a facet (pure, no window) -------------------------


@pytest.mark.parametrize("nside", [2, 16, 180])
def test_every_facet_centre_maps_back_to_its_facet(nside):
    n = healpix.npix(nside)
    pix = np.arange(n) if n < 50_000 else np.random.default_rng(0).choice(n, 50_000)
    c = healpix.centers(nside, pix)
    mx, my = view_lonlat(np.arctan2(c[:, 1], c[:, 0]), np.arcsin(c[:, 2]))
    x, y = mollweide(mx, my)
    np.testing.assert_array_equal(pixel_at(nside, x, y), pix)


def test_mollweide_inverts_and_matches_matplotlib():
    from matplotlib.projections.geo import MollweideAxes

    rng = np.random.default_rng(1)
    lon = rng.uniform(-math.pi, math.pi, 20_000)
    lat = np.arcsin(rng.uniform(-1, 1, 20_000))
    x, y = mollweide(lon, lat)
    theta = np.arcsin(y / math.sqrt(2))
    assert np.abs(2 * theta + np.sin(2 * theta) - math.pi * np.sin(lat)).max() < 1e-14
    lon2, lat2, inside = mollweide_inverse(x, y)
    assert inside.all()
    assert np.abs(lat2 - lat).max() < 1e-7 and np.abs(lon2 - lon).max() < 1e-7
    mpl = MollweideAxes.MollweideTransform(1).transform_non_affine(np.column_stack([lon, lat]))
    assert np.abs(mpl - np.column_stack([x, y])).max() < 3e-3  # its looser Newton
    assert not mollweide_inverse(2.9, 0.0)[2] and not mollweide_inverse(0.0, 1.5)[2]
    assert pixel_at(8, 2.9, 0.0) == -1


def test_astropy_healpix_agrees_with_the_hover_lookup():
    """astropy-healpix's lonlat_to_healpix (RING) gives the facets pixel_at gives, also at
    nside 180 (not a power of two), away from the cells' boundaries."""
    import astropy.units as u
    from astropy_healpix import core

    rng = np.random.default_rng(2)
    x = rng.uniform(-2.8, 2.8, 20_000)
    y = rng.uniform(-1.4, 1.4, 20_000)
    lon, lat, inside = mollweide_inverse(x, y)
    x, y, lon, lat = x[inside], y[inside], lon[inside], lat[inside]
    mlon = np.mod(math.pi / 2 - lon, 2 * math.pi)  # the map's forward at the centre, flipped
    for nside in (16, 180):
        theirs = core.lonlat_to_healpix(mlon * u.rad, lat * u.rad, nside, order="ring")
        np.testing.assert_array_equal(pixel_at(nside, x, y), theirs)


def test_lit_owners_later_ball_wins():
    indptr = np.array([0, 3, 5])
    idx = np.array([1, 4, 9, 4, 7])
    pix, ball = lit_owners((indptr, idx))
    assert pix.tolist() == [1, 4, 7, 9] and ball.tolist() == [0, 1, 1, 0]
