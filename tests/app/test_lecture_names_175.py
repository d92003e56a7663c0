"""The spherical lecture at 175 % in a 1280 x 720 window in presentation mode (issue 32
item 3): in every step no ball's name touches the 3D view's title or its side note (they
printed over the title in steps 6 and 7; then, with the title's box taken 57 px under the
view, "target" still did in step 7; where no place is clear the title now gives way), nor
the close-up's names each other or its caption (item 4).
Checked in every step of test_lecture_whole_175's walk (real keys, xdotool, into the real
window), with the other checks of the lecture at 175 %: one window and one walk for all."""

from collections import Counter

import numpy as np
from test_lecture3d import _focus3d
from test_presenting_real_x import _keys

from eyeviz.model.scene import load
from eyeviz.resources import scene_path


def _box(actor, ren) -> tuple[float, float, float, float]:
    """A text actor's box in its viewport's pixels (x0, y0, x1, y1, y up). VTK gives the
    box relative to the actor's anchor (the title's from -57 to 0 px: under the view);
    the anchor is its normalized-viewport position times the viewport's size."""
    b = [0.0] * 4
    actor.GetBoundingBox(ren, b)
    w, h = ren.GetSize()
    px, py = actor.GetPosition()
    ax, ay = px * w, py * h
    return ax + b[0], ay + b[2], ax + b[1], ay + b[3]


def _overlap(a, b) -> bool:
    return min(a[2], b[2]) > max(a[0], b[0]) and min(a[3], b[3]) > max(a[1], b[1])


def lecture_at_175(make_window, qtbot):
    """sphere_lecture in a 1280 x 720 window, presenting (F5), its text at 175 %
    (Ctrl+= four times); returns (the window, the scene's path)."""
    path = scene_path("sphere_lecture")
    win = make_window(load(path), path)
    win.resize(1280, 720)
    qtbot.waitUntil(lambda: win.width() == 1280, timeout=3000)
    _focus3d(win, qtbot)
    _keys(qtbot, "F5", until=lambda: win.presenter.presenting)
    for _ in range(4):
        _keys(qtbot, "ctrl+equal")
    qtbot.waitUntil(lambda: win.presenter.scale == 1.75, timeout=3000)
    return win, path


def check_names(win, step: int, tally: Counter) -> None:
    """One step of the walk at 175 % (test_lecture_whole_175): names clear of the title, the
    side note and each other; the close-up's names clear of each other and its caption."""
    host = win.host3d
    ren = host.actors.scene_ren
    # the panels a step shows fit the window (the Facets panel's 501 px minimum at
    # 175 % grew it to 824 px in step 8: the status bar off a 1280 x 720 screen)
    assert win.height() == 720, (step + 1, win.height())
    t = host.readout.table
    if t.isVisible():  # numbers whole, not "..." in every cell (step 8 shows it)
        # and its rows shown: a row whole, not the header alone (step 8 showed no row)
        bottom = t.rowViewportPosition(0) + t.rowHeight(0)
        assert bottom <= t.viewport().height(), (step + 1, bottom, t.viewport().height())
        head, fm = t.horizontalHeader(), t.fontMetrics()
        for j in range(1, t.columnCount()):
            if t.isColumnHidden(j):  # gave way for want of width (not cut)
                continue
            for i in range(t.rowCount()):
                item = t.item(i, j)
                if item is not None and item.text():
                    wide = fm.horizontalAdvance(item.text())
                    assert wide <= head.sectionSize(j), (step + 1, item.text())
    title, side = _box(host.actors.title, ren), _box(host.side.actor, ren)
    shown = [b for b in host.actors.name_boxes if np.isfinite(b).all()]
    # no two shown names over each other ("above" over "below" in step 7's 234 px view)
    for i, a in enumerate(shown):
        for b in shown[i + 1 :]:
            assert not _overlap(a, b), (step + 1, a, b)
    for box in shown:
        assert not _overlap(box, title), (step + 1, box, title)
        assert not _overlap(box, side), (step + 1, box, side)
        tally["names"] += 1
    # the close-up's names: clear of each other and of its caption where it is shown
    # ("eye A" printed over the caption in steps 6-8, over "eye B" in step 8)
    eyes_ren, cap = host.actors.eyes_ren, host.actors.eyes_caption
    names = [b for b in host.actors.eye_name_boxes if np.isfinite(b).all()]
    assert len(names) == 2, (step + 1, names)
    assert not _overlap(names[0], names[1]), (step + 1, names)
    # each name nearer its own eye than the other's ("eye A" sat under eye B in step 6)
    at = host.actors.eye_name_anchors
    for k, box in enumerate(names):
        mid = np.array([box[0] + box[2], box[1] + box[3]]) / 2
        near = np.linalg.norm(at - mid, axis=1)
        assert near[k] < near[1 - k], (step + 1, k, box, at)
    if cap.GetVisibility() and cap.GetInput() and cap.GetTextProperty().GetOpacity() > 0:
        for box in names:
            assert not _overlap(box, _box(cap, eyes_ren)), (step + 1, box)


def names_checked(tally: Counter) -> None:
    assert tally["names"] >= 8  # names were shown and checked
