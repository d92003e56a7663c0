"""The Eyes panel (eyeviz/app/panels/eyes.py) on a real window: h, l and m are entered as a
triple and checked together as EyePair checks them (issue 12 item 11)."""

import shutil
import subprocess
import time

import pytest
from PyQt5 import QtCore
from PyQt5.QtTest import QTest

from eyeviz.model.scene import Eyes, Feature, Scene, View

PENDING = "background: #fff4c2;"


def scene(h=40.0, l=20.0, m=720):
    return Scene(
        Eyes(h, l, m),
        [Feature("target", 0.0, 1500.0, 50.0, "#D55E00")],
        ["eyes", "bfv", "features", "bitmaps", "readout"],
        view=View((0.0, 2300.0), 7000.0),
    )


def type_into(edit, text):
    """Select all of the field and type ``text`` key by key (real Qt key events)."""
    edit.setFocus()
    edit.selectAll()
    QTest.keyClicks(edit, text)


def eyes(win):
    e = win.model.scene.eyes
    return e.h, e.l, e.m


def test_h_below_the_old_l_then_l_then_enter_is_one_change(make_window):
    win = make_window(scene())
    panel = win.eyes_panel
    type_into(panel.edits["h"], "10")
    QTest.keyClick(panel.edits["h"], QtCore.Qt.Key_Tab)  # leaving a field applies nothing
    assert eyes(win) == (40.0, 20.0, 720) and panel.message.text() == ""
    assert panel.edits["h"].styleSheet() == PENDING and panel.apply_button.isEnabled()
    type_into(panel.edits["l"], "5")
    QTest.keyClick(panel.edits["l"], QtCore.Qt.Key_Return)
    assert eyes(win) == (10.0, 5.0, 720)
    assert win.undo_stack.count() == 1 and win.undo_stack.undoText() == "Change eyes"
    assert panel.message.text() == "" and not panel.apply_button.isEnabled()
    assert all(e.styleSheet() == "" for e in panel.edits.values())
    win.undo_stack.undo()  # one step back to the old triple, shown in the fields
    assert eyes(win) == (40.0, 20.0, 720)
    assert panel.texts() == {"h": "40", "l": "20", "m": "720"}


def test_a_refused_triple_changes_nothing_and_keeps_what_was_typed(make_window):
    win = make_window(scene())
    panel = win.eyes_panel
    before = win.model.scene.copy()
    lit = (win.model.state.LA.copy(), win.model.state.RA.copy())
    type_into(panel.edits["h"], "30")
    type_into(panel.edits["l"], "30")  # l = h: refused together, whichever came first
    type_into(panel.edits["m"], "36")
    panel.apply_button.click()
    assert win.model.scene == before and win.undo_stack.count() == 0
    assert (win.model.state.LA == lit[0]).all() and (win.model.state.RA == lit[1]).all()
    msg = panel.message.text()
    assert msg.startswith("Refused: h must be > l") and "\n" not in msg
    assert panel.texts() == {"h": "30", "l": "30", "m": "36"}  # not clamped, not reset
    assert [e.styleSheet() for e in panel.edits.values()] == [PENDING] * 3
    # a refresh for another reason (an edit of a feature) keeps the typed values
    win.model.set_feature(0, x=25.0)
    assert panel.texts() == {"h": "30", "l": "30", "m": "36"}
    # fixing one field and Enter applies the triple
    type_into(panel.edits["l"], "12")
    QTest.keyClick(panel.edits["l"], QtCore.Qt.Key_Return)
    assert eyes(win) == (30.0, 12.0, 36) and panel.message.text() == ""
    # Revert after a typed value shows the scene's values again
    type_into(panel.edits["m"], "9")
    panel.revert_button.click()
    assert panel.texts() == {"h": "30", "l": "12", "m": "36"}
    assert not panel.apply_button.isEnabled()


def test_a_value_is_never_rounded_when_another_field_changes(make_window):
    win = make_window(scene(h=40.123456789, l=19.87654321))
    panel = win.eyes_panel
    assert panel.texts()["h"] == "40.123456789"
    type_into(panel.edits["m"], "360")
    QTest.keyClick(panel.edits["m"], QtCore.Qt.Key_Return)
    assert eyes(win) == (40.123456789, 19.87654321, 360)


def test_h_l_m_typed_through_the_x_server(make_window, qtbot):
    """Real key presses (xdotool through the X server), not Qt's synthetic events."""
    if shutil.which("xdotool") is None:
        pytest.fail("xdotool is needed for this test: apt-get install xdotool")
    win = make_window(scene())
    win.activateWindow()
    win.raise_()
    win.eyes_panel.parentWidget().parentWidget().parentWidget().raise_()  # the Eyes tab
    h = win.eyes_panel.edits["h"]
    h.setFocus()
    qtbot.waitUntil(h.hasFocus, timeout=3000)
    wid = str(int(win.winId()))

    def keys(*names):
        subprocess.run(["xdotool", "key", "--window", wid, *names], check=True)

    keys("ctrl+a", "1", "0", "Tab")  # h = 10 with l = 20: not applied on Tab
    deadline = time.time() + 3
    while time.time() < deadline and not win.eyes_panel.edits["l"].hasFocus():
        qtbot.wait(50)
    assert h.text() == "10" and eyes(win) == (40.0, 20.0, 720)
    keys("ctrl+a", "5", "Return")
    qtbot.waitUntil(lambda: eyes(win) == (10.0, 5.0, 720), timeout=3000)
    keys("Tab", "ctrl+a", "7", "Return")  # m = 7: refused, the message in the panel
    qtbot.waitUntil(lambda: "Refused" in win.eyes_panel.message.text(), timeout=3000)
    assert eyes(win) == (10.0, 5.0, 720) and win.eyes_panel.edits["m"].text() == "7"
