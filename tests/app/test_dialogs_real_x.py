"""Ctrl+S, Ctrl+O and the unsaved-changes prompt through the X server, as a user meets
them: real key presses (xdotool's XTEST) into the real dialogs Qt shows, not calls to
``save_path`` / ``open_file``."""

import shutil
import subprocess

import pytest
from mouse import x_focus
from PyQt5 import QtCore, QtWidgets

from eyeviz.model.scene import Eyes, Feature, Scene, View, load


def _scene():
    return Scene(
        Eyes(40.0, 20.0, 720),
        [Feature("target", 0.0, 1500.0, 50.0, "#D55E00")],
        ["eyes", "bfv", "features", "bitmaps", "readout"],
        view=View((0.0, 2300.0), 7000.0),
    )


def _retried(step: str) -> str:
    """A shell command for one xdotool step. A search is retried (up to 5 s): xdotool walks
    the window tree and dies with BadWindow when a window in it is destroyed meanwhile (a
    dialog closing under a loaded machine), or BadMatch when its window is not viewable
    yet. Key presses are never retried: they would be typed twice."""
    if not step.startswith("search"):
        return f"xdotool {step}"
    return f"(for i in $(seq 25); do xdotool {step} 2>/dev/null && exit 0; sleep 0.2; done; exit 1)"


def _run_keys(qtbot, *script: str, until=lambda: True) -> None:
    """Run xdotool commands one after another in the background (a modal dialog runs its
    own event loop inside the key handler: the test cannot type into it from this thread)
    and wait for them and ``until``. Should the keys miss, every modal dialog is rejected
    after 15 s and the test fails, instead of hanging in the dialog's event loop."""
    if shutil.which("xdotool") is None:
        pytest.fail("xdotool is needed for this test: apt-get install xdotool")
    rejected: list[str] = []

    def reject_modal():
        while (w := QtWidgets.QApplication.activeModalWidget()) is not None:
            rejected.append(w.windowTitle())
            w.reject() if isinstance(w, QtWidgets.QDialog) else w.close()

    guard = QtCore.QTimer()
    guard.setSingleShot(True)
    guard.timeout.connect(reject_modal)
    guard.start(15000)
    cmd = " && ".join(map(_retried, script))
    proc = subprocess.Popen(["bash", "-c", cmd])
    try:
        qtbot.waitUntil(lambda: proc.poll() is not None and until(), timeout=20000)
    finally:
        guard.stop()
        if proc.poll() is None:
            proc.kill()
    assert not rejected, f"the keys never closed {rejected}"
    assert proc.returncode == 0


def _focus(win, qtbot):
    x_focus(win, win.plotter)


def test_ctrl_s_on_an_untitled_scene_asks_for_a_name_and_saves_there(make_window, qtbot, tmp_path):
    win = make_window(_scene())
    win.model.set_feature(0, x=123.0)
    assert win.is_modified()
    _focus(win, qtbot)
    out = tmp_path / "mine.toml"
    _run_keys(
        qtbot,
        "key ctrl+s",
        "search --sync --onlyvisible --name 'Save scene' windowfocus --sync",
        f"type --delay 15 '{out}'",
        "key Return",
        until=lambda: win.path is not None,
    )
    assert load(out).features[0].x == 123.0
    assert not win.is_modified() and "mine.toml" in win.windowTitle()


def test_ctrl_o_with_unsaved_changes_asks_and_cancel_keeps_everything(make_window, qtbot, tmp_path):
    other = tmp_path / "other.toml"
    sc = _scene()
    sc.features[0].name = "elsewhere"
    from eyeviz.model.scene import save

    save(sc, other)
    win = make_window(_scene())
    win.model.set_feature(0, x=77.0)
    _focus(win, qtbot)
    _run_keys(
        qtbot,
        "key ctrl+o",
        "search --sync --onlyvisible --name 'Unsaved changes' windowfocus --sync",
        "key Escape",
        until=lambda: QtWidgets.QApplication.activeModalWidget() is None,
    )
    assert win.model.scene.features[0].x == 77.0 and win.is_modified()  # Cancel: nothing lost
    # again, and this time Discard, then the file in the open dialog
    _focus(win, qtbot)
    _run_keys(
        qtbot,
        "key ctrl+o",
        "search --sync --onlyvisible --name 'Unsaved changes' windowfocus --sync",
        "key alt+d",
        "search --sync --onlyvisible --name 'Open scene' windowfocus --sync",
        f"type --delay 15 '{other}'",
        "key Return",
        until=lambda: win.path == other,
    )
    assert win.model.scene.features[0].name == "elsewhere"
    assert not win.is_modified()
