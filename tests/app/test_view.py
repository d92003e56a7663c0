"""The view widget (eyeviz/app/view.py): pyvistaqt's QtInteractor by default, VTK's own
widget behind EYEVIZ_VIEW=vtk; both drive the same drag and draw the same picture, and
no sibling widget becomes a native window (issue 12, drag latency)."""

import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from mouse import drag, pixel_of
from PyQt5 import QtCore, QtWidgets

import eyeviz.app.view as view
from eyeviz.app.screenshot import qimage_to_array
from eyeviz.model.scene import load

ROOT = Path(__file__).resolve().parents[2]


def test_the_default_view_is_pyvistaqt():
    code = "import eyeviz.app.view as v; print(v.BACKEND)"
    env = {k: v for k, v in os.environ.items() if k != "EYEVIZ_VIEW"}
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env)
    assert r.stdout.strip() == "pyvistaqt", r.stderr


@pytest.mark.parametrize("backend", ["pyvistaqt", "vtk"])
def test_both_views_drag_and_draw_the_scene(make_window, monkeypatch, backend):
    monkeypatch.setattr(view, "BACKEND", backend)
    win = make_window(load(ROOT / "assets" / "scenes" / "default.toml"))
    assert win.plotter.backend == backend
    # only the view and its ancestors are native windows: a native sibling (dock, status
    # bar, bitmaps panel) was flushed to X on its own every drag frame
    native = {
        type(w).__name__
        for w in win.findChildren(QtWidgets.QWidget)
        if w.testAttribute(QtCore.Qt.WA_NativeWindow)
    }
    assert native <= {type(win.plotter).__name__, "QSplitter"}, native
    f = win.model.scene.features[0]
    x0, y0 = f.x, f.y
    frames = win.plotter.frames
    start = pixel_of(win, f.x, f.y)
    drag(win, start, start + QtCore.QPoint(60, 25))
    QtWidgets.QApplication.processEvents()
    moved = win.model.scene.features[0]
    assert (moved.x, moved.y) != (x0, y0) and win.undo_stack.count() == 1
    assert win.plotter.frames > frames
    img = qimage_to_array(win.grab_image())
    assert img.std() > 20 and len(np.unique(img.reshape(-1, 3), axis=0)) > 50


def test_an_unknown_view_is_refused_in_one_line(tmp_path):
    env = dict(os.environ, EYEVIZ_VIEW="opengl")
    r = subprocess.run(
        [sys.executable, "-m", "eyeviz", "app", "--screenshot", str(tmp_path / "x.png")],
        capture_output=True,
        text=True,
        env=env,
        timeout=60,
    )
    assert r.returncode == 2
    lines = [ln for ln in r.stderr.splitlines() if "XDG_RUNTIME_DIR" not in ln]
    assert len(lines) == 1 and "EYEVIZ_VIEW" in lines[0] and "opengl" in lines[0], r.stderr
    assert not (tmp_path / "x.png").exists()


@pytest.mark.parametrize("backend", ["pyvistaqt", "vtk"])
def test_a_real_x_pointer_drags_a_feature_and_ctrl_z_undoes_it(
    make_window, qtbot, monkeypatch, backend
):
    """The pointer and keys through the X server (xdotool), as a user's hand would."""
    if shutil.which("xdotool") is None:
        pytest.fail("xdotool is needed for this test: apt-get install xdotool")
    monkeypatch.setattr(view, "BACKEND", backend)
    win = make_window(load(ROOT / "assets" / "scenes" / "default.toml"))
    win.activateWindow()
    win.raise_()
    f = win.model.scene.features[0]
    x0, y0 = f.x, f.y
    p = win.plotter.mapToGlobal(pixel_of(win, f.x, f.y))

    def xdo(*args):
        subprocess.run(["xdotool", *map(str, args)], check=True)
        qtbot.wait(30)

    xdo("mousemove", p.x(), p.y())
    xdo("mousedown", 1)
    for k in range(1, 9):
        xdo("mousemove", p.x() + 8 * k, p.y() + 3 * k)
    xdo("mouseup", 1)
    qtbot.waitUntil(lambda: win.undo_stack.count() == 1, timeout=3000)
    moved = win.model.scene.features[0]
    assert (moved.x, moved.y) != (x0, y0)
    # the disc is drawn where the model says, through the same camera the pointer used
    end = win.plotter.mapToGlobal(pixel_of(win, moved.x, moved.y))
    assert abs(end.x() - (p.x() + 64)) <= 2 and abs(end.y() - (p.y() + 24)) <= 2
    wid = str(int(win.winId()))
    xdo("key", "--window", wid, "ctrl+z")
    qtbot.waitUntil(lambda: win.undo_stack.index() == 0, timeout=3000)
    back = win.model.scene.features[0]
    assert (back.x, back.y) == (x0, y0)
