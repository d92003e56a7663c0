"""A feature overlapping an eye (issue 24): drawn over the eye, also in the inset, which
frames it whole, and a red warning in the readout instead of a grey "no / yes"."""

import numpy as np
from PyQt5 import QtCore, QtGui

from eyeviz.model.camera import eye_overlaps, fit_inset, to_pixel
from eyeviz.model.scene import Eyes, Feature, Scene, View
from eyeviz.render.vtk.style import FILL_ALPHA, hex_rgb

INSIDE = Feature("inside", 45.0, 6.0, 9.0, "#0072B2")  # its centre lies in eye B


def _scene():
    return Scene(
        Eyes(40.0, 20.0, 36),
        [Feature("far", 0.0, 1500.0, 50.0, "#D55E00"), INSIDE],
        ["eyes", "bfv", "features", "readout", "labels"],
        view=View((0.0, 700.0), 3000.0),
    )


def test_eye_overlaps_names_the_eye_and_the_inset_frames_the_disc_whole():
    sc = _scene()
    assert eye_overlaps(sc.eyes, sc.features) == [(1, "B")]
    from eyeviz.model.camera import Viewport

    vp = Viewport(0.0, 0.0, 240.0, 160.0)
    plain = fit_inset(sc.eyes, vp)
    out = Feature("out", 300.0, 40.0, 30.0)  # overlaps nothing: the inset is unchanged
    assert fit_inset(sc.eyes, vp, [out]) == plain
    far = Feature("edge", 70.0, 30.0, 25.0)  # overlaps B and reaches beyond the plain inset
    v = fit_inset(sc.eyes, vp, [far])
    for x, y in ((far.x + far.g, far.y), (far.x, far.y + far.g), (-60.0, 0.0)):
        px, py = to_pixel(v, vp, x, y)
        assert 0 <= px <= vp.width and 0 <= py <= vp.height, (x, y)


def _inset_pixel(win, x, y):
    vp = win.viewport("inset")
    px, py = to_pixel(win.inset_view, vp, x, y)
    img = win.grab_image()
    top_left = win.plotter.mapTo(win, QtCore.QPoint(0, 0))
    c = QtGui.QColor(img.pixel(top_left.x() + round(px), top_left.y() + round(py)))
    return np.array([c.red(), c.green(), c.blue()])


def test_a_feature_inside_an_eye_is_drawn_over_it_in_the_inset_with_a_warning(make_window):
    win = make_window(_scene())
    win.fit_inset()
    win.model.select(1)
    assert win.inset_shown
    # a point of the disc inside eye B (off its centre dot and the sight lines): the
    # feature's tint, not the eye's grey
    col = np.array(hex_rgb(INSIDE.color), float)
    tint = np.round(FILL_ALPHA * col + (1 - FILL_ALPHA) * 255)
    got = _inset_pixel(win, INSIDE.x - 0.6 * INSIDE.g, INSIDE.y - 0.4 * INSIDE.g)
    assert np.abs(got - tint).max() <= 12, (got, tint)
    text = win.readout.texts["overlap"]
    assert text.startswith("⚠") and "inside an eye" in text
