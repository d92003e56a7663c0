"""The Eyes panel and Save agree with every other entry point on m (issue 20): the window
draws m = MAX_M and saves it; MAX_M + 2 is refused in one line naming m and the scene is
kept. The other entry points: tests/test_one_bound_of_m.py."""

from PyQt5 import QtCore
from PyQt5.QtTest import QTest

from eyeviz.core.bounds import MAX_M
from eyeviz.model.scene import Eyes, Feature, Scene, View, load


def _scene() -> Scene:
    return Scene(
        Eyes(40.0, 20.0, 720),
        [Feature("target", 0.0, 1500.0, 50.0, "#D55E00")],
        ["eyes", "bfv", "features", "bitmaps", "readout"],
        view=View((0.0, 2300.0), 7000.0),
    )


def _type_m(win, text: str) -> None:
    edit = win.eyes_panel.edits["m"]
    edit.setText(text)
    QTest.keyClick(edit, QtCore.Qt.Key_Return)  # Enter applies h, l, m together


def test_the_panel_draws_and_saves_the_largest_m(make_window, tmp_path):
    win = make_window(_scene())
    _type_m(win, str(MAX_M))
    assert win.eyes_panel.message.text() == ""
    assert win.model.scene.eyes.m == MAX_M
    win.flush()
    assert [mesh.n_cells for mesh in win.actors.eye_meshes] == [MAX_M, MAX_M]
    out = tmp_path / "max.toml"
    assert win.save_path(out)
    assert win.error_box is None or not win.error_box.isVisible()
    assert load(out).eyes.m == MAX_M


def test_the_panel_refuses_one_more_step(make_window):
    win = make_window(_scene())
    before = win.model.scene.copy()
    _type_m(win, str(MAX_M + 2))
    msg = win.eyes_panel.message.text()
    rule = f"m must be an even integer >= 4 and <= {MAX_M}, got {MAX_M + 2}"
    assert msg.startswith(f"Refused: {rule}") and "\n" not in msg, msg
    assert win.model.scene == before and win.undo_stack.count() == 0
    _type_m(win, f"{MAX_M}.0")  # the integer rule: a whole-number float is that integer
    assert win.model.scene.eyes.m == MAX_M and type(win.model.scene.eyes.m) is int
