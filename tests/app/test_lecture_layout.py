"""The window's layout for a lecture hall (issue 24): the trajectory scene framed on its
path (and F frames it), the trajectory plots unscrolled with thin lines and the legend
off the data, Eye design beside Eyes, the Estimators panel always there, no cut tab."""

import subprocess

import pytest
from mouse import x_focus
from PyQt5 import QtWidgets

from eyeviz.model.camera import to_pixel
from eyeviz.model.scene import load
from eyeviz.resources import scene_path


def _focus(win, qtbot):
    x_focus(win, win.plotter)


def _path_in_view(win) -> bool:
    p = win.trajectory_panel.path
    vp = win.viewport("main")
    view = win.model.scene.view
    for x, y in ((p.x.min(), p.y.min()), (p.x.max(), p.y.max())):
        px, py = to_pixel(view, vp, x, y)
        if not (0 <= px <= vp.width and win.title_band_px() <= py <= vp.height):
            return False
    return True


def _design(win, qtbot):
    """View > Eye design, its curves computed (none lands in a closed window)."""
    panel = win.show_design()
    panel.wait()
    qtbot.waitUntil(lambda: panel.running is None, timeout=30000)


def _trajectory_window(make_window, qtbot):
    path = scene_path("trajectory")
    win = make_window(load(path), path)
    win.resize(1280, 720)
    qtbot.waitUntil(lambda: win.width() == 1280, timeout=3000)
    qtbot.wait(50)
    assert win.trajectory_panel is not None and win.trajectory_panel.path is not None
    return win


def test_the_trajectory_scene_opens_framed_on_its_path_and_f_frames_it(make_window, qtbot):
    win = _trajectory_window(make_window, qtbot)
    win.frame_bundled()  # as eyeviz app does once the window shows
    assert _path_in_view(win)
    # zoomed onto the eyes, the path is out of view; F (a real key) frames it again
    from eyeviz.model.scene import View

    win.model.scene.view = View((0.0, 0.0), 400.0)
    win.model.notify_view()
    assert not _path_in_view(win)
    _focus(win, qtbot)
    subprocess.run(["xdotool", "key", "f"], check=True)
    qtbot.waitUntil(lambda: _path_in_view(win), timeout=5000)


def test_the_trajectory_plots_fit_unscrolled_with_thin_lines_and_the_legend_outside(
    make_window, qtbot
):
    win = _trajectory_window(make_window, qtbot)
    dock = win._docks["trajectory"]
    qtbot.waitUntil(dock.isVisible, timeout=3000)
    qtbot.wait(100)
    scroll = dock.widget()
    assert isinstance(scroll, QtWidgets.QScrollArea)
    assert not scroll.verticalScrollBar().isVisible()  # both plots above the fold
    panel = win.trajectory_panel
    lines = [ln for ln in panel.ax_dd.get_lines() if ln.get_label() in win.model.scene.estimators]
    assert len(lines) == 2 and all(ln.get_linewidth() <= 1.5 for ln in lines)
    assert len({str(ln.get_linestyle()) for ln in lines}) == 2  # equal curves stay apart
    # the legend is the figure's, above both axes: on none of the data
    panel.canvas.draw()
    r = panel.canvas.get_renderer()
    leg = panel.legend.get_window_extent(r)
    for ax in (panel.ax_ad, panel.ax_dd):
        assert not leg.overlaps(ax.get_window_extent(r))


def test_eye_design_shows_beside_the_eyes_panel(make_window, qtbot):
    win = _trajectory_window(make_window, qtbot)
    _design(win, qtbot)
    eyes = win.findChild(QtWidgets.QDockWidget, "dock_eyes")
    design = win._docks["design"]
    qtbot.waitUntil(
        lambda: design.isVisible() and not design.visibleRegion().isEmpty(),
        timeout=3000,
    )
    assert eyes.isVisible() and not eyes.visibleRegion().isEmpty()  # both shown at once
    assert eyes not in win.tabifiedDockWidgets(design)


def test_the_estimators_panel_is_always_there_greyed_until_predictions_are_on(make_window, qtbot):
    sc = load(scene_path("default"))
    assert "predictions" not in sc.layers
    win = make_window(sc)
    dock = win._docks["predictions"]
    assert win.picker is not None and not win.picker.isEnabled()
    assert dock.toggleViewAction().isEnabled()
    win.model.set_layer("predictions", True)
    assert win.picker.isEnabled()
    win.model.set_layer("predictions", False)
    assert not win.picker.isEnabled()


@pytest.mark.parametrize("size", [(1280, 720), (1920, 1080)])
def test_no_tab_is_cut_with_every_panel_open(make_window, qtbot, size):
    win = _trajectory_window(make_window, qtbot)
    win.resize(*size)
    _design(win, qtbot)
    qtbot.waitUntil(lambda: win.width() == size[0], timeout=3000)
    qtbot.wait(100)
    for bar in win.findChildren(QtWidgets.QTabBar):
        if not bar.isVisible():
            continue
        for i in range(bar.count()):
            text = bar.tabText(i)
            need = bar.fontMetrics().horizontalAdvance(text)
            assert bar.tabRect(i).width() >= need, text
            assert bar.tabRect(i).right() <= bar.width(), text  # no scrolled-off tab


def test_the_paper_estimators_message_names_the_folders_it_searched(
    make_window, monkeypatch, tmp_path
):
    from eyeviz.estimators.paper.weights import weights_dirs

    monkeypatch.delenv("EYEVIZ_PAPER_DIR", raising=False)
    monkeypatch.setenv("HOME", str(tmp_path))  # no weights in the user's folders
    monkeypatch.delenv("XDG_DATA_HOME", raising=False)
    monkeypatch.delenv("XDG_CACHE_HOME", raising=False)
    monkeypatch.delenv("EYEVIZ_HOME", raising=False)
    if any((d / "ad.pt").is_file() for d in weights_dirs()):
        pytest.skip("the paper's weights are installed here: no message to read")
    sc = load(scene_path("default"))
    sc.layers.append("predictions")
    sc.estimators = ["paper"]
    win = make_window(sc)
    win.jobs.wait()
    win.picker.refresh()
    note, row = win.picker.note.text(), win.readout.texts.get("pred:paper", "")
    # the picker's note names all three; the readout's one line starts with them
    assert "looked in eyeviz/assets/models/paper, ~/.local/share/eyeviz/models/paper, " in note
    assert "~/.cache/eyeviz/models/paper)" in note
    assert "looked in eyeviz/assets/models/paper, ~/.local/share/eyeviz/" in row
    assert str(tmp_path) not in note + row  # no local path: the home folder is ~


def test_three_estimators_fit_the_readout_uncut_at_1280x720(make_window, qtbot):
    from eyeviz.model.scene import Eyes, Feature, Scene, View

    # far from the training range: four-digit errors, the longest lines the readout shows
    sc = Scene(
        Eyes(40.0, 20.0, 720),
        [Feature("target", 400.0, 700.0, 30.0)],
        ["eyes", "bfv", "features", "readout", "predictions"],
        estimators=["analytic", "limit", "compact"],
        view=View((0.0, 2300.0), 7000.0),
    )
    win = make_window(sc)
    win.resize(1280, 720)
    qtbot.waitUntil(lambda: win.width() == 1280, timeout=3000)
    win.jobs.wait()
    win.model.select(0)
    qtbot.wait(50)
    rows = [v for k, v in win.readout._rows if v.isVisible()]
    texts = [v.text() for v in rows]
    assert any("Δr" in t for t in texts)
    for v in rows:
        fm = v.fontMetrics()
        for line in v.text().split("\n"):
            assert fm.horizontalAdvance(line) <= v.width(), line  # never elided


@pytest.mark.parametrize("m", [720, 100000])
def test_the_insets_m_theta_psi_line_stays_inside_the_inset(make_window, m):
    from eyeviz.model.scene import Eyes, Feature, Scene, View

    sc = Scene(
        Eyes(40.0, 20.0, m),
        [Feature("target", 0.0, 1500.0, 50.0)],
        ["eyes", "bfv", "features", "labels"],
        view=View((0.0, 2300.0), 7000.0),
    )
    win = make_window(sc)
    win.resize(1280, 720)
    win.fit_inset()
    win.render()
    assert win.inset_shown
    foot = win.actors.labels.bfv_text["inset"]
    assert f"m = {m}" in foot.GetInput() and "θ = 120°" in foot.GetInput()
    box = [0.0] * 4
    foot.GetBoundingBox(win.inset_ren, box)  # pixels about its anchor (centred)
    width = win.inset_ren.GetSize()[0]
    assert box[1] - box[0] <= 0.96 * width, (box, width)


def test_figure3b_opens_with_its_sector_rays_clear_of_the_title_and_the_tangents_note(
    make_window, qtbot
):
    import numpy as np

    path = scene_path("figure3b")
    win = make_window(load(path), path)
    win.resize(1280, 720)
    qtbot.waitUntil(lambda: win.width() == 1280, timeout=3000)
    win.frame_bundled()
    win.render()
    sectors = win.actors.painters["sectors"]
    assert sectors.shown
    band = win.title_band_px()
    assert band > 48  # the title and the tangents' note under it
    vp, view = win.viewport("main"), win.model.scene.view
    for x, y in np.asarray(sectors.mesh.points)[:, :2]:
        assert to_pixel(view, vp, x, y)[1] >= band, (x, y)


def test_zoomed_onto_the_eyes_the_m_theta_psi_line_steps_aside_for_a_name(make_window, qtbot):
    from eyeviz.model.scene import Eyes, Feature, Scene, View

    sc = Scene(
        Eyes(40.0, 20.0, 72),
        [Feature("a name", 0.0, 0.0, 4.0)],
        ["eyes", "bfv", "features", "labels"],
        view=View((0.0, 0.0), 200.0),
    )
    win = make_window(sc)
    win.resize(1280, 720)
    qtbot.waitUntil(lambda: win.width() == 1280, timeout=3000)
    win.render()
    assert not win.inset_shown  # the eyes are large: the main view carries the line
    foot = win.actors.labels.bfv_text["main"]
    vp, view = win.viewport("main"), win.model.scene.view
    # the feature's name where the line is, then far from it
    from eyeviz.model.camera import to_model

    x, y = to_model(view, vp, vp.width - 200.0, vp.height - 8.0)
    win.model.set_feature(0, x=x - 30.0, y=y)
    win.render()
    assert not foot.GetVisibility()
    win.model.set_feature(0, x=0.0, y=60.0)
    win.render()
    assert foot.GetVisibility() and "θ = 120°" in foot.GetInput()
