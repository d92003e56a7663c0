"""Presenting with eyeviz (issue 24) through the X server, as a lecturer meets it: real key
presses (xdotool's XTEST) into the real window under a small window manager (openbox; a
bare Xvfb has none, and full screen is the window manager's job)."""

import json
import shutil
import subprocess
import tempfile
from pathlib import Path

import pytest
from mouse import x_focus
from PyQt5 import QtCore, QtGui, QtWidgets
from real_x import start_window_manager, stop_window_manager

from eyeviz.app.launch import APP_FONT_PT
from eyeviz.app.presenting import PRESENT_FACTOR, SCALE_KEY
from eyeviz.model.scene import Eyes, Feature, Scene, View, load
from eyeviz.render.vtk.scene3d import LABEL_PX
from eyeviz.resources import scene_path


@pytest.fixture(scope="module", autouse=True)
def window_manager():
    """openbox on this test's display, for the module; its --startup command says when it
    is ready. A window manager already running (a desktop) is used as it is."""
    if shutil.which("openbox") is None:
        pytest.fail("openbox is needed for these tests: apt-get install openbox (scripts/setup.sh)")
    if shutil.which("xdotool") is None:
        pytest.fail("xdotool is needed for these tests: apt-get install xdotool")
    with tempfile.TemporaryDirectory() as tmp:
        proc = start_window_manager(Path(tmp))  # None: another one runs (then it is used)
        yield
        stop_window_manager(proc)


def _scene():
    return Scene(
        Eyes(40.0, 20.0, 720),
        [Feature("target", 0.0, 1500.0, 50.0, "#D55E00")],
        ["eyes", "bfv", "features", "bitmaps", "readout", "labels"],
        view=View((0.0, 2300.0), 7000.0),
        title="Lecture",
    )


def _focus(win, qtbot):
    x_focus(win, win.plotter)


def _keys(qtbot, *keys: str, until=lambda: True) -> None:
    """Real key presses, one xdotool call each, then wait for ``until``."""
    for k in keys:
        subprocess.run(["xdotool", "key", "--delay", "40", k], check=True)
        qtbot.wait(60)
    qtbot.waitUntil(until, timeout=5000)


def _screen_size(win):
    screen = win.screen() or QtWidgets.QApplication.primaryScreen()
    return screen.geometry().size()


def test_f11_fills_the_screen_under_a_window_manager_and_f11_again_restores(make_window, qtbot):
    win = make_window(_scene())
    win.resize(1280, 720)
    qtbot.waitUntil(lambda: win.width() == 1280, timeout=3000)
    assert win.frameGeometry() != win.geometry()  # decorated: a window manager runs
    _focus(win, qtbot)
    full = _screen_size(win)
    _keys(qtbot, "F11", until=lambda: win.isFullScreen() and win.size() == full)
    assert win.presenter.fullscreen_action.isChecked()
    assert win.geometry().topLeft() == win.screen().geometry().topLeft()
    _focus(win, qtbot)
    _keys(qtbot, "F11", until=lambda: not win.isFullScreen() and win.width() == 1280)
    assert not win.presenter.fullscreen_action.isChecked()
    assert win.size().height() == 720


def test_view_full_screen_is_in_the_menu_with_its_key(make_window):
    win = make_window(_scene())
    view = next(a.menu() for a in win.menuBar().actions() if a.text() == "&View")
    texts = {a.text().replace("&", ""): a for a in view.actions()}
    assert texts["Full screen"].shortcut().toString() == "F11"


def test_f1_lists_the_shortcuts_read_from_the_actions(make_window, qtbot):
    win = make_window(_scene())
    _focus(win, qtbot)
    _keys(qtbot, "F1", until=lambda: win.presenter.shortcuts_dialog is not None)
    dlg = win.presenter.shortcuts_dialog
    qtbot.waitUntil(dlg.isVisible, timeout=3000)
    rows = dlg.rows()
    keys = {(r[1], r[2]) for r in rows}
    for name, key in [
        ("Full screen", "F11"),
        ("Keyboard shortcuts", "F1"),
        ("Presentation mode", "F5"),
        ("Next step", "PgDown"),
        ("Fit view", "F"),
        ("Save", "Ctrl+S"),
    ]:
        assert (name, key) in keys, (name, key, sorted(keys))
    # every action of the window with a key has its row (the table is made from them)
    for a in win.actions():
        if a.shortcut().toString():
            shown = a.shortcuts()[0].toString(QtGui.QKeySequence.NativeText)
            assert any(shown in r[2] for r in rows), a.text()
    # never stale: a changed key shows the next time
    fit = next(a for a in win.actions() if a.text() == "&Fit view")
    fit.setShortcut(QtGui.QKeySequence("G"))
    dlg.close()
    _focus(win, qtbot)
    _keys(qtbot, "F1", until=dlg.isVisible)
    assert ("Fit view", "G") in {(r[1], r[2]) for r in dlg.rows()}


def test_help_about_the_model_shows_the_model_page(make_window, qtbot):
    win = make_window(_scene())
    _focus(win, qtbot)
    _keys(qtbot, "alt+h", "a", until=lambda: win.presenter.about_dialog is not None)
    dlg = win.presenter.about_dialog
    qtbot.waitUntil(dlg.isVisible, timeout=3000)
    text = dlg.browser.toPlainText()
    for part in ["Definition 1", "Definition 2", "Figure 2", "Figure 5", "Figure 6"]:
        assert part in text, part
    for k in range(1, 5):
        assert f"Proposition {k}" in text
    assert "θ = π − 2ψ" in text and "ψ = arcsin(l / h)" in text


def test_view_panels_lists_every_dock_and_brings_a_closed_one_back(make_window, qtbot):
    win = make_window(_scene())
    design = win.show_design()  # a dock made later is listed too
    design.wait()
    qtbot.waitUntil(lambda: design.running is None, timeout=30000)
    eyes = win.findChild(QtWidgets.QDockWidget, "dock_eyes")
    eyes.close()
    qtbot.waitUntil(lambda: not eyes.isVisible(), timeout=2000)
    menu = win.presenter.panels_menu
    win.presenter.fill_panels_menu()
    titles = [a.text() for a in menu.actions()]
    docks = win.findChildren(QtWidgets.QDockWidget)
    assert sorted(d.windowTitle() for d in docks) == titles
    assert "Eye design" in titles
    _focus(win, qtbot)
    # View > Panels from the keyboard (mnemonics), then a real click on "Eyes"
    _keys(qtbot, "alt+v", "n", until=menu.isVisible)
    item = next(a for a in menu.actions() if a.text() == "Eyes")
    spot = menu.mapToGlobal(menu.actionGeometry(item).center())
    subprocess.run(["xdotool", "mousemove", "--sync", str(spot.x()), str(spot.y())], check=True)
    subprocess.run(["xdotool", "click", "1"], check=True)
    qtbot.waitUntil(eyes.isVisible, timeout=5000)
    assert eyes.toggleViewAction().isChecked()


def _text_sizes(win):
    return (
        QtWidgets.QApplication.font().pointSizeF(),
        win.title_actor.GetTextProperty().GetFontSize(),
        win.readout.title.font().pointSizeF(),
    )


def test_ctrl_plus_minus_zero_scale_the_ui_text_and_the_labels_and_are_remembered(
    make_window, qtbot, tmp_path
):
    win = make_window(_scene())
    app0, title0, readout0 = _text_sizes(win)
    assert app0 == APP_FONT_PT
    _focus(win, qtbot)
    _keys(qtbot, "ctrl+equal", "ctrl+equal", until=lambda: win.presenter.scale == 1.3)
    app1, title1, readout1 = _text_sizes(win)
    assert app1 == pytest.approx(APP_FONT_PT * 1.3)
    assert title1 == round(title0 * 1.3)
    assert readout1 == pytest.approx(readout0 * 1.3)
    # a feature label in the view grew too
    assert json.loads((tmp_path / "settings.json").read_text())[SCALE_KEY] == 1.3
    _keys(qtbot, "ctrl+minus", until=lambda: win.presenter.scale == 1.15)
    assert _text_sizes(win)[1] == round(title0 * 1.15)
    # remembered: a new window starts at the scale kept in the settings
    win2 = make_window(_scene())
    assert win2.presenter.scale == 1.15
    assert win2.title_actor.GetTextProperty().GetFontSize() == round(title0 * 1.15)
    _focus(win2, qtbot)
    _keys(qtbot, "ctrl+0", until=lambda: win2.presenter.scale == 1.0)
    assert _text_sizes(win2) == (app0, title0, readout0)


def test_f5_presentation_mode_hides_the_panels_enlarges_text_and_raises_contrast(
    make_window, qtbot
):
    win = make_window(_scene())
    shown = [d for d in win.findChildren(QtWidgets.QDockWidget) if d.isVisible()]
    assert shown
    pal0 = QtWidgets.QApplication.palette()
    _focus(win, qtbot)
    _keys(qtbot, "F5", until=lambda: win.presenter.presenting)
    qtbot.waitUntil(lambda: not any(d.isVisible() for d in shown), timeout=3000)
    assert QtWidgets.QApplication.font().pointSizeF() == pytest.approx(APP_FONT_PT * PRESENT_FACTOR)
    pal = QtWidgets.QApplication.palette()
    assert pal.color(QtGui.QPalette.Window).name() == "#ffffff"
    assert pal.color(QtGui.QPalette.WindowText).name() == "#000000"
    _focus(win, qtbot)
    _keys(qtbot, "F5", until=lambda: not win.presenter.presenting)
    qtbot.waitUntil(lambda: all(d.isVisible() for d in shown), timeout=3000)
    assert QtWidgets.QApplication.font().pointSizeF() == APP_FONT_PT
    assert QtWidgets.QApplication.palette().color(QtGui.QPalette.Window) == pal0.color(
        QtGui.QPalette.Window
    )


def test_pagedown_pageup_walk_the_lecture_steps_and_esc_shows_the_whole_scene(
    make_window, qtbot, tmp_path
):
    path = scene_path("lecture")
    whole = load(path)
    win = make_window(load(path), path)
    steps = whole.steps
    _focus(win, qtbot)
    _keys(qtbot, "Next", until=lambda: win.step_index == 0)
    assert win.model.scene.layers == steps[0].layers and win.model.scene.features == []
    assert win.caption_bar.isVisible() and steps[0].caption in win.caption_bar.text()
    _keys(qtbot, "Next", "Next", until=lambda: win.step_index == 2)
    assert win.model.scene.layers == steps[2].layers
    assert [f.name for f in win.model.scene.features] == steps[2].features
    assert f"3 / {len(steps)}" in win.caption_bar.text()
    _keys(qtbot, "Prior", until=lambda: win.step_index == 1)
    assert win.model.scene.layers == steps[1].layers
    # walking is not an edit: nothing to save
    assert not win.is_modified()
    # past the last step stays on it
    _keys(qtbot, *(["Next"] * (len(steps) + 1)), until=lambda: win.step_index == len(steps) - 1)
    assert "predictions" in win.model.scene.layers
    _keys(qtbot, "Escape", until=lambda: win.step_index == -1)
    assert win.model.scene.layers == whole.layers
    assert win.model.scene.features == whole.features
    assert not win.caption_bar.isVisible()
    # saving while walking writes the whole scene
    _keys(qtbot, "Next", until=lambda: win.step_index == 0)
    out = tmp_path / "mine.toml"
    assert win.save_path(out)
    saved = load(out)
    assert saved.features == whole.features and saved.steps == whole.steps
    assert saved.layers == whole.layers


def test_pagedown_on_a_scene_without_steps_says_so(make_window, qtbot):
    win = make_window(_scene())
    _focus(win, qtbot)
    _keys(qtbot, "Next", until=lambda: "no steps" in win.statusBar().currentMessage())
    assert win.step_index == -1 and win.model.scene.layers == _scene().layers


def _caption_whole(bar) -> bool:
    inner = bar.contentsRect().adjusted(bar.margin(), bar.margin(), -bar.margin(), -bar.margin())
    need = bar.fontMetrics().boundingRect(
        QtCore.QRect(0, 0, inner.width(), 0),
        int(QtCore.Qt.TextFlag.TextWordWrap) | int(QtCore.Qt.AlignmentFlag.AlignCenter),
        bar.text(),
    )
    return need.height() <= inner.height()


def test_the_step_caption_shows_whole_and_grows_in_presentation_mode(make_window, qtbot):
    from eyeviz.app.steps import CAPTION_PT

    path = scene_path("lecture")
    win = make_window(load(path), path)
    win.resize(1280, 720)
    qtbot.waitUntil(lambda: win.width() == 1280, timeout=3000)
    _focus(win, qtbot)
    longest = max(range(len(win.model.scene.steps)), key=lambda i: len(win._steps()[i].caption))
    _keys(qtbot, *(["Next"] * (longest + 1)), until=lambda: win.step_index == longest)
    bar = win.caption_bar
    assert bar.font().pointSizeF() == CAPTION_PT
    qtbot.waitUntil(lambda: _caption_whole(bar), timeout=3000)
    _keys(qtbot, "F5", until=lambda: win.presenter.presenting)
    assert bar.font().pointSizeF() == pytest.approx(CAPTION_PT * PRESENT_FACTOR)
    qtbot.waitUntil(lambda: _caption_whole(bar), timeout=3000)
    assert bar.isVisible() and win._steps()[longest].caption in bar.text()
    _keys(qtbot, "F5", until=lambda: not win.presenter.presenting)
    assert bar.font().pointSizeF() == CAPTION_PT


# --- the 3D view (a spherical scene's lecture) ---------------------------------------------


def _focus3d(win, qtbot):
    view = win.host3d.view
    x_focus(win, view)


def _shown3d(win) -> dict[str, bool]:
    """What the 3D view draws now, read from its VTK actors."""
    a = win.host3d.actors
    return {
        "balls": any(b.GetVisibility() for b in a.balls.ball_actors),
        "cones": bool(a.balls.cone_actor is not None and a.balls.cone_actor.GetVisibility()),
        "plane": any(p.GetVisibility() for p in a.field.plane_actors),
        "bfv": bool(a.field.bfv_actor is not None and a.field.bfv_actor.GetVisibility()),
    }


def test_pagedown_walks_a_spherical_lecture_in_the_3d_view(make_window, qtbot, tmp_path):
    path = scene_path("sphere_lecture")
    whole = load(path)
    win = make_window(load(path), path)
    host, steps = win.host3d, whole.steps
    assert host.active and not win.plotter.isVisible()
    _focus3d(win, qtbot)
    picture0 = win.grab_image()
    _keys(qtbot, "Next", until=lambda: win.step_index == 0)
    assert host.model.scene.layers == steps[0].layers and host.model.scene.features == []
    assert _shown3d(win) == {"balls": False, "cones": False, "plane": False, "bfv": False}
    bar = win.caption_bar
    assert bar.isVisible() and f"1 / {len(steps)}   {steps[0].caption}" == bar.text()
    # the caption sits under the 3D view (the planar view and strip are hidden)
    split = win.centralWidget()
    assert split.indexOf(bar) == split.indexOf(host.view) + 1
    assert bar.geometry().top() >= host.view.geometry().bottom()
    qtbot.waitUntil(lambda: win.grab_image() != picture0, timeout=3000)  # balls gone
    _keys(qtbot, "Next", until=lambda: win.step_index == 1)
    assert [f.name for f in host.model.scene.features] == ["target"]
    assert _shown3d(win) == {"balls": True, "cones": False, "plane": False, "bfv": False}
    assert sum(int(n) for n in host.model.state.facets_a) > 0  # its facets are lit
    _keys(qtbot, "Next", until=lambda: win.step_index == 2)
    assert _shown3d(win)["cones"] and steps[2].caption in bar.text()
    plane = next(i for i, s in enumerate(steps) if "plane" in s.layers)
    _keys(qtbot, *(["Next"] * (plane - 2)), until=lambda: win.step_index == plane)
    assert _shown3d(win)["plane"] and not _shown3d(win)["cones"]
    _keys(qtbot, "Prior", until=lambda: win.step_index == plane - 1)
    assert not _shown3d(win)["plane"]
    assert host.docks["bitmaps3d"].isVisible()
    _keys(qtbot, *(["Next"] * len(steps)), until=lambda: win.step_index == len(steps) - 1)
    assert _shown3d(win)["bfv"] and len(host.model.scene.features) == len(whole.features)
    assert not win.is_modified()  # walking is not an edit
    _keys(qtbot, "Escape", until=lambda: win.step_index == -1)
    assert host.model.scene.layers == whole.layers
    assert host.model.scene.features == whole.features
    assert not bar.isVisible() and host.active
    # saving while walking writes the whole spherical scene
    _keys(qtbot, "Next", "Next", until=lambda: win.step_index == 1)
    out = tmp_path / "mine.toml"
    assert win.save_path(out)
    saved = load(out)
    assert saved.kind == "spherical" and saved.features == whole.features
    assert saved.layers == whole.layers and saved.steps == whole.steps
    assert win.step_index == -1 and host.model.scene.features == whole.features


def test_f5_f1_f11_and_ctrl_plus_work_in_the_3d_view(make_window, qtbot):
    path = scene_path("sphere_teaching")
    win = make_window(load(path), path)
    host = win.host3d
    docks = [host.docks["bitmaps3d"], host.docks["readout3d"]]
    assert all(d.isVisible() for d in docks)
    title0 = host.actors.title.GetTextProperty().GetFontSize()
    _focus3d(win, qtbot)
    _keys(qtbot, "F5", until=lambda: win.presenter.presenting)
    qtbot.waitUntil(lambda: not any(d.isVisible() for d in docks), timeout=3000)
    assert QtWidgets.QApplication.font().pointSizeF() == pytest.approx(APP_FONT_PT * PRESENT_FACTOR)
    assert host.actors.title.GetTextProperty().GetFontSize() == round(title0 * PRESENT_FACTOR)
    assert host.active and host.view.isVisible()
    _focus3d(win, qtbot)
    _keys(qtbot, "F5", until=lambda: not win.presenter.presenting)
    qtbot.waitUntil(lambda: all(d.isVisible() for d in docks), timeout=3000)
    assert host.actors.title.GetTextProperty().GetFontSize() == title0
    _focus3d(win, qtbot)
    _keys(qtbot, "ctrl+equal", until=lambda: win.presenter.scale == 1.15)
    assert host.actors.title.GetTextProperty().GetFontSize() == round(title0 * 1.15)
    # a label made after the scaling (a ball added) is at the text scale too
    n = len(host.actors.balls.ball_labels)
    host.add_ball()
    qtbot.waitUntil(lambda: len(host.actors.balls.ball_labels) == n + 1, timeout=3000)
    sizes = {lab.GetTextProperty().GetFontSize() for lab in host.actors.balls.ball_labels}
    assert sizes == {round(LABEL_PX * 1.15)}
    _keys(qtbot, "ctrl+0", until=lambda: win.presenter.scale == 1.0)
    assert host.actors.title.GetTextProperty().GetFontSize() == title0
    _focus3d(win, qtbot)
    _keys(qtbot, "F1", until=lambda: win.presenter.shortcuts_dialog is not None)
    qtbot.waitUntil(win.presenter.shortcuts_dialog.isVisible, timeout=3000)
    win.presenter.shortcuts_dialog.close()
    _focus3d(win, qtbot)
    full = _screen_size(win)
    _keys(qtbot, "F11", until=lambda: win.isFullScreen() and win.size() == full)
    assert host.view.isVisible()
    _focus3d(win, qtbot)
    _keys(qtbot, "F11", until=lambda: not win.isFullScreen())


def _plot_fonts(ax) -> tuple[float, float, float]:
    """(x label, the largest other text: y label or title, first tick label) sizes."""
    side = [ax.yaxis.label] if ax.get_ylabel() else []
    side += [t for t in ax.texts + [ax.title] if t.get_text()]
    side += [ax._left_title] if ax.get_title(loc="left") else []  # the trajectory's titles
    ticks = ax.get_yticklabels() or ax.get_xticklabels()
    return (
        ax.xaxis.label.get_fontsize(),
        max(t.get_fontsize() for t in side),
        ticks[0].get_fontsize(),
    )


def test_the_trajectory_and_design_plots_follow_the_text_scale(make_window, qtbot):
    from eyeviz.app.docks import PLOT_PT

    path = scene_path("trajectory")
    win = make_window(load(path), path)
    traj = win.trajectory_panel
    assert traj is not None and traj.path is not None  # the scene's path is plotted
    design = win.show_design()
    design.wait()
    qtbot.waitUntil(lambda: design.running is None, timeout=30000)
    axes = {"trajectory": (traj, traj.ax_dd), "design": (design, design.ax_ad)}
    before = {k: _plot_fonts(ax) for k, (_p, ax) in axes.items()}
    for k, sizes in before.items():
        assert sizes == (PLOT_PT, PLOT_PT, PLOT_PT), (k, sizes)
    _focus(win, qtbot)
    _keys(qtbot, "ctrl+equal", "ctrl+equal", until=lambda: win.presenter.scale == 1.3)
    for k, (panel, ax) in axes.items():
        qtbot.waitUntil(lambda ax=ax: _plot_fonts(ax)[0] > PLOT_PT, timeout=3000)
        assert _plot_fonts(ax) == pytest.approx((PLOT_PT * 1.3,) * 3), k
        panel.canvas.draw()  # the constrained layout still fits the bigger text
    _focus(win, qtbot)
    _keys(qtbot, "ctrl+0", until=lambda: win.presenter.scale == 1.0)
    for _p, ax in axes.values():
        qtbot.waitUntil(lambda ax=ax: _plot_fonts(ax) == (PLOT_PT,) * 3, timeout=3000)
    # presentation mode scales them too
    _keys(qtbot, "F5", until=lambda: win.presenter.presenting)
    assert _plot_fonts(design.ax_ad)[0] == pytest.approx(PLOT_PT * PRESENT_FACTOR)
    _keys(qtbot, "F5", until=lambda: not win.presenter.presenting)
