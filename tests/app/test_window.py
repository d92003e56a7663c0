"""The app on a real window: drags with mouse events, parameters, files, undo, screenshot."""

import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from mouse import drag, move, pixel_of
from PyQt5 import QtCore, QtGui
from PyQt5.QtTest import QTest

from eyeviz.app.window import qimage_to_array
from eyeviz.core.geometry import EyePair
from eyeviz.model.app_model import DRAG_THRESHOLD_PX
from eyeviz.model.scene import Eyes, Feature, Scene, View, load
from eyeviz.render.vtk.style import UNLIT, hex_rgb

ROOT = Path(__file__).resolve().parents[2]


def two_features(m=720):
    return Scene(
        Eyes(40.0, 20.0, m),
        [
            Feature("target", 0.0, 1500.0, 50.0, "#D55E00"),
            Feature("other", -1200.0, 3000.0, 200.0, "#0072B2"),
        ],
        ["eyes", "bfv", "features", "bitmaps", "readout", "labels"],
        view=View((0.0, 2300.0), 7000.0),
    )


def expected_owner(scene, eye):
    pair = scene.eyes.pair()
    fs = scene.features
    wa, wb = pair.bitmaps([f.x for f in fs], [f.y for f in fs], [f.g for f in fs])
    bits = wa if eye == "A" else wb
    owner = np.full(pair.m, -1)
    for i in range(len(fs)):
        owner[bits[i]] = i
    return owner, bits


def check_lit(win):
    """Eye meshes and bitmap panel equal EyePair.bitmaps of the scene's features."""
    sc = win.model.scene
    palette = np.vstack([UNLIT] + [hex_rgb(f.color) for f in sc.features])
    m = sc.eyes.m
    for k, eye in enumerate("AB"):
        owner, bits = expected_owner(sc, eye)
        np.testing.assert_array_equal(win.actors.eye_meshes[k].cell_data["rgb"], palette[owner + 1])
        np.testing.assert_array_equal(win.bitmaps.lit(eye, True), bits.any(axis=0))
        np.testing.assert_array_equal(win.bitmaps.lit(eye, False), bits.any(axis=0)[: m // 2])
        np.testing.assert_array_equal(win.bitmaps.strips[(eye, True)], owner)


def test_drag_moves_feature_lights_ommatidia_and_undo_restores(make_window):
    win = make_window(two_features())
    check_lit(win)
    before = win.model.scene.copy()
    lit_before = win.actors.eye_meshes[0].cell_data["rgb"].copy()
    start = pixel_of(win, 0.0, 1500.0)
    end = pixel_of(win, -700.0, 2500.0)
    drag(win, start, end)
    f = win.model.scene.features[0]
    u = win.units_per_px()
    assert abs(f.x - -700.0) <= 2 * u and abs(f.y - 2500.0) <= 2 * u
    assert f.g == 50.0 and win.model.scene.features[1] == before.features[1]
    check_lit(win)
    assert not np.array_equal(win.actors.eye_meshes[0].cell_data["rgb"], lit_before)
    # one drag is one undo step
    assert win.undo_stack.count() == 1
    win.undo_stack.undo()
    assert win.model.scene.features == before.features
    np.testing.assert_array_equal(win.actors.eye_meshes[0].cell_data["rgb"], lit_before)
    check_lit(win)
    win.undo_stack.redo()
    assert win.model.scene.features[0].x == f.x
    check_lit(win)


def test_click_selects_without_an_undo_step(make_window):
    win = make_window(two_features())
    p = pixel_of(win, -1200.0, 3000.0)
    small = QtCore.QPoint(int(DRAG_THRESHOLD_PX) - 2, 0)
    drag(win, p, p + small, steps=2)
    assert win.model.selected == 1
    assert win.undo_stack.count() == 0
    assert win.model.scene.features[1].x == -1200.0


def wheel_at(win, pos, notches=1, modifiers=QtCore.Qt.NoModifier):
    for _ in range(notches):
        ev = QtGui.QWheelEvent(
            QtCore.QPointF(pos),
            QtCore.QPointF(win.plotter.mapToGlobal(pos)),
            QtCore.QPoint(),
            QtCore.QPoint(0, 120),
            QtCore.Qt.NoButton,
            modifiers,
            QtCore.Qt.NoScrollPhase,
            False,
        )
        QtCore.QCoreApplication.sendEvent(win.plotter, ev)


def test_drag_on_handle_changes_radius_and_ctrl_wheel_too(make_window):
    win = make_window(two_features())
    win.model.select(1)
    start = pixel_of(win, -1200.0 + 200.0, 3000.0)
    end = pixel_of(win, -1200.0 + 500.0, 3000.0)
    drag(win, start, end)
    f = win.model.scene.features[1]
    assert abs(f.g - 500.0) <= 2 * win.units_per_px() and (f.x, f.y) == (-1200.0, 3000.0)
    g = f.g
    pos = pixel_of(win, -1200.0, 3000.0)
    wheel_at(win, pos, 3, QtCore.Qt.ControlModifier)
    assert win.model.scene.features[1].g == pytest.approx(g * 1.08**3)
    assert win.undo_stack.count() == 2  # the drag, then the three wheel steps merged
    check_lit(win)


def test_changing_m_rebuilds_the_eyes(make_window, qtbot):
    win = make_window(two_features())
    edit = win.eyes_panel.edits["m"]
    edit.setText("36")
    QTest.keyClick(edit, QtCore.Qt.Key_Return)  # Enter applies h, l, m together
    assert win.model.scene.eyes.m == 36
    assert [mesh.n_cells for mesh in win.actors.eye_meshes] == [36, 36]
    check_lit(win)
    win.undo_stack.undo()
    assert [mesh.n_cells for mesh in win.actors.eye_meshes] == [720, 720]


@pytest.mark.parametrize(
    "key, text, words",
    [
        ("m", "7", "even integer"),
        ("m", "2", "even integer"),
        ("m", "7.5", "even integer"),
        ("h", "10", "h must be > l"),
        ("h", "20", "h must be > l"),  # h = l: the eyes would touch the y-axis
        ("l", "-1", "l"),
        ("l", "0", "l"),
        ("h", "nan", "h"),
        ("l", "inf", "l"),
        ("m", "1048578", "<= 1048576, got 1048578"),
        ("h", "abc", "number"),
        ("m", "", "even integer"),
    ],
)
def test_forbidden_parameter_is_refused(make_window, key, text, words):
    win = make_window(two_features())
    before = win.model.scene.copy()
    edit = win.eyes_panel.edits[key]
    edit.setText(text)
    QTest.keyClick(edit, QtCore.Qt.Key_Return)
    assert win.model.scene == before
    msg = win.eyes_panel.message.text()
    assert words in msg and msg.startswith("Refused") and "\n" not in msg, msg
    assert "h = 40, l = 20, m = 720" in msg  # what the scene keeps
    assert edit.text() == text  # what was typed stays, to be fixed (never clamped)
    assert win.undo_stack.count() == 0
    assert [mesh.n_cells for mesh in win.actors.eye_meshes] == [720, 720]


def test_invalid_scene_file_shows_a_dialog_and_keeps_the_scene(make_window, tmp_path):
    win = make_window(two_features())
    before = win.model.scene.copy()
    bad = tmp_path / "bad.toml"
    bad.write_text("[eyes]\nh = 40.0\nl = 20.0\nm = 7\n")
    assert win.open_path(bad) is False
    assert win.model.scene == before
    assert win.error_box is not None and win.error_box.isVisible()
    assert "bad.toml:4" in win.error_box.text() and "even integer" in win.error_box.text()
    win.error_box.close()


def test_save_load_round_trip_and_recent_files(make_window, tmp_path):
    win = make_window(two_features())
    win.model.add_feature(300.0, 2000.0, 80.0)
    win.model.set_feature(0, name="renamed", x=12.5)
    out = tmp_path / "saved.toml"
    assert win.save_path(out)
    assert load(out) == win.model.scene
    assert win.undo_stack.isClean() and "saved.toml" in win.windowTitle()
    win2 = make_window(Scene())
    assert win2.open_path(out)
    assert win2.model.scene == win.model.scene
    assert win2.recent_files()[0] == str(out.resolve())


def test_feature_table_edit_and_bad_value(make_window):
    win = make_window(two_features())
    table = win.features_panel.table
    table.item(0, 3).setText("75")
    assert win.model.scene.features[0].g == 75.0
    check_lit(win)
    before = win.model.scene.copy()
    table.item(0, 3).setText("-5")
    assert win.model.scene == before
    assert "g (feature radius) must be > 0" in win.features_panel.message.text()
    assert table.item(0, 3).text() == "75"
    table.item(0, 3).setText("80")  # a success clears the old refusal (issue 12 item 11)
    assert win.model.scene.features[0].g == 80.0
    assert win.features_panel.message.text() == ""


def test_add_duplicate_delete(make_window):
    win = make_window(two_features())
    menu = win._context_menu(pixel_of(win, 0.0, 1500.0), QtCore.QPoint(0, 0))
    texts = [a.text() for a in menu.actions()]
    assert texts[1:] == ["Duplicate target", "Delete target"]
    menu.actions()[1].trigger()
    menu.close()
    assert len(win.model.scene.features) == 3 and win.model.selected == 2
    win.delete_selected()
    win.delete_selected()
    assert [f.name for f in win.model.scene.features] == ["target"]
    check_lit(win)


@pytest.mark.slow
def test_screenshot_is_not_blank_and_shows_the_lit_colour(make_window, tmp_path):
    sc = load(ROOT / "assets" / "scenes" / "figure3b.toml")
    win = make_window(sc)
    out = win.save_screenshot(tmp_path / "shot.png")
    img = qimage_to_array(QtGui.QImage(str(out)))
    assert img.shape[0] >= 600 and img.std() > 20
    assert len(np.unique(img.reshape(-1, 3), axis=0)) > 50
    # the eyes are large on screen here: no inset duplicating them, the main view names them
    assert not win.inset_shown and not win.inset_ren.GetDraw()
    labels = win.actors.labels.main_eye_labels
    assert labels and all(t.GetVisibility() for t in labels)
    # the lit ommatidia of eye B (1..3) drawn in the feature's colour in the main view
    f = sc.features[0]
    col = np.array(hex_rgb(f.color))
    pair = EyePair(sc.eyes.h, sc.eyes.l, sc.eyes.m)
    top = win.plotter.mapTo(win, QtCore.QPoint(0, 0))
    for k in (1, 2, 3):
        a = (k + 0.5) * pair.gamma
        x, y = pair.h + 0.6 * pair.l * math.cos(a), 0.6 * pair.l * math.sin(a)
        px, py = win.to_pixel(x, y, "main")
        rgb = img[int(py) + top.y(), int(px) + top.x()]
        assert np.abs(rgb.astype(int) - col).max() <= 12, (k, rgb)
    a = 8.5 * pair.gamma  # an unlit ommatidium
    px, py = win.to_pixel(pair.h + 0.6 * pair.l * math.cos(a), 0.6 * pair.l * math.sin(a), "main")
    assert np.abs(img[int(py) + top.y(), int(px) + top.x()].astype(int) - UNLIT).max() <= 12


@pytest.mark.slow
def test_app_does_not_import_torch(tmp_path):
    code = (
        "import sys\n"
        "from eyeviz.app.window import MainWindow, make_app, make_settings\n"
        "from eyeviz.model.scene import load\n"
        "app = make_app()\n"
        f"w = MainWindow(load({str(ROOT / 'assets/scenes/default.toml')!r}), "
        f"settings=make_settings({str(tmp_path / 's.ini')!r}))\n"
        "w.show(); app.processEvents(); w.render()\n"
        "print('torch' in sys.modules)\n"
    )
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert r.returncode == 0, r.stderr
    assert r.stdout.strip().splitlines()[-1] == "False"


@pytest.mark.slow
def test_spherical_window_loads_nothing_its_first_frame_does_not_need(tmp_path):
    # issue 32.14: numba (the kernels' warm-up thread), scipy and the data-set package
    # were loaded while the window built its first frame; the kernels now load after it
    # (a screenshot never needs them), scipy.special and eyeviz.dataset when first used
    code = (
        "import sys\n"
        "from eyeviz.app.main import run_app\n"
        f"run_app({str(ROOT / 'assets/scenes/sphere_lecture.toml')!r}, "
        f"{str(tmp_path / 'w.png')!r}, {str(tmp_path / 's.ini')!r})\n"
        "loaded = [m for m in ('numba', 'scipy', 'eyeviz.dataset') if m in sys.modules]\n"
        "print('loaded:', *loaded)\n"
    )
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    assert (tmp_path / "w.png").stat().st_size > 10_000
    assert r.stdout.strip().splitlines()[-1] == "loaded:"


@pytest.mark.slow
def test_cli_screenshot(tmp_path):
    out = tmp_path / "cli.png"
    r = subprocess.run(
        [
            sys.executable,
            "-m",
            "eyeviz",
            "app",
            str(ROOT / "assets/scenes/figure5.toml"),
            "--screenshot",
            str(out),
            "--settings",
            str(tmp_path / "s.ini"),
        ],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert r.returncode == 0, r.stderr
    assert out.stat().st_size > 10_000 and str(out) in r.stdout
    bad = tmp_path / "bad.toml"
    bad.write_text("[eyes]\nm = 3\n")
    r = subprocess.run(
        [sys.executable, "-m", "eyeviz", "app", str(bad)],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert r.returncode == 2 and "eyes.m" in r.stderr and "Traceback" not in r.stderr


def test_inset_shows_tiny_eyes_in_a_corner_and_hides_for_large_ones(make_window):
    win = make_window(load(ROOT / "assets" / "scenes" / "default.toml"))
    assert win.inset_shown and win.inset_ren.GetDraw()
    left, top, w, h = win._viewport_px("inset")
    assert left == 0 and top + h == pytest.approx(win.plotter.height())
    assert w * h <= 0.25 * win.plotter.width() * win.plotter.height()
    assert win.to_model(left + w / 2, top + h / 2)[0] == "inset"
    win.model.scene.view = View((0.0, 0.0), 300.0)  # zoomed onto the eyes
    win.apply_cameras()
    assert not win.inset_shown and win.to_model(left + w / 2, top + h / 2)[0] == "main"


@pytest.mark.slow
def test_dragged_disc_is_drawn_at_its_new_place_during_and_after_the_drag(make_window):
    """The selected disc is a separate actor moved by its transform: it must follow."""
    win = make_window(two_features())
    w = win.plotter
    start, end = pixel_of(win, -1200.0, 3000.0), pixel_of(win, -400.0, 2500.0)
    tint = np.round(0.4 * np.array(hex_rgb("#0072B2")) + 0.6 * 255)
    top = w.mapTo(win, QtCore.QPoint(0, 0))

    def fill_at(x, y):
        win.flush()
        win.render()
        img = qimage_to_array(win.grab_image())
        px, py = win.to_pixel(x, y, "main")
        return np.abs(img[int(py) + top.y(), int(px) + top.x()].astype(int) - tint).max() <= 12

    QTest.mousePress(w, QtCore.Qt.LeftButton, QtCore.Qt.NoModifier, start)
    for k in range(1, 13):
        move(w, start + (end - start) * (k / 12))
    for _ in ("during the drag", "after the release"):
        f = win.model.scene.features[1]
        assert win.model.selected == 1 and f.g == 200.0 and abs(f.x + 400.0) < 30
        win.flush()  # the moves are coalesced into the next frame
        x0, x1, y0, y1, _, _ = win.actors.live_fill.GetBounds()
        assert win.actors.live_fill.GetVisibility()
        np.testing.assert_allclose([x0, x1, y0, y1], [f.x - 200, f.x + 200, f.y - 200, f.y + 200])
        assert fill_at(f.x + 120.0, f.y) and fill_at(f.x, f.y - 120.0)
        assert not fill_at(-1200.0 - 120.0, 3000.0)  # nothing left at the old place
        QTest.mouseRelease(w, QtCore.Qt.LeftButton, QtCore.Qt.NoModifier, end)
    assert win.undo_stack.count() == 1
