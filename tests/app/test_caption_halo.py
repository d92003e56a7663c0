"""The planar view's title and tangents note (issue 24) sit on a background box: geometry
panned under them never crosses their letters. Read from the window's pixels: a feature
wider than the view is orange everywhere but inside the two text boxes."""

import numpy as np
from PyQt5 import QtCore

from eyeviz.app.screenshot import qimage_to_array
from eyeviz.model.scene import Eyes, Feature, Scene, View

ORANGE = "#D55E00"


def _scene():
    # the eyes at the origin, out of the view; one ball covering the whole view
    return Scene(
        Eyes(40.0, 20.0, 720),
        [Feature("wall", 0.0, 5000.0, 1500.0, ORANGE)],
        ["eyes", "features", "tangents"],
        view=View((0.0, 5000.0), 1200.0),
        title="A title over a feature",
    )


def _box(win, actor) -> tuple[int, int, int, int]:
    """The text actor's box in window pixels (x0, y0, x1, y1), y down."""
    bb = [0.0] * 4
    actor.GetBoundingBox(win.main_ren, bb)  # display pixels from the actor's anchor
    ax, ay = actor.GetActualPositionCoordinate().GetComputedDisplayValue(win.main_ren)
    h = win.ren_win.GetSize()[1]
    origin = win.plotter.mapTo(win, QtCore.QPoint(0, 0))
    x0, x1, y0, y1 = bb[0] + ax, bb[1] + ax, bb[2] + ay, bb[3] + ay
    return (
        origin.x() + int(x0),
        origin.y() + int(h - y1),
        origin.x() + int(np.ceil(x1)),
        origin.y() + int(np.ceil(h - y0)),
    )


def _orange(rgb: np.ndarray) -> np.ndarray:
    """Pixels of the feature's fill or outline (red well above blue)."""
    return rgb[..., 0].astype(int) - rgb[..., 2].astype(int) > 60


def test_the_title_and_the_tangents_note_are_boxed_over_geometry(make_window):
    win = make_window(_scene())
    win.model.select(0)
    win.render()
    note = win.actors.layer("tangents").text_actor
    assert note.GetVisibility() and "tangents" in note.GetInput()
    img = qimage_to_array(win.grab_image())[..., :3]
    for actor in (win.title_actor, note):
        x0, y0, x1, y1 = _box(win, actor)
        assert x1 - x0 > 100 and y1 - y0 > 10, (x0, y0, x1, y1)
        inside = img[y0 + 2 : y1 - 2, x0 + 2 : x1 - 2]
        assert _orange(inside).mean() < 0.002, actor.GetInput()
        # the feature is there, just right of the box (the box hides it)
        beside = img[y0 + 2 : y1 - 2, x1 + 4 : x1 + 40]
        assert _orange(beside).mean() > 0.5
