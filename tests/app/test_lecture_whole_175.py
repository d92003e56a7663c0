"""The spherical lecture at 175 % in a 1280 x 720 window in presentation mode (F5), every
step (issue 32, the lecture-hall items left open): nothing cut, nothing elided, nothing
scrolled sideways. Before, at F11 + F5 + 175 % on a 1280 x 720 screen:

- the step's caption (42 pt, six lines in step 7) took 420 px and left the 3D view 165 px;
- the Balls table scrolled sideways (its names cut at the left: "bal"), kept the height
  of three rows at 100 % (one ball and half of the next shown);
- the Facets panel's lines read "nside 8, 768 facets …" and "lit: A 15, B 15; 'targ…";
- the status bar's line was cut at "facets lit A 15  B";
- the 3D view's title read "Spherical c…", its side note "from front, right,…", the
  close-up's caption "768 facet…".

Real keys (xdotool) into the real window: one window walks the steps once, and every
check of the lecture at 175 % reads each step (those of test_lecture_names_175,
test_lecture_text_fits_175 and test_lecture_balls_175 too)."""

from collections import Counter

import numpy as np
import pytest
from PyQt5 import QtWidgets
from test_lecture_balls_175 import balls_checked, check_balls
from test_lecture_names_175 import _box, check_names, lecture_at_175, names_checked
from test_lecture_text_fits_175 import check_text_fits, text_fits_checked
from test_presenting_real_x import _keys, window_manager  # noqa: F401

from eyeviz.app.launch import APP_FONT_PT
from eyeviz.app.steps import CAPTION_SHARE
from eyeviz.model.labels3d import discs
from eyeviz.model.scene import load
from eyeviz.render.vtk.scene3d import camera_of


def _vtk_texts(host) -> dict[str, str]:
    """The 3D view's texts as drawn: its title, side note and the close-up's caption (a
    caption that gave way is transparent: not drawn)."""
    a = host.actors
    cap = a.eyes_caption
    shown = cap.GetVisibility() and cap.GetTextProperty().GetOpacity() > 0
    return {
        "title": str(a.title.GetInput() or "") if a.title.GetVisibility() else "",
        "side note": str(host.side.actor.GetInput() or ""),
        "close-up caption": str(cap.GetInput() or "") if shown else "",
    }


def check_whole(win, step: int, tally: Counter) -> None:
    """One step: the caption's share, the 3D view's texts, the status bar's line, the
    Facets panel's lines and the Balls table's cells whole, nothing cut or elided."""
    host = win.host3d
    at = step + 1
    assert win.height() == 720, (at, win.height())  # the status bar on the screen
    # the caption at most CAPTION_SHARE of the window, unless at the window's own size
    bar = win.caption_bar
    floor = APP_FONT_PT * win.presenter.effective_scale
    small = bar.font().pointSizeF() <= floor + 1e-6
    assert bar.height() <= CAPTION_SHARE * win.height() or small, (at, bar.height())
    assert bar.font().pointSizeF() >= floor - 1e-6, at  # never smaller than the rest
    # the 3D view: no text cut with "…"
    for name, text in _vtk_texts(host).items():
        assert "…" not in text, (at, name, text)
    # the status bar's line whole
    sb = win.statusBar()
    msg = sb.currentMessage()
    assert sb.fontMetrics().horizontalAdvance(msg) <= sb.width() - 8, (at, msg)
    tally["statuses"] += bool(msg)
    # the Facets panel's lines, as shown: none elided
    maps = host.bitmaps
    if maps.isVisible():
        shown = QtWidgets.QLabel.text(maps.counts)  # the lines drawn (not the whole text)
        assert "…" not in shown, (at, shown)
        fm = maps.counts.fontMetrics()
        for line in shown.split("\n"):
            assert fm.horizontalAdvance(line) <= maps.counts.contentsRect().width(), line
        tally["maps_lines"] += len([x for x in shown.split("\n") if x])
    # the Balls table: no sideways scroll, every shown cell whole, every row whole
    t = host.readout.table
    if t.isVisible():
        tally["tables"] += 1
        assert not t.horizontalScrollBar().isVisible(), at
        head = t.horizontalHeader()
        assert sum(head.sectionSize(j) for j in range(t.columnCount())
                   if not t.isColumnHidden(j)) <= t.viewport().width(), at  # fmt: skip
        fm, hfm = t.fontMetrics(), head.fontMetrics()
        for j in range(t.columnCount()):
            if t.isColumnHidden(j):
                continue
            words = [t.horizontalHeaderItem(j).text()]
            words += [t.item(i, j).text() for i in range(t.rowCount()) if t.item(i, j)]
            room = head.sectionSize(j) - (24 if j == 0 else 0)  # the swatch's room
            for k, w in enumerate(words):
                wide = (hfm if k == 0 else fm).horizontalAdvance(w)
                assert wide <= room, (at, j, w, wide, room)
        for i in range(t.rowCount()):  # each ball's row whole in the table
            bottom = t.rowViewportPosition(i) + t.rowHeight(i)
            assert bottom <= t.viewport().height(), (at, i, bottom, t.viewport().height())
        # r, azimuth and elevation, the step's words, are never the columns given way
        assert not any(t.isColumnHidden(j) for j in range(5)), at


def check_close_up(win, step: int, tally: Counter) -> None:
    """In the close-up (a 300 px pane at 175 %) each eye's name is clearly its own: its
    middle nearer its eye's centre than 0.75 times the other eye's distance. In step 6
    "eye A" and "eye B" both sat between the eyes, one over the other; where the whole
    names cannot be placed so, they read "A" and "B"."""
    host = win.host3d
    boxes, at = host.actors.eye_name_boxes, host.actors.eye_name_anchors
    labs = host.actors.eyes.labels
    assert [lab.GetInput() for lab in labs] in (["eye A", "eye B"], ["A", "B"]), step + 1
    if np.linalg.norm(at[0] - at[1]) < 1.0:  # one eye behind the other: no side
        return
    cap = host.actors.eyes_caption  # drawn: never over an eye ("each" over eye A, step 7)
    if cap.GetInput() and cap.GetTextProperty().GetOpacity() > 0:
        x0, y0, x1, y1 = _box(cap, host.actors.eyes_ren)
        w, h = host.actors.eyes_ren.GetSize()
        _, rad = discs(camera_of(host.actors.eyes_ren), *_eye_discs(host), float(w), float(h))
        for (cx, cy), r in zip(at, rad, strict=True):
            nx, ny = min(max(cx, x0), x1), min(max(cy, y0), y1)
            assert np.hypot(nx - cx, ny - cy) >= r, (step + 1, (x0, y0, x1, y1), cx, cy, r)
        tally["close_up_captions"] += 1
    mid = np.column_stack([boxes[:, 0] + boxes[:, 2], boxes[:, 1] + boxes[:, 3]]) / 2
    for k in range(2):
        own, other = (float(np.linalg.norm(mid[k] - at[j])) for j in (k, 1 - k))
        assert own <= 0.75 * other, (step + 1, labs[k].GetInput(), own, other)
    tally["close_up_checked"] += 1


@pytest.mark.slow
def test_every_step_at_175_percent_shows_its_words_whole_and_its_names_clear(make_window, qtbot):
    """One window, one walk through the lecture's steps at 175 %, every step read back by
    each check: this module's (words whole, the close-up's names) and those of
    test_lecture_names_175, test_lecture_text_fits_175 and test_lecture_balls_175 (the
    checks only read the window: they walked a window each, 8 s of a core apiece). Then,
    at the last step, a column that gave way at 175 % comes back at 100 % (Ctrl+0): the
    table keeps nothing hidden that fits."""
    win, path = lecture_at_175(make_window, qtbot)
    tally: Counter = Counter()
    for step in range(len(load(path).steps)):
        _keys(qtbot, "Next", until=lambda s=step: win.step_index == s)
        qtbot.wait(400)
        win.host3d.draw()
        for check in (check_whole, check_close_up, check_names, check_text_fits, check_balls):
            check(win, step, tally)
    # what each check looks at was shown, and checked, in enough steps
    assert tally["tables"] >= 1 and tally["maps_lines"] >= 4 and tally["statuses"] >= 7, tally
    assert tally["close_up_checked"] >= 6 and tally["close_up_captions"] >= 3, tally
    names_checked(tally)
    text_fits_checked(tally)
    balls_checked(tally)
    # the Balls table's columns come back when there is room
    t = win.host3d.readout.table
    qtbot.waitUntil(t.isVisible, timeout=3000)
    qtbot.wait(300)
    assert any(t.isColumnHidden(j) for j in range(t.columnCount()))  # some gave way
    assert "not shown at this width" in t.toolTip()
    _keys(qtbot, "ctrl+0", until=lambda: win.presenter.scale == 1.0)
    _keys(qtbot, "F5", until=lambda: not win.presenter.presenting)
    win.resize(1600, 900)
    qtbot.waitUntil(lambda: win.width() == 1600, timeout=3000)
    qtbot.waitUntil(
        lambda: not any(t.isColumnHidden(j) for j in range(t.columnCount())), timeout=5000
    )
    assert t.toolTip() == ""


def _eye_discs(host):
    """The eyes' centres and radii (model units) as the close-up draws them."""
    s = host.actors.surface
    return np.asarray(s.centres, float), np.full(len(s.centres), float(s.radius))
