"""The spherical lecture at 175 % in a 1280 x 720 window in presentation mode (issue 32
items 3-4): no text is cut at its pane's edges. The close-up's caption (614 px of text in
a 305-355 px pane) was cut at the right; the Mollweide maps' titles ("eye A (left), seen
from inside") at both sides of the 390 px dock in steps 4-7; the 3D view's side note
("seen from front, right, above") at the right of its 533 px view in steps 2-5.
Checked in every step of test_lecture_whole_175's walk (real keys, xdotool, into the real
window), with the other checks of the lecture at 175 %: one window and one walk for all."""

from collections import Counter

from matplotlib.text import Text
from test_lecture_names_175 import _box


def check_text_fits(win, step: int, tally: Counter) -> None:
    """One step of the walk at 175 % (test_lecture_whole_175): the close-up's caption, the
    side note and the maps' titles inside their panes."""
    host = win.host3d
    ren, cap = host.actors.eyes_ren, host.actors.eyes_caption
    if cap.GetVisibility() and cap.GetInput() and cap.GetTextProperty().GetOpacity() > 0:
        x0, _, x1, _ = _box(cap, ren)
        assert 0 <= x0 and x1 <= ren.GetSize()[0], (step + 1, x0, x1, ren.GetSize())
        tally["fit_captions"] += 1
    side, scene_ren = host.side.actor, host.actors.scene_ren
    if side.GetVisibility() and side.GetInput():  # "seen from front, right, above"
        x0, _, x1, _ = _box(side, scene_ren)
        assert 0 <= x0 and x1 <= scene_ren.GetSize()[0], (step + 1, side.GetInput(), x1)
        tally["fit_notes"] += 1
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
            tally["fit_titles"] += 1


def text_fits_checked(tally: Counter) -> None:
    captions, titles, notes = tally["fit_captions"], tally["fit_titles"], tally["fit_notes"]
    assert captions >= 4 and titles >= 8 and notes >= 8, (captions, titles, notes)  # checked
