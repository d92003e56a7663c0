"""The app with 10^4 features (issue 25): a drag is one undo step that undo restores, with
few Scene copies, and the feature table is not rebuilt row by row while it lasts."""

import math

import numpy as np
from mouse import drag, pixel_of

from eyeviz.model import scene as scene_mod
from eyeviz.model.scene import OKABE_ITO, Eyes, Feature, Scene, View

N = 10_000


def big_scene() -> Scene:
    rng = np.random.default_rng(3)
    r = rng.uniform(1000, 5000, N)
    phi = rng.uniform(math.radians(40), math.radians(140), N)
    g = rng.uniform(20, 300, N)
    fs = [
        Feature(
            f"f{i}",
            float(r[i] * math.cos(phi[i])),
            float(r[i] * math.sin(phi[i])),
            float(g[i]),
            OKABE_ITO[i % 7],
        )
        for i in range(N)
    ]
    fs[-1] = Feature("dragged", 0.0, 1500.0, 50.0, OKABE_ITO[0])  # on top: the press takes it
    layers = ["eyes", "bfv", "features", "bitmaps", "readout", "labels"]
    return Scene(Eyes(40.0, 20.0, 720), fs, layers, [], View((0.0, 2600.0), 9000.0))


def test_drag_at_ten_thousand_features_is_one_undo_step(make_window, monkeypatch):
    win = make_window(big_scene())
    before = win.model.scene.copy()
    full_refreshes = []
    panel = win.features_panel
    real_refresh = panel.refresh

    def refresh(index=None):
        if index is None:
            full_refreshes.append(win.model.live_open)
        real_refresh(index)

    monkeypatch.setattr(panel, "refresh", refresh)
    copies = []
    real_copy = scene_mod.Scene.copy
    monkeypatch.setattr(scene_mod.Scene, "copy", lambda s: copies.append(1) or real_copy(s))
    drag(win, pixel_of(win, 0.0, 1500.0), pixel_of(win, -300.0, 2000.0), steps=6)
    f = win.model.scene.features[-1]
    u = win.units_per_px()
    assert abs(f.x - -300.0) <= 2 * u and abs(f.y - 2000.0) <= 2 * u
    assert win.model.scene.features[:-1] == before.features[:-1]
    assert win.undo_stack.count() == 1
    # begin_live, end_live and set_scene (the push's redo): no copy per frame
    assert len(copies) <= 3, len(copies)
    assert not any(full_refreshes), "the table was rebuilt during the drag"
    # the merged discs hold every feature but the dragged (selected) one
    assert win.model.selected == N - 1
    assert len(win.actors.features.verts) == N - 1
    win.undo_stack.undo()
    assert win.model.scene.features == before.features
    assert win.model.scene.eyes == before.eyes and win.model.scene.layers == before.layers
    sel = win.model.selected
    live = win.actors.features.live_fill
    if sel == N - 1:  # the selection stays on the dragged feature: its live disc is back
        np.testing.assert_allclose(live.GetPosition()[:2], [0.0, 1500.0])
    win.undo_stack.redo()
    assert win.model.scene.features[-1].x == f.x
