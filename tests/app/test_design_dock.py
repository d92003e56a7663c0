"""Issue 11 item 4: the "Eye design" dock in the real window (Qt + VTK under Xvfb).

The limit curves of the scene's eyes beside the paper's; recomputed on a worker thread
when h, l or m change (the old curve greyed and marked "computing…" meanwhile); the
selected feature's distance a vertical line that follows a drag without recomputing.
"""

import math
import threading

import numpy as np
import pytest
from mouse import move, pixel_of
from PyQt5 import QtCore
from PyQt5.QtTest import QTest

from eyeviz.app import design_dock
from eyeviz.model.scene import Eyes, Feature, Scene, View


def scene(m=720):
    return Scene(
        Eyes(40.0, 20.0, m),
        [
            Feature("target", 0.0, 1500.0, 50.0, "#D55E00"),
            Feature("other", -1200.0, 3000.0, 200.0, "#0072B2"),
        ],
        ["eyes", "bfv", "features", "bitmaps", "readout", "labels"],
        view=View((0.0, 2300.0), 7000.0),
    )


def curve_on_screen(panel):
    """(DD y, AD y, colour) of the current eyes' curve as drawn."""
    dd, ad = panel.lines["current"]
    return np.asarray(dd.get_ydata()), np.asarray(ad.get_ydata()), dd.get_color()


def set_m_in_panel(win, m):
    """Type m into the Eyes panel and press Enter (as a user does: Enter applies h, l, m)."""
    e = win.eyes_panel.edits["m"]
    e.setText(str(m))
    e.returnPressed.emit()


@pytest.mark.slow
def test_dock_exists_and_shows_the_new_curve_after_m_changes(make_window, qtbot):
    win = make_window(scene())
    act = next(a for a in win.actions() if a.text().startswith("Eye &design"))
    act.trigger()  # View > Eye design
    panel = win.design_panel
    dock = win._docks["design"]
    assert dock.windowTitle() == "Eye design" and dock.isVisible()
    assert win.show_design() is panel  # built once
    assert panel.wait()
    assert not panel.stale and panel.shown == (40.0, 20.0, 720)
    paper = design_dock.compute_curve(40.0, 20.0, 720)  # pure: the same numbers again
    dd, ad, color = curve_on_screen(panel)
    np.testing.assert_allclose(dd, paper["dd_mape"])
    np.testing.assert_allclose(ad, paper["ad_mape"])
    assert color == design_dock.CURRENT
    assert "m 720" in panel.legend.text()

    set_m_in_panel(win, 2880)
    assert win.model.scene.eyes.m == 2880
    # at once: the old curve greyed, "computing…" shown, nothing computed on this thread
    assert panel.stale
    _, _, color = curve_on_screen(panel)
    assert color == design_dock.STALE
    assert panel.computing.get_visible() and "computing" in panel.computing.get_text()
    assert "old: m 720" in panel.legend.text()
    qtbot.waitUntil(lambda: not panel.stale, timeout=15000)
    dd, ad, color = curve_on_screen(panel)
    want = design_dock.compute_curve(40.0, 20.0, 2880)
    np.testing.assert_allclose(dd, want["dd_mape"])
    assert color == design_dock.CURRENT and not panel.computing.get_visible()
    assert np.nanmean(dd) < 0.5 * np.nanmean(paper["dd_mape"])  # 4x the ommatidia
    # the paper's eyes stay drawn beside it (dashed), from the cache
    pd_, pa = panel.lines["paper"]
    np.testing.assert_allclose(pd_.get_ydata(), paper["dd_mape"])
    assert all(t != threading.get_ident() for t in panel.compute_threads)

    # undo: the earlier curve comes from the cache at once, no new computation
    started = panel.jobs_started
    win.undo_stack.undo()
    assert win.model.scene.eyes.m == 720
    assert not panel.stale and panel.jobs_started == started
    np.testing.assert_allclose(curve_on_screen(panel)[0], paper["dd_mape"])


def test_drag_moves_the_marker_without_recomputing(make_window, qtbot):
    win = make_window(scene())
    panel = win.show_design()
    assert panel.wait()
    win.model.select(1)
    QTest.qWait(100)
    r0 = math.hypot(-1200.0, 3000.0)
    assert panel.markers[0].get_visible()
    assert panel.markers[0].get_xdata()[0] == r0
    assert "other: r = 3,231" in panel.legend.text()
    started = panel.jobs_started
    blits = panel.marker_blits
    w = win.plotter
    start, end = pixel_of(win, -1200.0, 3000.0), pixel_of(win, -400.0, 2000.0)
    QTest.mousePress(w, QtCore.Qt.LeftButton, QtCore.Qt.NoModifier, start)
    for k in range(1, 13):
        move(w, start + (end - start) * (k / 12))
    # during the drag (button still down) the marker follows
    f = win.model.scene.features[1]
    r_mid = math.hypot(f.x, f.y)
    assert abs(r_mid - r0) > 300
    qtbot.waitUntil(lambda: abs(panel.markers[0].get_xdata()[0] - r_mid) < 1e-6, timeout=2000)
    QTest.mouseRelease(w, QtCore.Qt.LeftButton, QtCore.Qt.NoModifier, end)
    QTest.qWait(100)
    f = win.model.scene.features[1]
    r1 = math.hypot(f.x, f.y)
    assert panel.markers[0].get_xdata()[0] == r1 and panel.markers[1].get_xdata()[0] == r1
    assert panel.jobs_started == started and not panel.stale  # nothing recomputed
    assert panel.marker_blits > blits  # the marker alone was redrawn (no full draw)
    assert panel.debounce.isActive() is False and panel.running is None


@pytest.mark.slow
def test_the_gui_thread_is_not_blocked_and_stale_results_are_not_drawn(make_window, qtbot):
    win = make_window(scene())
    panel = win.show_design()
    assert panel.wait()
    gate = threading.Event()
    seen = []

    held = threading.Event()

    def slow(h, l, m):  # the real computation, held until the test lets it go
        seen.append((m, threading.get_ident()))
        held.set()
        gate.wait(20)
        held.clear()
        return design_dock.compute_curve(h, l, m)

    panel.compute = slow
    shown = []
    real_show = panel._show
    panel._show = lambda key: (shown.append(key), real_show(key))

    win.model.set_eyes(40.0, 20.0, 1440)
    qtbot.waitUntil(lambda: panel.running == (40.0, 20.0, 1440), timeout=5000)
    # while the worker holds the computation, the GUI thread handles events: a timer ticks
    # and a drag moves the marker
    ticks = []
    timer = QtCore.QTimer()
    timer.timeout.connect(lambda: held.is_set() and ticks.append(len(ticks)))
    timer.start(10)
    win.model.set_eyes(40.0, 20.0, 360)  # a newer change while 1440 is computed
    win.model.select(0)
    win.model.begin_live("move")
    win.model.live(0, y=2600.0)
    qtbot.waitUntil(lambda: panel.markers[0].get_xdata()[0] == 2600.0, timeout=10000)
    # the GUI was live while the curve was computed: ticks counted while the worker is
    # held at the gate (a GUI thread waiting on it would not tick until it was let go)
    qtbot.waitUntil(lambda: len(ticks) >= 10, timeout=10000)
    win.model.end_live()
    timer.stop()
    assert panel.stale and panel.running == (40.0, 20.0, 1440)
    assert seen and all(t != threading.get_ident() for _, t in seen)
    gate.set()
    qtbot.waitUntil(lambda: not panel.stale, timeout=15000)
    assert panel.shown == (40.0, 20.0, 360)
    assert (40.0, 20.0, 1440) not in shown  # computed (cached) but never drawn: stale
    assert (40.0, 20.0, 1440) in panel.cache
    assert [m for m, _ in seen] == [1440, 360]
    want = design_dock.compute_curve(40.0, 20.0, 360)
    np.testing.assert_allclose(curve_on_screen(panel)[0], want["dd_mape"])


def test_a_refused_computation_is_a_message_not_a_crash(make_window, qtbot):
    win = make_window(scene())
    panel = win.show_design()
    assert panel.wait()

    def broken(h, l, m):
        raise ValueError("no prior for these eyes")

    panel.compute = broken
    win.model.set_eyes(40.0, 20.0, 1000)
    qtbot.waitUntil(lambda: bool(panel.error), timeout=5000)
    assert "no prior for these eyes" in panel.info.text() and panel.info.isVisible()
    assert not panel.computing.get_visible()


def test_closing_the_window_during_a_computation_is_clean(make_window, qtbot):
    win = make_window(scene())
    panel = win.show_design()
    assert panel.wait()
    gate = threading.Event()

    def slow(h, l, m):
        gate.wait(20)
        return design_dock.compute_curve(h, l, m)

    panel.compute = slow
    win.model.set_eyes(40.0, 20.0, 1440)
    qtbot.waitUntil(lambda: panel.running is not None, timeout=5000)
    win.force_close()
    gate.set()
    assert panel.pool.waitForDone(20000)
    QTest.qWait(50)  # the result arrives after the close: drawn into a hidden dock, no error
    assert panel.running is None and (40.0, 20.0, 1440) in panel.cache
