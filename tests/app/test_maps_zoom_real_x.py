"""The Facets dock's maps at nside 180 (issue 32 item 9), through the real window and the
X server: the wheel zooms the maps (real wheel clicks with xdotool), a drag pans them, a
double click and "Whole map" go back; the selected ball's dot is not hidden by its
outline nor by the equator; the equator's label sits beside the map, off the facets."""

from __future__ import annotations

import shutil
import subprocess

import numpy as np
import pytest
from PyQt5 import QtCore

from eyeviz.model.scene import load
from eyeviz.resources import scene_path

pytestmark = pytest.mark.skipif(shutil.which("xdotool") is None, reason="needs xdotool")


@pytest.fixture
def maps(make_window, qtbot):
    win = make_window(load(scene_path("sphere_equator")))  # nside 180; ball 0 'mid' selected
    panel = win.host3d.bitmaps
    qtbot.waitUntil(lambda: panel._bg is not None and panel.canvas.isVisible(), timeout=10000)
    return win, panel


def _ball_centre(panel, st, eye: str = "A", ball: int = 0) -> tuple[float, float]:
    """Map-plane centre of the ball's lit facets on ``eye``'s map (state ``st``)."""
    pts = np.array([panel.map_point(eye, int(p)) for p in st.lit(ball, eye)])
    return float(pts[:, 0].mean()), float(pts[:, 1].mean())


def _screen(panel, eye: str, x: float, y: float) -> QtCore.QPoint:
    """The screen pixel of map point (x, y) of ``eye``'s map."""
    dx, dy = panel.axes[eye].transData.transform((x, y))
    r = panel.canvas.devicePixelRatioF()
    local = QtCore.QPoint(round(dx / r), round(panel.canvas.height() - dy / r))
    return panel.canvas.mapToGlobal(local)


def _xdo(*args: str) -> None:
    subprocess.run(["xdotool", *args], check=True)


def _colour_px(panel, eye: str, rgb: tuple[int, int, int]) -> int:
    """Pixels of ``eye``'s map within 40 of colour ``rgb``."""
    buf = np.asarray(panel.canvas.buffer_rgba())[..., :3].astype(int)
    x0, y0, x1, y1 = panel.axes[eye].bbox.extents
    h = buf.shape[0]
    box = buf[int(h - y1) : int(h - y0), int(x0) : int(x1)]
    return int(np.count_nonzero(np.abs(box - np.array(rgb)).max(axis=-1) < 40))


def test_the_wheel_zooms_a_drag_pans_and_a_double_click_shows_the_whole_map(maps, qtbot):
    win, panel = maps
    orange = (0xD5, 0x5E, 0x00)  # 'mid'
    before = _colour_px(panel, "A", orange)
    assert not panel.zoom.zoomed and not panel.whole.isVisible()
    cx, cy = _ball_centre(panel, win.host3d.model.state)
    p = _screen(panel, "A", cx, cy)
    _xdo("mousemove", "--sync", str(p.x()), str(p.y()))
    qtbot.wait(100)
    for _ in range(8):  # eight real wheel clicks up
        _xdo("click", "4")
        qtbot.wait(30)
    qtbot.waitUntil(lambda: panel.zoom.factor > 5, timeout=5000)
    qtbot.waitUntil(lambda: panel._bg is not None, timeout=5000)
    qtbot.wait(200)
    assert panel.whole.isVisible()  # over the canvas: the dock's layout did not move
    assert panel.whole.parent() is panel.canvas
    # both maps show the same window; the ball's dot became a patch many times larger
    assert panel.axes["B"].get_xlim() == panel.axes["A"].get_xlim()
    after = _colour_px(panel, "A", orange)
    assert after > 10 * max(before, 1), (before, after)
    # the point under the mouse stayed there (zoom about the cursor)
    x0, x1 = panel.axes["A"].get_xlim()
    assert x0 < cx < x1
    # a real left drag pans: the window moves against the mouse
    lim0 = panel.zoom.limits
    _xdo("mousedown", "1")
    for k in range(1, 6):
        _xdo("mousemove", "--sync", str(p.x() + 12 * k), str(p.y()))
        qtbot.wait(30)
    _xdo("mouseup", "1")
    qtbot.waitUntil(lambda: panel.zoom.limits != lim0, timeout=5000)
    assert panel.zoom.limits[0] < lim0[0]  # dragged right: the map shows what lay left
    # a real double click: the whole map again
    _xdo("click", "--repeat", "2", "--delay", "60", "1")
    qtbot.waitUntil(lambda: not panel.zoom.zoomed, timeout=5000)
    assert not panel.whole.isVisible()
    # the wheel again, then the button
    _xdo("click", "4")
    qtbot.waitUntil(lambda: panel.zoom.zoomed, timeout=5000)
    panel.whole.click()
    assert not panel.zoom.zoomed
    assert panel.axes["A"].get_xlim() == pytest.approx(panel._home_lim[:2])


def test_the_selected_dot_and_the_equator_label_stay_clear(maps, qtbot):
    win, panel = maps
    assert panel.selected == 0 and "A" in panel._raster  # 'mid', on the equator
    orange = (0xD5, 0x5E, 0x00)
    lit_px = _colour_px(panel, "A", orange)
    # the dot keeps its colour: the outline rings it one pixel off, the equator runs under
    cx, cy = _ball_centre(panel, win.host3d.model.state)
    dx, dy = panel.axes["A"].transData.transform((cx, cy))
    buf = np.asarray(panel.canvas.buffer_rgba())[..., :3].astype(int)
    h = buf.shape[0]
    centre = buf[int(h - 1 - np.floor(dy)), int(np.floor(dx))]
    assert np.abs(centre - np.array(orange)).max() < 40, centre
    assert lit_px >= 4
    # the equator's label lies beside the map: wholly left of its left tip
    r = panel.fig.canvas.get_renderer()
    for eye, ax in panel.axes.items():
        label = next(t for t in ax.texts if t.get_gid() == "equator")
        assert label.get_visible() and "m = 720" in label.get_text()
        box = label.get_window_extent(r)
        tip_x, tip_y = ax.transData.transform((-2 * np.sqrt(2.0), 0.0))
        assert box.x1 < tip_x, (eye, box, tip_x)
        assert box.y0 < tip_y < box.y1  # level with the equator


def test_a_selected_ball_under_a_later_one_keeps_its_outline_at_nside_8(make_window, qtbot):
    sc = load(scene_path("sphere_teaching"))  # nside 8: facets many pixels wide
    big = sc.features[1]  # a later ball, larger, over ball 0: it colours all its facets
    big.x, big.y, big.z = sc.features[0].x, sc.features[0].y, sc.features[0].z
    big.g = 2.0 * sc.features[0].g
    win = make_window(sc)
    panel = win.host3d.bitmaps
    qtbot.waitUntil(lambda: panel._bg is not None and panel.canvas.isVisible(), timeout=10000)
    st = win.host3d.model.state
    assert panel.selected == 0 and "A" not in panel._raster
    pix, owner = panel.owners["A"]
    mine = st.lit(0, "A")
    assert mine.size and np.all(owner[np.searchsorted(pix, mine)] == 1)  # all covered

    def dark_inside() -> int:
        panel._repaint()
        ax = panel.axes["A"]
        pts = np.array([ax.transData.transform(panel.map_point("A", int(p))) for p in mine])
        buf = np.asarray(panel.canvas.buffer_rgba())[..., :3].astype(int)
        h = buf.shape[0]
        (x0, y0), (x1, y1) = pts.min(axis=0), pts.max(axis=0)
        box = buf[int(h - y1) : int(h - y0) + 1, int(x0) : int(x1) + 1]
        return int(np.count_nonzero(box.max(axis=-1) < 70))

    outlined = dark_inside()
    panel.set_state(st, win.host3d.model.scene, None)
    plain = dark_inside()
    assert outlined > plain + 10, (outlined, plain)
