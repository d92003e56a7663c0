"""Issue 12, drag latency: a mouse move during a drag re-lays out nothing and repaints only
the widgets whose content changed (real window, real VTK, counted by an event filter)."""

import collections
import math
import time

import pytest
from mouse import move, pixel_of
from PyQt5 import QtCore, QtWidgets
from PyQt5.QtTest import QTest

from eyeviz.app.window import LIVE_PANEL_MS
from eyeviz.model.scene import Eyes, Feature, Scene, View

LAYERS = ["eyes", "bfv", "features", "bitmaps", "readout", "labels"]


class Counter(QtCore.QObject):
    def __init__(self):
        super().__init__()
        self.on = False
        self.counts = collections.Counter()

    def eventFilter(self, obj, ev):  # noqa: N802
        if self.on and ev.type() in (QtCore.QEvent.Paint, QtCore.QEvent.LayoutRequest):
            self.counts[(int(ev.type()), type(obj).__name__)] += 1
        return False

    def total(self, kind):
        return sum(v for (t, _), v in self.counts.items() if t == int(kind))


@pytest.mark.slow
def test_a_drag_move_lays_out_nothing_and_paints_little(make_window):
    fs = [Feature(f"f{i}", -2000.0 + 400 * i, 3000.0, 60.0) for i in range(8)]
    fs.append(Feature("dragged", 0.0, 1500.0, 50.0, "#D55E00"))
    win = make_window(Scene(Eyes(40.0, 20.0, 720), fs, LAYERS, view=View((0.0, 2600.0), 9000.0)))
    win.model.select(len(fs) - 1)
    app = QtWidgets.QApplication.instance()
    counter = Counter()
    app.installEventFilter(counter)
    try:
        w = win.plotter
        start = pixel_of(win, 0.0, 1500.0)
        QTest.mousePress(w, QtCore.Qt.LeftButton, QtCore.Qt.NoModifier, start)
        for k in range(8):  # past the drag threshold, panels settled
            move(w, start + QtCore.QPoint(3 * k, -k))
            app.processEvents()
        n, frames0 = 30, w.frames
        x0 = win.model.scene.features[-1].x
        counter.on = True
        for k in range(n):
            # the move's (coalesced) frame, counted from before the move: move() runs the
            # pending events, which usually draw it already (counted after, every move
            # waited out its 0.5 s: 15 s of a busy loop); on a loaded machine three more
            # passes may not reach it
            target, deadline = w.frames + 1, time.monotonic() + 0.5
            move(w, start + QtCore.QPoint(30 + 4 * k, -10 - 3 * k))
            for _ in range(3):
                app.processEvents()
            while w.frames < target and time.monotonic() < deadline:
                app.processEvents()
        counter.on = False
        QTest.mouseRelease(w, QtCore.Qt.LeftButton, QtCore.Qt.NoModifier, start)
    finally:
        app.removeEventFilter(counter)
    assert win.model.scene.features[-1].x != x0 and w.frames - frames0 >= n // 2  # it moved
    layouts = counter.total(QtCore.QEvent.LayoutRequest)
    paints = counter.total(QtCore.QEvent.Paint)
    # before: 5 layout requests and ~19 paint events per move (the whole window re-laid
    # out and repainted under every changed label)
    assert layouts <= 1, counter.counts
    assert paints / n <= 7, counter.counts
    assert counter.counts[(int(QtCore.QEvent.Paint), "MainWindow")] == 0, counter.counts
    assert counter.counts[(int(QtCore.QEvent.Paint), "QDockWidget")] == 0, counter.counts


def test_bitmaps_panel_repaints_nothing_when_the_bitmaps_do_not_change(make_window):
    win = make_window(
        Scene(
            Eyes(40.0, 20.0, 72),
            [Feature("f", 0.0, 2000.0, 50.0)],
            LAYERS,
            view=View((0, 0), 9000.0),
        )
    )
    win.model.select(0)
    app = QtWidgets.QApplication.instance()
    QTest.qWait(300)  # everything of the first show painted
    counter = Counter()
    app.installEventFilter(counter)
    try:
        counter.on = True
        win.model.live(0, x=0.01)  # far below one ommatidium: the same bitmaps
        win.render()
        for _ in range(3):
            app.processEvents()
        QTest.qWait(LIVE_PANEL_MS + 100)  # the panels' coalesced refresh ran too
        counter.on = False
    finally:
        app.removeEventFilter(counter)
    assert counter.counts[(int(QtCore.QEvent.Paint), "BitmapPanel")] == 0, counter.counts


def _shown(win):
    """What the readout's r row and the bitmaps panel's A interval should show now."""
    st, i = win.model.state, win.model.selected
    r_text = f"{st.r[i]:.1f}, {math.degrees(st.phi[i]):.2f}°"
    return r_text, (int(st.LA[i]), int(st.RA[i]))


def _panels(win):
    return win.readout.texts["r"], win.bitmaps.intervals["A"]


def test_panels_follow_a_live_change_coalesced_and_show_its_end(make_window, qtbot):
    """During a drag the readout and bitmaps panels refresh at <= 20 Hz (a drag frame does
    not wait for them); flush(), the coalesced refresh and the release show the last state."""
    fs = [Feature("f0", -1500.0, 3000.0, 60.0), Feature("dragged", 0.0, 1500.0, 50.0)]
    win = make_window(Scene(Eyes(40.0, 20.0, 720), fs, LAYERS, view=View((0.0, 2600.0), 9000.0)))
    win.model.select(1)
    assert _panels(win) == _shown(win)
    before = _panels(win)
    win.model.live(1, x=300.0, y=1200.0)  # a live change: drawn by the next frame
    win.render()  # no event handled since: the panels' refresh is still pending
    assert _panels(win) == before and win._panel_timer.isActive()
    assert _shown(win) != before  # the move changed what they show
    win.flush()  # at once
    assert _panels(win) == _shown(win) and not win._panel_timer.isActive()
    win.model.live(1, x=-400.0, y=1800.0)
    win.render()
    qtbot.waitUntil(lambda: not win._panel_timer.isActive(), timeout=2000)
    assert _panels(win) == _shown(win)  # the coalesced refresh took the last change
    # a real drag: the release (its undo step) refreshes the panels at once
    before = _panels(win)
    start = pixel_of(win, -400.0, 1800.0)
    end = start + QtCore.QPoint(40, 25)
    w = win.plotter
    QTest.mousePress(w, QtCore.Qt.LeftButton, QtCore.Qt.NoModifier, start)
    for k in range(1, 9):
        move(w, start + (end - start) * (k / 8))
        win.render()
    QTest.mouseRelease(w, QtCore.Qt.LeftButton, QtCore.Qt.NoModifier, end)
    assert win.model.scene.features[1].x != -400.0 and win.undo_stack.count() == 1
    assert _shown(win) != before  # the drag changed what the panels show
    assert _panels(win) == _shown(win) and not win._panel_timer.isActive()
