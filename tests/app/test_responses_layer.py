"""The responses layer in the real window (issue 34 item 2, docs/responses.md "In the
app"): turned on from the 3D view menu for the honeybee, each lit facet on the eye and on
the Facets dock's map is its ball's colour blended towards the unlit grey by 1 - its
gaussian response (the pair's own ``responses``), and hovering a lit facet names its value."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from PyQt5 import QtCore, QtGui
from PyQt5.QtTest import QTest

from eyeviz.app.panels.bitmaps3d import lit_owners
from eyeviz.model.scene import load
from eyeviz.render.vtk.primitives import read_rgb
from eyeviz.render.vtk.style import UNLIT, hex_rgb

BEE = Path(__file__).resolve().parents[2] / "eyeviz" / "assets" / "scenes" / "bee.toml"


def _owned(st, e: str, i: int) -> tuple[np.ndarray, np.ndarray]:
    """Ball i's facets on eye e that it colours (no later ball lights them), and their
    gaussian responses from the pair's public call."""
    f = [st.x, st.y, st.z, st.g]
    a, b = st.pair.responses(*f, kind="gaussian")
    ip, ix, vals = a if e == "A" else b
    pix, ball = lit_owners((ip, ix))
    mine = set(pix[ball == i].tolist())
    row = slice(int(ip[i]), int(ip[i + 1]))
    keep = np.array([k in mine for k in ix[row].tolist()])
    return ix[row][keep], vals[row][keep]


def _weight(rgb, ball) -> float:
    """How far a colour lies from the unlit grey towards the ball's colour (0..1)."""
    u, c = np.asarray(UNLIT, float), np.asarray(ball, float)
    d = c - u
    return float(np.dot(np.asarray(rgb, float) - u, d) / np.dot(d, d))


def _pick(idx, vals) -> tuple[int, int]:
    """Two facets whose responses differ well (the lowest above 0.1 and the highest)."""
    ok = np.flatnonzero(vals > 0.1)
    lo, hi = ok[np.argmin(vals[ok])], int(np.argmax(vals))
    assert vals[hi] - vals[lo] > 0.3
    return int(lo), hi


def test_the_responses_layer_shades_the_eye_and_the_map(make_window, qtbot):
    win = make_window(load(BEE), BEE)
    host = win.host3d
    act = host.layer_actions["responses"]
    assert act.isVisible() and not act.isChecked()  # off by default
    st = host.model.state
    i, e = 2, "A"  # "far": the largest patch
    idx, vals = _owned(st, e, i)
    lo, hi = _pick(idx, vals)
    ball = hex_rgb(host.model.scene.features[i].color)
    host.flush()
    bare = read_rgb(host.actors.eyes.meshes[0]).copy()
    assert (bare[idx[[lo, hi]]] == ball).all()  # without the layer: the plain colour
    act.trigger()  # the 3D view menu's "Show the lit facets' graded responses"
    assert host.model.scene.shows("responses")
    host.flush()
    rgb = read_rgb(host.actors.eyes.meshes[0])
    w = [_weight(rgb[idx[k]], ball) for k in (lo, hi)]
    assert w[0] < w[1] - 0.2, w  # the higher response, nearer the ball's colour
    for k in (lo, hi):
        assert abs(_weight(rgb[idx[k]], ball) - vals[k]) < 0.06, (k, vals[k])
    # the Facets dock: the same shades on the map, and the hover names the value
    host.docks["bitmaps3d"].show()
    host.docks["bitmaps3d"].raise_()
    panel = host.bitmaps
    host.refresh_panels()
    qtbot.waitUntil(lambda: panel.canvas.isVisible() and panel._bg is not None, timeout=8000)
    qtbot.waitUntil(lambda: e in panel.values, timeout=3000)
    img = panel.canvas.grab().toImage()
    ratio = panel.canvas.devicePixelRatioF()
    seen = []
    for k in (lo, hi):
        x, y = panel.axes[e].transData.transform(panel.map_point(e, int(idx[k])))
        pt = QtCore.QPoint(round(x / ratio), round(panel.canvas.height() - y / ratio))
        c = QtGui.QColor(img.pixel(pt.x(), pt.y()))
        seen.append(_weight((c.red(), c.green(), c.blue()), ball))
        QTest.mouseMove(panel.canvas, pt)
        want = f"facet {int(idx[k]):,}:"
        qtbot.waitUntil(lambda w=want: w in panel.hover.text(), timeout=3000)
        assert panel.hover.text().endswith(f"response {vals[k]:.3g} (gaussian)")
    assert seen[0] < seen[1] - 0.2, seen
    act.trigger()  # off again: the plain colour
    host.flush()
    rgb = read_rgb(host.actors.eyes.meshes[0])
    assert (rgb[idx[[lo, hi]]] == ball).all()


@pytest.mark.slow  # a second window: 8-30 s on the shared machine
def test_healpix_cells_are_shaded_at_any_size_and_during_a_drag(make_window, qtbot):
    """A HEALPix pair (nside 16: the full surface): a ball lighting many cells (more than
    the old 24-cell bound) and not selected is shaded by its cells' exact shares, at rest
    and on a drag frame (the gesture still open), as the pair's own ``responses`` say."""
    from eyeviz.model.scene import OKABE_ITO, Eyes, Feature, Scene

    big = Feature("big", 0.0, 150.0, 25.0, OKABE_ITO[1], 0.0)
    small = Feature("small", 60.0, 400.0, 12.0, OKABE_ITO[2], 30.0)
    layers = ["eyes", "features", "bitmaps", "responses"]
    win = make_window(Scene(Eyes(40.0, 20.0, nside=16), [big, small], layers))
    host = win.host3d
    host.model.select(1)
    ball = hex_rgb(big.color)
    for x in (None, 9.0):  # at rest, then a drag frame
        if x is not None:
            host.model.begin_live("Drag big")
            host.model.live(0, x=x)
        host.flush()
        st = host.model.state
        (ip, ix, vals), _ = st.pair.responses(st.x, st.y, st.z, st.g)
        pix, owner = lit_owners((ip, ix))
        mine = set(pix[owner == 0].tolist())
        row = range(int(ip[0]), int(ip[1]))
        assert len(row) > 24
        keep = [k for k in row if int(ix[k]) in mine]
        rgb = read_rgb(host.actors.eyes.meshes[0])
        part = [k for k in keep if 0.1 < vals[k] < 0.9]
        assert part and any(vals[k] == 1.0 for k in keep)
        for k in part:
            assert abs(_weight(rgb[ix[k]], ball) - vals[k]) < 0.06, (x, k, vals[k])
    assert host.model.live_open  # the frame above was drawn inside the gesture
    host.model.end_live()


@pytest.mark.slow  # a third window at nside 64
def test_healpix_patches_beyond_the_full_surface_are_shaded(make_window, qtbot):
    """nside 64 (beyond the full surface: each ball's lit cells are a patch mesh of their
    own, one cell per facet): with the layer on, each patch cell is its ball's colour at
    the cell's exact share, at rest and after a move; with the layer off, the plain colour."""
    from eyeviz.model.scene import OKABE_ITO, Eyes, Feature, Scene

    big = Feature("big", 0.0, 150.0, 25.0, OKABE_ITO[1], 0.0)
    layers = ["eyes", "features", "bitmaps", "responses"]
    win = make_window(Scene(Eyes(40.0, 20.0, nside=64), [big], layers))
    host = win.host3d
    ball = hex_rgb(big.color)
    painter = host.actors.eyes
    assert not painter.full
    for x in (None, 9.0):
        if x is not None:
            host.model.begin_live("Drag big")
            host.model.live(0, x=x)
            host.model.end_live()
        host.flush()
        st = host.model.state
        (ip, ix, vals), _ = st.pair.responses(st.x, st.y, st.z, st.g)
        mesh = painter.patches[0][0][0]
        assert mesh.GetNumberOfCells() == int(ip[1] - ip[0]) > 24
        rgb = read_rgb(mesh)
        part = [k for k in range(mesh.GetNumberOfCells()) if 0.1 < vals[k] < 0.9]
        assert part and any(vals[k] == 1.0 for k in range(mesh.GetNumberOfCells()))
        for k in part:
            assert abs(_weight(rgb[k], ball) - vals[k]) < 0.06, (x, k, vals[k])
    host.model.set_layer("responses", False)
    host.flush()
    rgb = read_rgb(painter.patches[0][0][0])
    assert (rgb == np.asarray(ball, np.uint8)).all()
