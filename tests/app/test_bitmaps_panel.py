"""The bitmaps panel (eyeviz/app/panels/bitmaps.py): strips drawn in numpy and blitted,
texts and labels laid out once (issue 12, drag latency); what it shows is unchanged."""

import numpy as np
from hypothesis import given
from hypothesis import strategies as st
from PyQt5 import QtGui
from PyQt5.QtTest import QTest

from eyeviz.app.panels.bitmaps import _columns, _interval_runs, _runs_text
from eyeviz.core.geometry import intervals_to_bitmap
from eyeviz.model.scene import Eyes, Feature, Scene, View

LAYERS = ["eyes", "bfv", "features", "bitmaps", "readout", "labels"]


def _text_from_bits(lo: int, hi: int, m: int) -> str:
    k = np.flatnonzero(intervals_to_bitmap(lo, hi, m, m // 2))
    if k.size == 0:
        return "none"
    gaps = np.flatnonzero(np.diff(k) > 1)
    if gaps.size == 0:
        return f"[{k[0]}, {k[-1]}]"
    return f"[{k[0]}, {k[gaps[0]]}] ∪ [{k[gaps[0] + 1]}, {k[-1]}]"


@given(st.integers(2, 500), st.data())
def test_half_strip_text_is_the_lit_indices_the_networks_see(half, data):
    m = 2 * half
    lo = data.draw(st.integers(0, m - 1))
    hi = data.draw(st.integers(lo, lo + m - 1))
    assert _runs_text(_interval_runs((lo, hi), m, False)) == _text_from_bits(lo, hi, m)


@given(st.integers(1, 400), st.integers(1, 900), st.data())
def test_columns_show_every_cell_and_every_lit_one(n, width, data):
    owner = np.array(data.draw(st.lists(st.integers(-1, 3), min_size=n, max_size=n)))
    cols = _columns(owner, width)
    if n <= width:  # each cell spans >= 1 column, in order
        assert cols.shape == (width,)
        idx = (np.arange(width) * n) // width
        np.testing.assert_array_equal(cols, owner[idx])
        assert set(idx.tolist()) == set(range(n))
    else:  # a column holds several cells: lit wins
        assert cols.shape == (width,)
        starts = (np.arange(width) * n) // width
        lit = np.maximum.reduceat(owner, starts) >= 0
        np.testing.assert_array_equal(cols >= 0, lit)


def test_strip_pixels_are_each_cells_owner_with_the_selection_outlined(make_window):
    fs = [
        Feature("left", -500.0, 1500.0, 200.0, "#0072B2"),
        Feature("mid", 0.0, 2000.0, 300.0, "#D55E00"),
    ]
    win = make_window(Scene(Eyes(40.0, 20.0, 16), fs, LAYERS, view=View((0, 1500), 6000)))
    win.model.select(1)
    QTest.qWait(50)
    panel = win.bitmaps
    img = panel.grab().toImage()
    label_w, right_w, row_h = panel._geometry(panel.fontMetrics())
    width = panel.width() - right_w - label_w
    st_ = win.model.state
    colors = {-1: "#e1e1e1", 0: "#0072b2", 1: "#d55e00"}
    for r, (eye, whole) in enumerate(panel.ROWS):
        own = panel.strips[(eye, whole)]
        n = own.shape[0]
        y = 4 + r * row_h + 3 + 5  # above the index text, below the outline's edge
        for k in range(n):
            x = label_w + int((k + 0.5) * width / n)
            got = QtGui.QColor(img.pixel(x, y)).name()
            assert got == colors[int(own[k])], (eye, whole, k, got)
        lo, hi = (
            (int(st_.LA[1]), int(st_.RA[1])) if eye == "A" else (int(st_.LB[1]), int(st_.RB[1]))
        )
        runs = _interval_runs((lo, hi), st_.m, whole)
        outline = QtGui.QColor("#d55e00").darker(130).name()
        for a, _ in runs:
            xa = label_w + int(a * width / n)
            assert QtGui.QColor(img.pixel(xa, y)).name() == outline
