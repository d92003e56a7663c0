"""The spherical lecture at 175 % in a 1280 x 720 window in presentation mode (issue 32
items 3-4): no text is cut at its pane's edges. The close-up's caption (614 px of text in
a 305-355 px pane) was cut at the right; the Mollweide maps' titles ("eye A (left), seen
from inside") at both sides of the 390 px dock in steps 4-7; the 3D view's side note
("seen from front, right, above") at the right of its 533 px view in steps 2-5.
Real keys (xdotool) into the real window."""

import pytest
from matplotlib.text import Text
from test_lecture_names_175 import _box, lecture_at_175
from test_presenting_real_x import _keys, window_manager  # noqa: F401

from eyeviz.model.scene import load


@pytest.mark.slow
def test_caption_and_map_titles_fit_their_panes_at_175_percent(make_window, qtbot):
    win, path = lecture_at_175(make_window, qtbot)
    host = win.host3d
    captions = titles = notes = 0
    for step in range(len(load(path).steps)):
        _keys(qtbot, "Next", until=lambda s=step: win.step_index == s)
        qtbot.wait(300)
        host.draw()
        ren, cap = host.actors.eyes_ren, host.actors.eyes_caption
        if cap.GetVisibility() and cap.GetInput() and cap.GetTextProperty().GetOpacity() > 0:
            x0, _, x1, _ = _box(cap, ren)
            assert 0 <= x0 and x1 <= ren.GetSize()[0], (step + 1, x0, x1, ren.GetSize())
            captions += 1
        side, scene_ren = host.side.actor, host.actors.scene_ren
        if side.GetVisibility() and side.GetInput():  # "seen from front, right, above"
            x0, _, x1, _ = _box(side, scene_ren)
            assert 0 <= x0 and x1 <= scene_ren.GetSize()[0], (step + 1, side.GetInput(), x1)
            notes += 1
        maps = host.bitmaps
        if maps.isVisible():
            maps.canvas.draw()
            fig = maps.fig
            # the maps' titles: "eye A (left), seen from inside" in its whole form
            for t in fig.findobj(Text):
                if not str(t.get_url() or t.get_text()).startswith("eye "):
                    continue
                box = t.get_window_extent(maps.canvas.get_renderer())
                assert t.get_text(), step + 1
                assert 0 <= box.x0 and box.x1 <= fig.bbox.width, (step + 1, t.get_text(), box)
                titles += 1
    assert captions >= 4 and titles >= 8 and notes >= 8, (
        captions,
        titles,
        notes,
    )  # shown and checked
