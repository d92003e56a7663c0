"""The 3D view's predictions layer in a real window (issue 23 item 4): the layer toggled
from the 3D view menu, ghost actors at the estimators' answers (VTK's own projection of
them checked against eyeviz.model.camera3d and the pixels), the readout's rows with
errors, the Estimators dock, a real X drag (xdotool) after which the limit's ghost
follows, the tables fit 1280x720, File > Export draws the ghosts."""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import matplotlib.image as mpimg
import numpy as np
import pytest
from PyQt5 import QtCore

from eyeviz.model import predictions3d as p3
from eyeviz.model.scene import Eyes, load
from eyeviz.render.vtk.style import hex_rgb

SCENES = Path(__file__).resolve().parents[2] / "assets" / "scenes"


def _scene(on: bool):
    sc = load(SCENES / "sphere_predictions.toml")
    if not on:
        sc.layers.remove("predictions")
    return sc


def _xdo(qtbot, *args):
    subprocess.run(["xdotool", *map(str, args)], check=True)
    qtbot.wait(40)


def _vtk_pixel(host, point) -> tuple[float, float]:
    """Widget pixel of a model point through VTK's own camera (vtkCoordinate)."""
    import vtk

    c = vtk.vtkCoordinate()
    c.SetCoordinateSystemToWorld()
    c.SetValue(*point)
    dx, dy = c.GetComputedDoubleDisplayValue(host.actors.scene_ren)
    h = host.view.ren_win.GetSize()[1]
    return dx, h - dy


def _limit_done(win):
    host = win.host3d
    win.jobs.wait()
    a = host.preds.answers.get("limit3d") if host.preds is not None else None
    return isinstance(a, p3.Answer3D)


def test_toggle_the_layer_and_the_ghosts_are_at_the_answers(make_window, qtbot):
    win = make_window(_scene(False))
    host = win.host3d
    assert not host.model.scene.shows("predictions")
    assert not host.estimators.isEnabled()  # greyed until the layer is on
    assert host.actors.ghosts is None or not host.actors.ghosts.centres
    host.layer_actions["predictions"].trigger()  # 3D view > Show predictions
    assert host.model.scene.shows("predictions") and win.undo_stack.count() == 1
    assert host.estimators.isEnabled()
    qtbot.waitUntil(lambda: _limit_done(win), timeout=20000)
    preds = host.preds
    assert preds is not None and preds.ball == host.model.selected == 0
    g = host.actors.ghosts
    assert g is not None and set(g.centres) == {"analytic3d", "learned3d", "limit3d"}
    for a in preds.ghosts():
        assert g.centres[a.name] == (a.x, a.y, a.z)
        # where VTK draws the ghost's centre is where the model's camera projects it
        vx, vy = _vtk_pixel(host, (a.x, a.y, a.z))
        mx, my = host.scene_pixel((a.x, a.y, a.z))
        assert abs(vx - mx) < 1.0 and abs(vy - my) < 1.0
    # analytic3d's answer lies apart: its centre dot is there, in its colour
    a = preds.answers["analytic3d"]
    assert isinstance(a, p3.Answer3D)
    cam = host.camera()  # zoomed on the ball (at the default framing it is ~50 px wide)
    c0, pos = np.array([a.x, a.y, a.z]), np.asarray(cam.position)
    back = (pos - c0) / np.linalg.norm(pos - c0)
    host.set_camera(type(cam)(tuple(c0 + 8 * preds.g * back), tuple(c0), cam.view_up,
                              cam.view_angle))  # fmt: skip
    qtbot.wait(50)
    img = win.grab_image()  # the window, the VTK view from its framebuffer
    vx, vy = (round(v) for v in host.scene_pixel((a.x, a.y, a.z)))
    at = host.view.mapTo(win, QtCore.QPoint(vx, vy))
    x, y = at.x(), at.y()
    want = np.array(hex_rgb(p3.estimator_color3d("analytic3d")))
    near = []
    for dx in range(-2, 3):
        for dy in range(-2, 3):
            c = img.pixelColor(x + dx, y + dy)
            near.append(np.abs(np.array([c.red(), c.green(), c.blue()]) - want).sum())
    assert min(near) < 60
    # the readout: a column per estimator, with the errors against the true ball
    ro = host.readout
    assert ro.pred_table.isVisible()
    assert ro.pred_text("analytic3d", "r") == f"{a.r:.0f} ({a.dr_pct:+.2f} %)"
    assert ro.pred_text("analytic3d", "el") == f"{np.degrees(a.elevation):.2f} ({a.del_:+.3f})"
    note = {r[0]: r[-1] for r in p3.prediction_rows(preds)}["limit3d"]
    assert note.startswith("MC ±") or note.endswith("draw: MC n/a")
    assert ro.pred_text("limit3d", "note") == note
    # hidden again: no ghost, no table, the dock greyed
    host.layer_actions["predictions"].trigger()
    assert not any(gh.ball.GetVisibility() for gh in g.ghosts.values())
    assert not ro.pred_table.isVisible() and not host.estimators.isEnabled()


def test_the_estimators_dock_chooses_the_ghosts(make_window, qtbot):
    win = make_window(_scene(True))
    host = win.host3d
    qtbot.waitUntil(lambda: _limit_done(win), timeout=20000)
    box = host.estimators.boxes["learned3d"]
    assert box.isChecked()
    box.click()
    assert host.model.scene.estimators == ["analytic3d", "limit3d"]
    assert "learned3d" not in host.actors.ghosts.centres
    assert set(host.preds.answers) == {"analytic3d", "limit3d"}
    for name in ("analytic3d", "limit3d"):  # the last one stays ticked
        host.estimators.boxes[name].click()
    assert host.model.scene.estimators == ["limit3d"]
    assert host.estimators.boxes["limit3d"].isChecked()
    win.undo_stack.undo()
    assert host.model.scene.estimators == ["analytic3d", "limit3d"]


def test_a_real_drag_then_the_limit_follows(make_window, qtbot):
    if shutil.which("xdotool") is None:
        pytest.fail("xdotool is needed for this test: apt-get install xdotool")
    win = make_window(_scene(True))
    win.activateWindow()
    win.raise_()
    host = win.host3d
    host.set_preset("front")
    qtbot.waitUntil(lambda: _limit_done(win), timeout=20000)
    before = host.preds.answers["limit3d"]
    jobs0 = host.limit_jobs
    f = host.model.scene.features[0]
    x, y = _vtk_pixel(host, (f.x, f.y, f.z))
    p = host.view.mapToGlobal(QtCore.QPoint(round(x), round(y)))
    seen_mid: list = []
    _xdo(qtbot, "mousemove", p.x(), p.y())
    _xdo(qtbot, "mousedown", 1)
    for k in range(1, 7):
        _xdo(qtbot, "mousemove", p.x() + 5 * k, p.y() + 3 * k)
        qtbot.wait(30)
        if host.model.live_open and host.preds is not None:
            shown = bool(host.actors.ghosts.ghosts["limit3d"].ball.GetVisibility())
            seen_mid.append(
                (host.preds.answers.get("limit3d"), host.preds.answers.get("analytic3d"), shown)
            )
    _xdo(qtbot, "mouseup", 1)
    qtbot.waitUntil(lambda: win.undo_stack.count() == 1, timeout=5000)
    # during the drag the fast ones answered every frame, the limit waited for the end
    assert seen_mid and all(lim == "after the drag" for lim, _, _ in seen_mid)
    assert all(isinstance(an, p3.Answer3D) for _, an, _ in seen_mid)
    assert not any(shown for _, _, shown in seen_mid)  # no stale limit ghost in the drag
    qtbot.waitUntil(lambda: _limit_done(win), timeout=20000)
    after = host.preds.answers["limit3d"]
    st = host.model.state
    key = p3.ball_key(st, 0)
    want = host.predictor3d.cached("limit3d", key)
    assert want is not None  # the answer drawn is the moved ball's key's
    assert (after.x, after.y, after.z) != (before.x, before.y, before.z)
    assert host.actors.ghosts.centres["limit3d"] == (after.x, after.y, after.z)
    assert host.actors.ghosts.ghosts["limit3d"].ball.GetVisibility()
    assert host.limit_jobs - jobs0 <= 2  # one job after the drag, none per frame


def test_the_tables_fit_1280x720_without_a_horizontal_scroll_bar(make_window, qtbot):
    win = make_window(_scene(True))
    win.resize(1280, 720)
    qtbot.waitUntil(lambda: _limit_done(win), timeout=20000)
    qtbot.wait(100)
    host = win.host3d
    host.refresh_panels()
    qtbot.wait(50)
    assert win.height() <= 720  # the docks' minimum heights fit a 720-line projector
    names = host.readout.table
    for f in host.model.scene.features:  # short names are not elided
        room = names.horizontalHeader().sectionSize(0) - names.iconSize().width() - 8
        assert names.fontMetrics().horizontalAdvance(f.name) <= room, f.name
    for t in (host.readout.table, host.readout.pred_table):
        assert t.isVisible()
        bar = t.horizontalScrollBar()
        assert bar is not None and not bar.isVisible() and bar.maximum() == 0
        head = t.horizontalHeader()
        total = sum(head.sectionSize(j) for j in range(t.columnCount()))
        assert total <= t.viewport().width() + 1
        for j in range(1, t.columnCount()):  # every number whole (only names elide)
            fm = t.fontMetrics()
            for i in range(t.rowCount()):
                item = t.item(i, j)
                if item is not None and item.text():
                    assert fm.horizontalAdvance(item.text()) <= head.sectionSize(j)


def test_export_draws_the_ghosts(make_window, qtbot, tmp_path):
    win = make_window(_scene(True))
    qtbot.waitUntil(lambda: _limit_done(win), timeout=20000)
    svg = win.export_to(tmp_path / "p.svg")
    text = Path(svg).read_text()
    for name in ("analytic3d", "learned3d", "limit3d"):
        assert f'id="ghost-{name}' in text
    assert 'id="posterior-cloud' in text
    png = win.export_to(tmp_path / "p.png", scale=0.5)
    img = (mpimg.imread(png)[..., :3] * 255).round().astype(int)
    want = np.array(hex_rgb(p3.estimator_color3d("analytic3d")))
    top = img.shape[0] // 3  # the 3D view (the maps and the tables below it)
    close = np.abs(img[:top] - want).sum(axis=-1) < 40
    assert close.sum() > 10  # the indigo outline of analytic3d's ghost (no ball is indigo)
    off = _scene(False)
    win.host3d.model.set_scene(off)
    png2 = win.export_to(tmp_path / "q.png", scale=0.5)
    img2 = (mpimg.imread(png2)[..., :3] * 255).round().astype(int)
    assert (np.abs(img2[:top] - want).sum(axis=-1) < 40).sum() < close.sum() / 5


def test_an_estimator_for_other_eyes_is_greyed_with_its_line(make_window, qtbot):
    sc = _scene(True)
    sc.eyes = Eyes(sc.eyes.h, sc.eyes.l, nside=16)  # learned3d's weights: nside 180
    win = make_window(sc)
    host = win.host3d
    qtbot.waitUntil(lambda: _limit_done(win), timeout=20000)
    host.refresh_panels()
    box = host.estimators.boxes["learned3d"]
    assert box.isChecked() and "8a8a8a" in box.styleSheet()
    assert "nside=180" in host.estimators.note.text() and host.estimators.note.isVisible()
    assert "learned3d" not in host.actors.ghosts.centres  # no ghost for the wrong eyes
    assert host.readout.pred_text("learned3d", "r") == ""
    assert host.readout.pred_text("learned3d", "note").startswith("unavailable: ")
    t = host.readout.pred_table
    head = t.horizontalHeader()
    assert sum(head.sectionSize(j) for j in range(t.columnCount())) <= t.viewport().width() + 1
    assert host.estimators.boxes["analytic3d"].styleSheet() == ""


def test_opening_a_scene_naming_an_unknown_estimator_is_refused(make_window, qtbot, tmp_path):
    win = make_window(_scene(False))
    host = win.host3d
    before = host.model.scene
    text = (SCENES / "sphere_predictions.toml").read_text()
    bad = tmp_path / "bad.toml"
    bad.write_text(text.replace('estimators = ["analytic3d", "learned3d", "limit3d"]',
                                'estimators = ["nonsense"]'))  # fmt: skip
    assert not win.open_path(bad)  # File > Open: one line, the open scene kept
    assert win.last_error.startswith("predictions.estimators: unknown estimator 'nonsense'")
    assert "\n" not in win.last_error
    assert host.model.scene is before and win.path != bad
    win.error_box.close()


def test_the_default_framing_keeps_the_balls_names_inside_the_view(make_window, qtbot):
    from eyeviz.render.vtk.scene3d import LABEL_MARGIN_PX, default_camera

    win = make_window(_scene(True))
    win.resize(1280, 720)
    qtbot.wait(50)
    host = win.host3d
    host.set_preset("default")
    vp = host.pointer("move", 0, 0)
    host.draw()
    boxes = host.actors.name_boxes  # where the names were placed (scene viewport px, y up)
    assert len(boxes) == 3
    for bx0, by0, bx1, by1 in boxes:  # "high" was cut at the view's right edge
        assert bx0 >= LABEL_MARGIN_PX - 0.5 and bx1 <= vp.w - LABEL_MARGIN_PX + 0.5
        assert by0 >= LABEL_MARGIN_PX - 0.5 and by1 <= vp.h - LABEL_MARGIN_PX + 0.5
    # the preset's direction and focal point are kept: only moved back along the sight
    cam, pre = host.camera(), default_camera(host.model.state, "default", vp.w / vp.h)
    d = np.subtract(cam.position, cam.focal_point)
    d0 = np.subtract(pre.position, pre.focal_point)
    assert np.allclose(cam.focal_point, pre.focal_point)
    assert np.allclose(d / np.linalg.norm(d), d0 / np.linalg.norm(d0))
    assert np.linalg.norm(d0) <= np.linalg.norm(d) <= 2.0 * np.linalg.norm(d0)
