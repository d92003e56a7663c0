"""Help > Keyboard shortcuts (F1) lists the 3D view's mouse and keys, and the 3D view's
"Mouse and keys" box is written from the same list (eyeviz.app.help.VIEW3D_KEYS)."""

from __future__ import annotations

import subprocess
from pathlib import Path

import pytest
from mouse import x_focus

from eyeviz.app import help as app_help
from eyeviz.app.view3d import PRESET_KEYS
from eyeviz.model.scene import load

SCENES = Path(__file__).resolve().parents[2] / "assets" / "scenes"


def _window3d(make_window, qtbot):
    win = make_window(load(SCENES / "sphere_teaching.toml"))
    assert win.host3d.active
    x_focus(win, win.host3d.view)
    return win


def _f1(win, qtbot):
    """A real F1 (xdotool's XTEST) into the window; the dialog it opens."""
    subprocess.run(["xdotool", "key", "--delay", "40", "F1"], check=True)
    qtbot.waitUntil(lambda: win.presenter.shortcuts_dialog is not None, timeout=5000)
    dlg = win.presenter.shortcuts_dialog
    qtbot.waitUntil(dlg.isVisible, timeout=5000)
    return dlg


def test_f1_lists_the_3d_views_mouse_and_keys(make_window, qtbot):
    win = _window3d(make_window, qtbot)
    rows = _f1(win, qtbot).rows()
    for what, keys in app_help.VIEW3D_KEYS:
        assert ("3D view", what, keys) in rows, (what, keys)
    keys = " | ".join(r[2] for r in rows if r[0] == "3D view")
    for key in ("Tab", "Shift+Up", "arrow keys", "Shift+ or Ctrl+left-drag", "background"):
        assert key in keys, key
    # the camera presets are the 3D view menu's actions: listed from them, with their keys
    for _name, text, key in PRESET_KEYS:
        assert ("3D view", text.replace("&", ""), key) in rows, (text, key)
    # the planar view's own rows are still there, after the actions'
    assert ("View (with the focus)", "Play / pause the trajectory", "Space") in rows


def test_the_mouse_and_keys_box_and_f1_come_from_one_list(make_window, qtbot, monkeypatch):
    win = _window3d(make_window, qtbot)
    box = win.host3d.show_help()
    text = box.text()
    box.close()
    for what, keys in app_help.VIEW3D_KEYS:  # every row of the list, in the box
        assert f"{keys[:1].upper()}{keys[1:]}: {what[:1].lower()}{what[1:]}." in text, keys
    for _name, label, key in PRESET_KEYS:
        assert f"{key} {label.replace('&', '')[:1].lower()}" in text, label
    assert "Ctrl+Z" in text and "line of sight" in text
    # a row added to the one list shows in both, with nothing else changed
    added = ("Do something new in the test", "Ctrl+Alt+F9")
    monkeypatch.setattr(app_help, "VIEW3D_KEYS", (*app_help.VIEW3D_KEYS, added))
    box = win.host3d.show_help()
    assert "Ctrl+Alt+F9: do something new in the test." in box.text()
    box.close()
    assert ("3D view", *added) in _f1(win, qtbot).rows()


@pytest.mark.parametrize("presets", [(), PRESET_KEYS])
def test_the_box_text_has_one_line_per_row(presets):
    text = app_help.view3d_help_text(presets)
    lines, notes = text.split("\n\n")
    n = len(app_help.VIEW3D_KEYS) + (1 if presets else 0)
    assert len(lines.split("\n")) == n
    assert notes == " ".join(app_help.VIEW3D_NOTES)
