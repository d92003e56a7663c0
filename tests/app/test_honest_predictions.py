"""Issue 10 item 4 in the app: an estimator made for other eyes is greyed with one short
line and draws no ring; a feature outside an estimator's r range is flagged."""

import numpy as np

from eyeviz.model.scene import Eyes, Feature, Scene, View

LAYERS = ["eyes", "bfv", "features", "bitmaps", "readout", "labels", "predictions"]


def scene(est=("analytic", "compact"), x=300.0, y=3000.0):
    return Scene(
        Eyes(40.0, 20.0, 720),
        [Feature("target", x, y, 60.0, "#D55E00")],
        list(LAYERS),
        estimators=list(est),
        view=View((0.0, 2300.0), 7000.0),
    )


def test_changing_h_greys_compact_and_removes_its_ring(make_window):
    win = make_window(scene())
    win.model.select(0)
    assert "compact" in win.overlays.ghosts and "r " in win.readout.texts["pred:compact"]
    win.model.set_eyes(80.0, 20.0, 720)
    win.model.select(0)
    note = win.readout.texts["pred:compact"]
    assert note == "trained for h = 40, l = 20, m = 720"
    assert "compact" not in win.overlays.ghosts  # no ring for other eyes
    assert "analytic" in win.overlays.ghosts  # analytic answers for any eyes
    assert np.isfinite(win.overlays.ghosts["analytic"][0]).all()
    # for these eyes (h = 80), not the paper's: near the truth, not at half its distance
    assert abs(np.hypot(*win.overlays.ghosts["analytic"][0]) / np.hypot(300, 3000) - 1) < 0.1
    box = win.picker.boxes["compact"]
    assert "8a8a8a" in box.styleSheet() and "trained for h = 40" in win.picker.note.text()
    assert win.picker.boxes["analytic"].styleSheet() == ""
    win.model.set_eyes(40.0, 20.0, 720)  # back to the design: an answer again
    win.model.select(0)
    assert "compact" in win.overlays.ghosts and "Δr" in win.readout.texts["pred:compact"]


def test_a_feature_nearer_than_the_range_is_flagged(make_window):
    win = make_window(scene(est=("analytic",), x=0.0, y=777.0))
    win.model.select(0)
    text = win.readout.texts["pred:analytic"]
    assert "r outside [1000, 5000]" in text  # the estimator's range, one short line
