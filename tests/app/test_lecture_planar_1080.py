"""The planar lecture (lecture.toml) full screen (F11) in presentation mode (F5), as a
lecturer gives it on a 1920 x 1080 screen (issue 32 item 11), real keys (xdotool) into
the real window: in every step the Selected feature panel's values show whole (they were
cut at the bottom: the value rows kept the height of the font before F5; and elided, the
dock as narrow as at the normal text size), the bitmaps
panel's four rows show whole, no feature sits under the title; after F5 on and off the
panel's rows fit its width again."""

import pytest
from test_presenting_real_x import _focus, _keys, _screen_size, window_manager  # noqa: F401

from eyeviz.app.panels.readout import ValueText
from eyeviz.model.scene import load
from eyeviz.resources import scene_path


def _values_whole(win) -> list[str]:
    """The readout's shown value texts cut: a widget lower than its lines need (cut at
    the bottom) or narrower than a line (elided, "...")."""
    cut = []
    for v in win.readout.findChildren(ValueText):
        if v.isVisible() and v.text():
            fm, lines = v.fontMetrics(), v.text().split("\n")
            if v.height() < fm.lineSpacing() * len(lines):
                cut.append(f"{v.text()!r}: {v.height()} px < {len(lines)} x {fm.lineSpacing()}")
            wide = max(fm.horizontalAdvance(t) for t in lines)
            if v.width() < wide:
                cut.append(f"{v.text()!r}: {v.width()} px wide < {wide}")
    return cut


def _lecture(make_window, qtbot):
    path = scene_path("lecture")
    win = make_window(load(path), path)
    win.resize(1280, 720)
    qtbot.waitUntil(lambda: win.width() == 1280, timeout=3000)
    _focus(win, qtbot)
    full = _screen_size(win)
    _keys(qtbot, "F11", until=lambda: win.isFullScreen() and win.size() == full)
    return win


@pytest.mark.slow
def test_each_step_shows_the_readout_the_bitmaps_and_the_features_whole(make_window, qtbot):
    win = _lecture(make_window, qtbot)
    _keys(qtbot, "F5", until=lambda: win.presenter.presenting)
    for step in range(len(win.model.scene.steps)):
        _keys(qtbot, "Next", until=lambda s=step: win.step_index == s)
        qtbot.wait(300)
        if win.readout.isVisible():
            assert _values_whole(win) == [], step + 1
        bm = win.bitmaps
        if bm.isVisible():
            last = bm._row_rect(3)  # the fourth row (Omega_B, whole eye)
            assert last.bottom() < bm.height(), (step + 1, last, bm.height())
        top = win.title_band_px()
        for f in win.model.scene.features:
            if win.model.scene.shows("features"):
                _, py = win.to_pixel(f.x, f.y + f.g, "main")  # the disc's top, y down
                assert py >= top - 1, (step + 1, f.name, py, top)


def test_f5_on_and_off_leaves_the_readout_whole(make_window, qtbot):
    win = _lecture(make_window, qtbot)
    _keys(qtbot, "F5", until=lambda: win.presenter.presenting)
    _keys(qtbot, "F5", until=lambda: not win.presenter.presenting)
    qtbot.wait(300)
    assert win.readout.isVisible()
    assert _values_whole(win) == []
    assert win.readout.width() >= win.readout.minimumSizeHint().width()
