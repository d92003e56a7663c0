"""The responses layer in the real window (issue 34 item 2, docs/responses.md "In the
app"): turned on from the 3D view menu for the honeybee, each lit facet on the eye and on
the Facets dock's map is its ball's colour blended towards the unlit grey by 1 - its
gaussian response (the pair's own ``responses``), and hovering a lit facet names its value."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from PyQt5 import QtCore, QtGui
from PyQt5.QtTest import QTest

from eyeviz.app.panels.bitmaps3d import lit_owners
from eyeviz.model.scene import load
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
    bare = np.asarray(host.actors.eyes.meshes[0].cell_data["rgb"]).copy()
    assert (bare[idx[[lo, hi]]] == ball).all()  # without the layer: the plain colour
    act.trigger()  # the 3D view menu's "Show the lit facets' graded responses"
    assert host.model.scene.shows("responses")
    host.flush()
    rgb = np.asarray(host.actors.eyes.meshes[0].cell_data["rgb"])
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
    rgb = np.asarray(host.actors.eyes.meshes[0].cell_data["rgb"])
    assert (rgb[idx[[lo, hi]]] == ball).all()
