"""Issue 12 items 5-8 on a real window (xvfb-run): the BFV to the view's edge, layers that
act, colours fixed by name, the selected feature visible in the bitmaps, small-m cells,
panels that fit 1280x720, messages without local paths."""

import numpy as np
import pytest
from PyQt5 import QtCore, QtGui, QtWidgets
from PyQt5.QtTest import QTest

from eyeviz.app.panels import user_message
from eyeviz.model.palette import ESTIMATOR_COLORS, FEATURE_COLORS, estimator_color
from eyeviz.model.scene import Eyes, Feature, Scene, View
from eyeviz.render.vtk.style import BFV_FILL, hex_rgb

LAYERS = ["eyes", "bfv", "features", "bitmaps", "readout", "labels"]


def view_pixel(win, px, py):
    img = win.grab_image()
    top_left = win.plotter.mapTo(win, QtCore.QPoint(0, 0))
    c = QtGui.QColor(img.pixel(top_left.x() + px, top_left.y() + py))
    return np.array([c.red(), c.green(), c.blue()])


def test_bfv_reaches_the_edge_of_the_view_far_away(make_window):
    # x = y = 1e7 is in the BFV (phi = 45 deg within [30, 150]); the old wedge stopped at
    # y = 5e6 and this spot was white
    win = make_window(Scene(Eyes(40.0, 20.0, 720), [], ["eyes", "bfv"], view=View((1e7, 1e7), 4e4)))
    win.apply_cameras()
    w, h = win.plotter.width(), win.plotter.height()
    fill = np.round(255 * np.array(BFV_FILL))
    for px, py in ((w // 2, h // 2), (w - 5, 5), (w // 2, 5)):
        assert np.abs(view_pixel(win, px, py) - fill).max() <= 2, (px, py)
    # zoomed further out (the view 100x wider): still filled to the edge
    win.model.scene.view = View((1e8, 1e8), 4e6)
    win.apply_cameras()
    assert np.abs(view_pixel(win, w - 5, 5) - fill).max() <= 2


def test_unticking_readout_hides_every_value(make_window):
    win = make_window(
        Scene(
            Eyes(40.0, 20.0, 720),
            [Feature("f", 0.0, 2000.0, 50.0)],
            LAYERS,
            view=View((0, 1500), 6000),
        )
    )
    win.model.select(0)
    assert "r" in win.readout.texts and "2000.0" in win.readout.texts["r"]
    win.model.set_layer("readout", False)
    assert set(win.readout.texts) == {"hidden"}
    shown = [v.text() for _, v in win.readout._rows if v.isVisible()]
    assert shown == [win.readout.texts["hidden"]] and "2000" not in " ".join(shown)
    win.model.set_layer("readout", True)
    assert "2000.0" in win.readout.texts["r"]


@pytest.mark.slow
def test_trajectory_without_a_path_shows_a_placeholder_not_empty_axes(make_window):
    sc = Scene(Eyes(40.0, 20.0, 720), [Feature("f", 0.0, 2000.0, 50.0)], LAYERS + ["trajectory"])
    win = make_window(sc)
    panel = win.trajectory_panel
    assert panel is not None and panel.path is None
    assert not panel.ax_ad.get_visible() and not panel.ax_dd.get_visible()
    assert panel.placeholder.get_visible() and "choose a path" in panel.placeholder.get_text()
    win.show_trajectory("horizontal")
    assert panel.path is not None and panel.ax_ad.get_visible()
    assert not panel.placeholder.get_visible()
    sizes = [t.get_fontsize() for t in panel.ax_dd.get_xticklabels()]
    sizes += [panel.ax_ad.title.get_fontsize(), panel.ax_dd.xaxis.label.get_fontsize()]
    assert min(sizes) >= 10


def _dist(a, b):
    return float(np.linalg.norm(np.subtract(hex_rgb(a), hex_rgb(b))))


def test_estimator_colours_are_fixed_by_name_and_unlike_feature_colours(make_window):
    for name in list(ESTIMATOR_COLORS) + ["someone_new"]:
        assert estimator_color(name) not in FEATURE_COLORS
        assert min(_dist(estimator_color(name), f) for f in FEATURE_COLORS) >= 60, name
    names = list(ESTIMATOR_COLORS)
    assert len({ESTIMATOR_COLORS[n] for n in names}) == len(names)
    # the same colour whatever the order of the scene's list, in the view and the picker
    seen = {}
    for order in (["analytic", "compact"], ["compact", "analytic"]):
        sc = Scene(
            Eyes(40.0, 20.0, 720),
            [Feature("f", 300.0, 2500.0, 60.0)],
            LAYERS + ["predictions"],
            estimators=order,
            view=View((0, 2300), 7000),
        )
        win = make_window(sc)
        for name in order:
            icon = win.picker.boxes[name].icon().pixmap(16, 16).toImage()
            seen.setdefault(name, set()).add(QtGui.QColor(icon.pixel(8, 8)).name())
        win.close()
    assert seen["compact"] == {ESTIMATOR_COLORS["compact"].lower()}
    assert seen["analytic"] == {ESTIMATOR_COLORS["analytic"].lower()}


def test_selected_feature_stays_visible_where_features_overlap_in_a_strip(make_window):
    # two features lighting overlapping cells: the later one ("top") owns them, but the
    # selected first one is drawn over it and outlined
    fs = [
        Feature("under", 0.0, 2000.0, 40.0, "#D55E00"),
        Feature("top", 0.0, 2000.0, 90.0, "#0072B2"),
    ]
    win = make_window(Scene(Eyes(40.0, 20.0, 720), fs, LAYERS, view=View((0, 1500), 6000)))
    st = win.model.state
    assert (st.owner_a == 1).any() and not (st.owner_a == 0).any()  # "under" is hidden
    win.model.select(0)
    strip = win.bitmaps.strips[("A", True)]
    lo, hi = int(st.LA[0]), int(st.RA[0])
    assert (strip[lo : hi + 1] == 0).all()
    img = win.bitmaps.grab().toImage()
    cols = {
        QtGui.QColor(img.pixel(x, y)).name()
        for x in range(img.width())
        for y in range(0, img.height(), 3)
    }
    assert "#d55e00" in cols


def test_small_m_shows_cell_boundaries(make_window):
    win = make_window(
        Scene(
            Eyes(40.0, 20.0, 16),
            [Feature("f", 0.0, 2000.0, 50.0)],
            LAYERS,
            view=View((0, 1500), 6000),
        )
    )
    win.model.select(0)
    QTest.qWait(50)
    img = win.bitmaps.grab().toImage()
    y = win.bitmaps._row_rect(1).center().y()
    x0, right, _ = win.bitmaps._geometry(win.bitmaps.fontMetrics())
    strip = range(x0 + 2, img.width() - right - 2)
    boundary = [x for x in strip if QtGui.QColor(img.pixel(x, y)).name() == "#9a9a9a"]
    assert len(boundary) >= 12  # m - 1 = 15 boundaries (some under the outline)
    win.model.set_eyes(40.0, 20.0, 720)  # large m: no boundaries
    QTest.qWait(50)
    img = win.bitmaps.grab().toImage()
    assert not [x for x in strip if QtGui.QColor(img.pixel(x, y)).name() == "#9a9a9a"]


def test_tab_names_are_whole_and_messages_never_widen_the_panel(make_window):
    sc = Scene(Eyes(40.0, 20.0, 720), [Feature("f", 0.0, 2000.0, 50.0)], LAYERS + ["predictions"])
    win = make_window(sc)
    win.resize(1280, 720)
    win.show_trajectory("horizontal")
    QTest.qWait(100)
    bars = [b for b in win.findChildren(QtWidgets.QTabBar) if b.count() > 1]
    assert bars
    for bar in bars:
        assert bar.elideMode() == QtCore.Qt.ElideNone
        for i in range(bar.count()):
            need = bar.fontMetrics().horizontalAdvance(bar.tabText(i))
            assert bar.tabRect(i).width() >= need, bar.tabText(i)
    dock = win.eyes_panel.parentWidget()
    before = dock.width()
    win.eyes_panel.edits["m"].setText("x" * 400)
    win.eyes_panel.apply()
    QTest.qWait(100)
    assert "Refused" in win.eyes_panel.message.text()
    assert dock.width() <= before + 2


def test_messages_never_show_a_local_path_or_an_exception_name():
    for raw in (
        "unavailable: no weights at /home/someone/eyeviz/assets/models/paper/w.npz",
        "FileNotFoundError: [Errno 2] No such file or directory: '/tmp/x/y/model.pt'",
        r"C:\Users\me\eyeviz\w.npz is missing",
    ):
        out = user_message(raw)
        assert "/home" not in out and "/tmp" not in out and "Users" not in out
        assert "Error" not in out and "Errno" not in out and out


def test_readout_and_picker_show_unavailable_estimators_without_paths(make_window, monkeypatch):
    import threading

    from eyeviz import estimators

    threads = []

    def fail(name, *a, **k):  # the real Predictor records this as "unavailable: ..."
        threads.append(threading.current_thread())
        raise FileNotFoundError(
            "no weights at /home/someone/.cache/eyeviz/paper.npz (Traceback: model.py:12)"
        )

    monkeypatch.setattr(estimators, "load", fail)
    sc = Scene(
        Eyes(40.0, 20.0, 720),
        [Feature("f", 300.0, 2500.0, 60.0)],
        LAYERS + ["predictions"],
        estimators=["paper"],
        view=View((0, 2300), 7000),
    )
    win = make_window(sc)
    win.model.select(0)
    win.jobs.wait()  # the failure is found on the worker thread, never on the GUI thread
    assert threads and threading.main_thread() not in threads
    texts = [win.readout.texts.get("pred:paper", ""), win.picker.note.text()]
    assert all("unavailable" in t for t in texts), texts
    for t in texts:
        assert "/home" not in t and ".cache" not in t and "Traceback" not in t
        assert "paper.npz" in t  # the file name stays: the user knows what is missing


def test_default_scene_opens_framed_clear_of_the_title_the_inset_and_the_edges(make_window, qtbot):
    """`eyeviz app` on the bundled default scene (its saved view put 'far' under the title
    and the eyes out of view): every disc, its label and the eyes in the free area."""
    from eyeviz.app.canvas import LABEL_CHAR_PX, TITLE_BAND_PX
    from eyeviz.model.scene import load
    from eyeviz.resources import scene_path

    path = scene_path("default")
    win = make_window(load(path), path)
    win.resize(1280, 720)
    qtbot.wait(100)
    win.frame_bundled()
    w, h = win.plotter.width(), win.plotter.height()
    inset = win.viewport("inset") if win.inset_shown else None
    sc = win.model.scene
    for f in sc.features:
        for dx, dy in ((f.g, 0), (-f.g, 0), (0, f.g), (0, -f.g)):
            px, py = win.to_pixel(f.x + dx, f.y + dy)
            assert TITLE_BAND_PX <= py <= h and 0 <= px <= w, (f.name, px, py)
            assert inset is None or not inset.contains(px, py), f.name
        lx, _ = win.to_pixel(f.x + 0.75 * f.g, f.y)
        assert lx + LABEL_CHAR_PX * (1 + len(f.name)) <= w, f.name  # the label is whole
    ex, ey = win.to_pixel(0.0, 0.0)
    assert 0 <= ex <= w and TITLE_BAND_PX <= ey <= h  # the eyes are in the main view too
    # the window grows: the view stays fitted (not zoomed or panned since)
    v0 = sc.view
    win.resize(1366, 768)
    qtbot.waitUntil(lambda: win.model.scene.view != v0, timeout=3000)
    # a user's own zoom is kept on a resize
    win.model.scene.view = View(win.model.scene.view.center, 3000.0)
    win.resize(1280, 720)
    qtbot.wait(200)
    assert win.model.scene.view.width == 3000.0


def test_every_tab_shows_whole_and_no_side_panel_is_cut_at_1280x720(make_window, qtbot):
    sc = Scene(
        Eyes(40.0, 20.0, 720),
        [Feature("feature with a long name", 0.0, 2000.0, 50.0)],
        LAYERS + ["predictions"],
        estimators=["analytic", "compact"],
    )
    win = make_window(sc)
    win.resize(1280, 720)
    win.show_trajectory("horizontal")
    win.jobs.wait()
    qtbot.wait(200)
    assert win.plotter.width() >= win.width() / 2
    for bar in [b for b in win.findChildren(QtWidgets.QTabBar) if b.count() > 1]:
        for i in range(bar.count()):  # every tab in full view: none scrolled away or cut
            assert bar.rect().contains(bar.tabRect(i)), bar.tabText(i)
    for dock in win.findChildren(QtWidgets.QDockWidget):
        if not dock.isVisibleTo(win):
            continue
        dock.raise_()  # its tab in front
        qtbot.wait(50)
        scroll = dock.widget()
        # nothing hidden beyond the right edge (there is no horizontal scroll bar)
        assert scroll.widget().width() <= scroll.viewport().width(), dock.windowTitle()
    # the readout's prediction values are whole (not elided) at this size
    vals = [v for _, v in win.readout._rows if v.isVisible()]
    for v in vals:
        for line in v._text.split("\n"):
            assert v.fontMetrics().horizontalAdvance(line) <= v.width(), line
