"""The spherical lecture as a lecturer gives it (issue 32): real keys (xdotool) into the real
window under a window manager; each step frames what it talks about, F5 keeps the panels
a step names, the zoom reaches every panel, and nothing moves on its own."""

import subprocess

import numpy as np
import pytest
from mouse import x_focus
from PyQt5 import QtCore, QtGui, QtWidgets
from test_presenting_real_x import _focus, _keys, _scene, window_manager  # noqa: F401

from eyeviz.app.help import SPHERICAL_SECTION
from eyeviz.app.panels.bitmaps3d import MAP_TITLE_PT
from eyeviz.model.camera3d import basis
from eyeviz.model.scene import load
from eyeviz.resources import scene_path


def _focus3d(win, qtbot):
    view = win.host3d.view
    x_focus(win, view)


def _in_view(host, point, margin=0.0) -> bool:
    """Whether model ``point`` is drawn inside the scene viewport of the 3D view."""
    from eyeviz.render.vtk.scene3d import split_viewports

    w, h = host.view.width(), host.view.height()
    _, (x0, _, x1, _) = split_viewports(w, h)
    c, r = host.scene_pixel(point)
    return x0 * w + margin <= c <= x1 * w - margin and margin <= r <= h - margin


def _ball_px(host, f) -> float:
    """The ball's radius on screen in pixels (its centre and a point g off it sideways)."""
    right, _, _ = basis(host.camera())
    c = np.array([f.x, f.y, f.z])
    a, b = host.scene_pixel(c), host.scene_pixel(c + f.g * right)
    return float(np.hypot(a[0] - b[0], a[1] - b[1]))


def _shown(dock) -> bool:
    return dock.isVisible() and not dock.visibleRegion().isEmpty()


@pytest.mark.slow
def test_sphere_lecture_frames_each_step_and_keeps_its_panels_in_f5(make_window, qtbot):
    path = scene_path("sphere_lecture")
    whole = load(path)
    win = make_window(load(path), path)
    win.resize(1280, 720)
    qtbot.waitUntil(lambda: win.width() == 1280, timeout=3000)
    host, steps = win.host3d, whole.steps
    maps, readout = host.docks["bitmaps3d"], host.docks["readout3d"]
    _focus3d(win, qtbot)
    _keys(qtbot, "F5", until=lambda: win.presenter.presenting)
    qtbot.waitUntil(lambda: not maps.isVisible(), timeout=3000)
    _keys(qtbot, "Next", until=lambda: win.step_index == 0)
    _keys(qtbot, "Next", until=lambda: win.step_index == 1)
    qtbot.wait(200)
    # item 1: step 2 talks about the ball: it is in the main view, large enough to see
    target = host.model.scene.features[0]
    assert _in_view(host, (target.x, target.y, target.z), margin=5)
    assert _ball_px(host, target) > 25
    # item 8: the view says where it is seen from and which way round the eyes are
    assert host.side.actor.GetVisibility() and "eye A on the right" in host.side.text
    # item 2: the map step keeps the maps panel in presentation mode
    maps_step = next(i for i, s in enumerate(steps) if s.panels == ["maps"])
    _keys(qtbot, *(["Next"] * (maps_step - 1)), until=lambda: win.step_index == maps_step)
    qtbot.waitUntil(lambda: maps.isVisible(), timeout=3000)
    assert not readout.isVisible()
    # a step's named camera (the binocular field from above)
    top = next(i for i, s in enumerate(steps) if s.camera == "top")
    _keys(qtbot, *(["Next"] * (top - maps_step)), until=lambda: win.step_index == top)
    _, up, back = basis(host.camera())
    assert back[2] > 0.99  # looking down
    last = len(steps) - 1
    _keys(qtbot, *(["Next"] * (last - top)), until=lambda: win.step_index == last)
    qtbot.waitUntil(lambda: maps.isVisible() and _shown(readout), timeout=3000)
    for f in host.model.scene.features:
        assert _in_view(host, (f.x, f.y, f.z))
    # the caption is whole with the panels beside it (refitted as the view narrowed)
    bar = win.caption_bar
    qtbot.waitUntil(lambda: _caption_fits(bar), timeout=3000)
    # item 3: 175 % reaches the readout's cells and the maps' words
    _focus3d(win, qtbot)
    for _ in range(4):
        _keys(qtbot, "ctrl+equal")
    qtbot.waitUntil(lambda: win.presenter.scale == 1.75, timeout=3000)
    qtbot.wait(300)
    table = host.readout.table
    rows_h = table.verticalHeader().defaultSectionSize()
    assert rows_h >= table.fontMetrics().height()
    eff = win.presenter.effective_scale
    title_pt = [t.get_fontsize() for t, pt in host.bitmaps._texts if pt == MAP_TITLE_PT]
    assert title_pt and all(p == pytest.approx(MAP_TITLE_PT * eff, rel=0.02) for p in title_pt)
    _no_overlap(host.bitmaps)
    _keys(qtbot, "ctrl+0", until=lambda: win.presenter.scale == 1.0)
    # item 11: leaving F5 raises the readout, not the greyed Estimators tab
    _focus3d(win, qtbot)
    _keys(qtbot, "F5", until=lambda: not win.presenter.presenting)
    qtbot.waitUntil(lambda: _shown(readout), timeout=3000)
    assert not _shown(host.docks["estimators3d"])
    _keys(qtbot, "Escape", until=lambda: win.step_index == -1)


def _caption_fits(bar) -> bool:
    flags = int(QtCore.Qt.TextFlag.TextWordWrap) | int(QtCore.Qt.AlignmentFlag.AlignCenter)
    inner = bar.contentsRect().adjusted(bar.margin(), bar.margin(), -bar.margin(), -bar.margin())
    need = bar.fontMetrics().boundingRect(QtCore.QRect(0, 0, inner.width(), 0), flags, bar.text())
    return need.height() <= inner.height()


def _no_overlap(panel) -> None:
    """No two of the maps' words overlap (drawn at their size now)."""
    panel.canvas.draw()
    r = panel.canvas.get_renderer()
    boxes = [t.get_window_extent(r) for t, _ in panel._texts if t.get_visible()]
    for i, a in enumerate(boxes):
        for b in boxes[i + 1 :]:
            assert not a.overlaps(b), (a, b)


def _settled(host, qtbot):
    """The camera once it stopped changing (no resize pending)."""
    last = host.camera()
    for _ in range(20):
        qtbot.wait(300)
        now = host.camera()
        if now == last:
            return now
        last = now
    return last


@pytest.mark.slow
def test_sphere_view_nothing_moves_on_its_own_and_the_menus_speak_plainly(make_window, qtbot):
    path = scene_path("sphere_lecture")
    win = make_window(load(path), path)
    host = win.host3d
    _focus3d(win, qtbot)
    qtbot.wait(500)
    cam0 = host.camera()
    # item 10: Ctrl+D and Ctrl+N keep the camera
    n = len(host.model.scene.features)
    _keys(qtbot, "ctrl+d", until=lambda: len(host.model.scene.features) == n + 1)
    _keys(qtbot, "ctrl+n", until=lambda: len(host.model.scene.features) == n + 2)
    qtbot.wait(300)
    # not re-framed: the same focal point and direction (a resize may only dolly)
    cam1 = host.camera()
    assert cam1.focal_point == pytest.approx(cam0.focal_point)
    assert basis(cam1)[2] == pytest.approx(basis(cam0)[2])
    cam0 = _settled(host, qtbot)  # a resize after the edits (the readout's new rows) done
    # the wheel over the eyes' close-up does not zoom the main view
    view = host.view
    spot = view.mapToGlobal(QtCore.QPoint(view.width() // 8, view.height() // 2))
    subprocess.run(["xdotool", "mousemove", "--sync", str(spot.x()), str(spot.y())], check=True)
    subprocess.run(["xdotool", "click", "4", "click", "4"], check=True)
    qtbot.wait(300)
    assert host.camera() == cam0
    # the first hover over a map does not push the readout down
    readout = host.docks["readout3d"]
    y0 = readout.mapTo(win, QtCore.QPoint(0, 0)).y()
    x, y = host.bitmaps.map_point("A", int(host.bitmaps.lit_facets("A")[0]))
    canvas = host.bitmaps.canvas
    dx, dy = host.bitmaps.axes["A"].transData.transform((x, y))
    ratio = canvas.devicePixelRatioF()
    px = canvas.mapToGlobal(QtCore.QPoint(int(dx / ratio), int(canvas.height() - dy / ratio)))
    subprocess.run(["xdotool", "mousemove", "--sync", str(px.x()), str(px.y())], check=True)
    qtbot.waitUntil(lambda: host.bitmaps.hover.text() != "", timeout=3000)
    qtbot.wait(200)
    assert readout.mapTo(win, QtCore.QPoint(0, 0)).y() == y0
    # item 11: View > Panels lists the 3D page's panels once each
    win.presenter.fill_panels_menu()
    titles = [a.text() for a in win.presenter.panels_menu.actions()]
    assert sorted(titles) == sorted(d.windowTitle() for d in host.docks.values())
    # F1 names the actions, not Undo's live text
    _focus3d(win, qtbot)
    _keys(qtbot, "F1", until=lambda: win.presenter.shortcuts_dialog is not None)
    names = [r[1] for r in win.presenter.shortcuts_dialog.rows()]
    assert "Undo" in names and not any(t.startswith("Undo ") for t in names)
    win.presenter.shortcuts_dialog.close()
    # the layers in words
    texts = [a.text() for a in host.layer_actions.values()]
    assert "Show the binocular field" in texts and not any("bfv" in t for t in texts)
    # disabled entries look disabled in presentation mode
    _focus3d(win, qtbot)
    _keys(qtbot, "F5", until=lambda: win.presenter.presenting)
    pal = QtWidgets.QApplication.palette()
    assert pal.color(QtGui.QPalette.Disabled, QtGui.QPalette.ButtonText) != pal.color(
        QtGui.QPalette.Active, QtGui.QPalette.ButtonText
    )
    _keys(qtbot, "F5", until=lambda: not win.presenter.presenting)
    # item 7: Help > About the model opens at the spherical model
    dlg = win.presenter.show_about()
    qtbot.waitUntil(dlg.isVisible, timeout=3000)

    def heading_shown() -> bool:
        cur = dlg.browser.document().find(SPHERICAL_SECTION)
        return not cur.isNull() and dlg.browser.viewport().rect().contains(
            dlg.browser.cursorRect(cur).center()
        )

    qtbot.waitUntil(heading_shown, timeout=3000)
    assert "HEALPix" in dlg.browser.toPlainText() and "tangent cone" in dlg.browser.toPlainText()
    dlg.close()


def test_planar_lecture_steps_frame_the_eyes_and_their_feature(make_window, qtbot):
    path = scene_path("lecture")
    win = make_window(load(path), path)
    _focus(win, qtbot)
    _keys(qtbot, "F5", until=lambda: win.presenter.presenting)
    for i in (1, 2, 3):
        _keys(qtbot, "Next", until=lambda i=i: win.step_index == i) if i > 1 else _keys(
            qtbot, "Next", "Next", until=lambda: win.step_index == 1
        )
        qtbot.wait(200)
        sc = win.model.scene
        w, h = win.plotter.width(), win.plotter.height()
        e = sc.eyes
        pts = [(-e.h, -e.l), (e.h, -e.l)] + [(f.x, f.y + f.g) for f in sc.features]
        for x, y in pts:
            px, py = win.to_pixel(x, y)
            assert 0 <= px <= w and win.title_band_px() <= py <= h, (i, x, y, px, py)


def test_a_window_the_screen_size_keeps_its_status_bar_on_screen(make_window, qtbot):
    win = make_window(_scene(), None)
    screen = win.screen().availableGeometry()
    win.resize(screen.width(), screen.height())
    qtbot.wait(200)
    win.fit_screen()
    qtbot.waitUntil(lambda: win.frameGeometry().height() <= screen.height(), timeout=3000)
    bar = win.statusBar()

    def bottom() -> int:  # the window manager moves the window after its frame is known
        return bar.mapToGlobal(QtCore.QPoint(0, bar.height())).y()

    qtbot.waitUntil(lambda: bottom() <= screen.bottom() + 1, timeout=3000)
