"""Editing balls in the 3D view with real X input (xdotool), issue 32 items 5 and 6:

- a depth drag (Shift held) moves the ball about a pixel's span in the screen plane per
  pixel (it moved thousands of units in 50 px), and Ctrl+Z puts back the ball and the
  view the drag started from, also when the view was re-framed after the drag;
- the readout's r, azimuth, elevation and g cells take typed values (one undo step); a
  bad value is refused in one line with nothing changed; a click on a row selects it."""

from __future__ import annotations

import math
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest
from PyQt5 import QtCore

from eyeviz.model.scene import load

SCENES = Path(__file__).resolve().parents[2] / "eyeviz" / "assets" / "scenes"


@pytest.fixture(scope="module")
def win(qapp, tmp_path_factory):
    from eyeviz.app.window import MainWindow, make_app, make_settings

    if shutil.which("xdotool") is None:
        pytest.fail("xdotool is needed for these tests: apt-get install xdotool")
    make_app()
    w = MainWindow(
        load(SCENES / "sphere_paper.toml"),
        None,
        settings=make_settings(tmp_path_factory.mktemp("s") / "settings.json"),
    )
    w._force_close = True
    w.resize(1280, 720)
    w.show()
    w.activateWindow()
    w.raise_()
    qapp.processEvents()
    w.jobs.wait()
    yield w
    w.force_close()


def _xdo(qapp, *args) -> None:
    subprocess.run(["xdotool", *map(str, args)], check=True)
    for _ in range(4):
        qapp.processEvents()
        QtCore.QThread.msleep(15)


def _centre(host, i: int) -> np.ndarray:
    f = host.model.scene.features[i]
    return np.array([f.x, f.y, f.z])


def test_depth_drag_pixel_for_pixel_and_undo_puts_the_view_back(win, qapp):
    host = win.host3d
    host.set_preset("default")
    qapp.processEvents()
    host.model.select(0)
    c0, cam0 = _centre(host, 0), host.camera()
    stack0 = win.undo_stack.count()
    x, y = host.scene_pixel(c0)
    p = host.view.mapToGlobal(QtCore.QPoint(round(x), round(y)))
    _xdo(qapp, "mousemove", p.x(), p.y())
    _xdo(qapp, "keydown", "shift")
    _xdo(qapp, "mousedown", 1)
    for k in range(1, 6):
        _xdo(qapp, "mousemove", p.x(), p.y() + 10 * k)  # 50 px down: nearer
    _xdo(qapp, "mouseup", 1)
    _xdo(qapp, "keyup", "shift")
    assert win.undo_stack.count() == stack0 + 1
    c1 = _centre(host, 0)
    # what 50 px span in the screen plane at the ball's depth
    right, up, back = (np.asarray(v) for v in _basis(cam0))
    depth = float((np.asarray(cam0.position) - c0) @ back)
    vp = host.pointer("move", 0, 0)
    span = 50 * 2.0 * depth * math.tan(math.radians(cam0.view_angle) / 2.0) / vp.h
    moved = float(np.linalg.norm(c1 - c0))
    assert 0.6 * span <= moved <= 1.2 * span, (moved, span)  # was a factor 1.28 of depth
    sight = (c0 - np.asarray(cam0.position)) / np.linalg.norm(c0 - np.asarray(cam0.position))
    assert float((c1 - c0) @ sight) < 0  # down: nearer the camera, along the line of sight
    # the view re-framed after the drag (as a resize does with a preset kept)
    host.set_preset("top")
    qapp.processEvents()
    assert not np.allclose(host.camera().position, cam0.position)
    host.view.setFocus()
    _xdo(qapp, "key", "ctrl+z")
    assert np.allclose(_centre(host, 0), c0)
    cam = host.camera()
    assert np.allclose(cam.position, cam0.position) and np.allclose(
        cam.focal_point, cam0.focal_point
    )


def _basis(cam):
    from eyeviz.model.camera3d import basis

    return basis(cam)


def _cell_point(win, row: int, col: int) -> QtCore.QPoint:
    t = win.host3d.readout.table
    rect = t.visualItemRect(t.item(row, col))
    return t.viewport().mapToGlobal(rect.center())


def _type_cell(win, qapp, row: int, col: int, text: str) -> None:
    p = _cell_point(win, row, col)
    _xdo(qapp, "mousemove", p.x(), p.y())
    _xdo(qapp, "click", "--repeat", 2, "--delay", 60, 1)
    _xdo(qapp, "key", "ctrl+a")
    _xdo(qapp, "type", "--delay", 20, "--", text)
    _xdo(qapp, "key", "Return")


def test_typed_coordinates_and_row_clicks(win, qapp):
    host = win.host3d
    readout = host.readout
    win.host3d.docks["readout3d"].raise_()
    qapp.processEvents()
    assert len(host.model.scene.features) >= 2
    # a click on row 1 selects ball 1
    host.model.select(0)
    p = _cell_point(win, 1, 0)
    _xdo(qapp, "mousemove", p.x(), p.y())
    _xdo(qapp, "click", 1)
    assert host.model.selected == 1
    # r typed: the distance changes, azimuth and elevation kept; one undo step
    st = host.model.state
    r0, az, el = float(st.r[1]), math.degrees(st.azimuth[1]), math.degrees(st.elevation[1])
    n0 = win.undo_stack.index()
    _type_cell(win, qapp, 1, 1, "2500")
    st = host.model.state
    assert st.r[1] == pytest.approx(2500.0)
    assert math.degrees(st.azimuth[1]) == pytest.approx(az)
    assert math.degrees(st.elevation[1]) == pytest.approx(el)
    assert win.undo_stack.index() == n0 + 1 and not readout.message.isVisible()
    assert readout.text(1, "r") == "2500"
    # elevation and g typed
    _type_cell(win, qapp, 1, 3, "-10")
    assert math.degrees(host.model.state.elevation[1]) == pytest.approx(-10.0)
    _type_cell(win, qapp, 1, 4, "75")
    assert host.model.scene.features[1].g == 75.0
    assert win.undo_stack.index() == n0 + 3
    # refused: one line, nothing changed, the cell shows the value kept
    before = host.model.scene.copy()
    for col, text, why in ((3, "95", "elevation must be within [-90, 90]"),
                           (2, "abc", "azimuth must be a number, got 'abc'"),
                           (4, "-5", "g (ball radius) must be > 0")):  # fmt: skip
        _type_cell(win, qapp, 1, col, text)
        msg = readout.message.text()
        assert readout.message.isVisible() and msg.startswith("Refused: ") and why in msg
        assert "\n" not in msg
        assert host.model.scene == before and win.undo_stack.index() == n0 + 3
        assert readout.table.item(1, col).text() != text
    # undo: the typed g, then the elevation, then r
    for _ in range(3):
        win.undo_stack.undo()
    assert host.model.state.r[1] == pytest.approx(r0)
    assert math.degrees(host.model.state.elevation[1]) == pytest.approx(el)
