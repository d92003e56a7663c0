"""The backdrop of the merged discs (issue 25, eyeviz/render/vtk/backdrop.py) in a real
window: a drag over thousands of features reuses the kept discs at every frame, and what
it shows equals, pixel for pixel, the same state drawn with every disc in the main
renderer; a real drag ends where the pointer did and undo restores the scene."""

import math

import numpy as np
from PyQt5 import QtCore
from PyQt5.QtTest import QTest
from vtkmodules.util.numpy_support import vtk_to_numpy
from vtkmodules.vtkRenderingCore import vtkWindowToImageFilter

from eyeviz.app.screenshot import qimage_to_array
from eyeviz.model import interactions
from eyeviz.model.scene import OKABE_ITO, Eyes, Feature, Scene, View
from eyeviz.render.vtk.layers.features import BACKDROP_MIN_FEATURES

N = 2_000
K = 1_000  # the dragged feature: discs above it (later) and under it (earlier) overlap it
X0, Y0, G0 = 0.0, 1500.0, 150.0


def scene() -> Scene:
    """N random discs away from the dragged one, one disc over it and one under it."""
    rng = np.random.default_rng(11)
    fs: list[Feature] = []
    while len(fs) < N - 3:
        r, phi = rng.uniform(1000, 5000), rng.uniform(math.radians(40), math.radians(140))
        x, y, g = r * math.cos(phi), r * math.sin(phi), rng.uniform(20, 300)
        if math.hypot(x - X0, y - Y0) > g + 900:  # the drag's neighbourhood stays clear
            fs.append(Feature(f"f{len(fs)}", x, y, g, OKABE_ITO[len(fs) % 7]))
    fs.insert(0, Feature("under", X0 + 250.0, Y0 + 150.0, 140.0, OKABE_ITO[2]))
    fs.insert(K, Feature("dragged", X0, Y0, G0, OKABE_ITO[0]))
    fs.append(Feature("over", X0 + 200.0, Y0 - 50.0, 120.0, OKABE_ITO[4]))
    layers = ["eyes", "bfv", "features", "labels", "tangents", "ambiguity"]
    return Scene(Eyes(40.0, 20.0, 720), fs, layers, [], View((0.0, 2600.0), 6000.0))


def view_pixels(win) -> np.ndarray:
    """The VTK view as rendered now (one render, read back as eyeviz.app.screenshot does)."""
    win.render()
    w2i = vtkWindowToImageFilter()
    w2i.SetInput(win.ren_win)
    w2i.ShouldRerenderOff()
    w2i.SetInputBufferTypeToRGB()
    w2i.ReadFrontBufferOff()
    w2i.Update()
    data = w2i.GetOutput()
    w, h, _ = data.GetDimensions()
    return vtk_to_numpy(data.GetPointData().GetScalars()).reshape(h, w, 3).copy()


def patch_colour(win, pixels: np.ndarray, x: float, y: float) -> np.ndarray:
    """The commonest colour of the 5 x 5 pixels about model point (x, y)."""
    px, py = win.to_pixel(x, y)
    h = pixels.shape[0]
    r, c = h - 1 - round(py), round(px)  # VTK's rows run bottom to top
    patch = pixels[r - 2 : r + 3, c - 2 : c + 3].reshape(-1, 3)
    values, counts = np.unique(patch, axis=0, return_counts=True)
    return values[counts.argmax()]


def frame_after(win, app, move, k=0) -> None:
    """Send ``move`` and wait for the frame that draws it."""
    before = win.plotter.frames
    move()
    for _ in range(200):
        app.processEvents()
        if win.plotter.frames > before and not win._frame_pending:
            return
    raise AssertionError(f"no frame was drawn after move {k}")


def test_a_drag_frame_over_the_backdrop_equals_the_full_render(make_window):
    from PyQt5.QtWidgets import QApplication

    assert N >= BACKDROP_MIN_FEATURES  # this scene's discs go to the backdrop
    app = QApplication.instance()
    win = make_window(scene())
    win.resize(1280, 800)
    for _ in range(5):
        app.processEvents()
    feats = win.actors.features
    bd = feats.backdrop
    assert bd.active and len(bd.props) == 3  # the main view's fill, outline and centres
    main_actors = win.main_ren.GetActors()
    assert not any(main_actors.IsItemPresent(p) for p in bd.props)
    before = win.model.scene.copy()

    w = win.plotter.windowHandle()
    u = win.units_per_px()
    px = QtCore.QPoint(*(round(v) for v in win.to_pixel(X0 - 0.5 * G0, Y0)))  # only it there
    end = px + QtCore.QPoint(round(180.0 / u), -round(60.0 / u))  # over "under", under "over"
    QTest.mousePress(w, QtCore.Qt.LeftButton, QtCore.Qt.NoModifier, px)
    app.processEvents()
    assert win.model.selected == K
    steps = 4  # each move past the click threshold (eyeviz.model.app_model)
    for k in range(1, steps + 1):
        p = px + (end - px) * (k / steps)
        frame_after(win, app, lambda p=p: QTest.mouseMove(w, p), k)
        if k == 1:
            c1, h1 = bd.captures, bd.hits
    # every drag frame after the first copied the kept discs (none drew them again)
    assert bd.captures == c1 and bd.hits >= h1 + steps - 1
    captures, hits = bd.captures, bd.hits
    # mid-drag (the button still down): the kept discs drawn under the live ones
    dragged = view_pixels(win)
    assert bd.hits > hits and bd.captures == captures  # this frame copied the kept discs
    f = win.model.scene.features[K]
    assert math.hypot(f.x - (X0 + 180.0), f.y - (Y0 + 60.0)) <= 3 * u
    # the depth order holds: "over" covers the dragged disc, which covers "under"
    for x, y, i in ((240.0, 1500.0, N - 1), (160.0, 1660.0, K)):
        assert np.array_equal(patch_colour(win, dragged, x, y), feats.fill_rgb(i))

    # the same state with every disc in the main renderer (the path of small scenes)
    feats.set_backdrop_min(10**9)
    assert not bd.active and main_actors.GetNumberOfItems() > 0
    full = view_pixels(win)
    diff = np.abs(dragged.astype(int) - full.astype(int)).max(axis=2)
    assert (diff > 0).sum() == 0, f"{(diff > 0).sum()} pixels differ, by up to {diff.max()}"
    feats.set_backdrop_min(BACKDROP_MIN_FEATURES)
    assert bd.active

    # the release: one undo step, the feature where the pointer left it; undo restores
    QTest.mouseRelease(w, QtCore.Qt.LeftButton, QtCore.Qt.NoModifier, end)
    app.processEvents()
    assert win.undo_stack.count() == 1
    f = win.model.scene.features[K]
    assert abs(f.x - (X0 + 180.0)) <= 3 * u and abs(f.y - (Y0 + 60.0)) <= 3 * u
    assert win.model.scene.features[:K] == before.features[:K]
    c = bd.captures
    win.undo_stack.undo()
    app.processEvents()
    assert win.model.scene.features == before.features
    # the undo changed the discs and a zoom moves the camera: the backdrop draws them
    # again, keeps them, and its next frame still equals the full render
    assert bd.captures > c
    vp = win.viewport("main")
    c, h = bd.captures, bd.hits
    assert interactions.wheel(win.model, "main", vp, 300.0, 300.0, 1.0, False) == "zoom"
    app.processEvents()
    view_pixels(win)
    zoomed = view_pixels(win)  # a hit
    assert bd.captures == c + 1 and bd.hits >= h + 1
    bd.invalidate()
    captured = view_pixels(win)  # a frame that draws the discs and keeps them
    assert bd.captures == c + 2
    feats.set_backdrop_min(10**9)
    full = view_pixels(win)
    assert np.array_equal(zoomed, full) and np.array_equal(captured, full)


def test_coincident_features_look_the_same_with_and_without_the_backdrop(make_window):
    """Two features at one spot (Add twice at the view's centre), the later one selected:
    its live centre dot and the other's merged one met at one depth, a tie the backdrop
    gave to the live dot and the full render to the merged one (82 pixels differed)."""
    fs = [
        Feature(f"f{i}", -3000.0 + 40.0 * i, 4000.0 + 15.0 * (i % 9), 30.0, OKABE_ITO[i % 7])
        for i in range(BACKDROP_MIN_FEATURES)
    ]
    fs += [Feature("a", 0.0, 2000.0, 200.0, OKABE_ITO[1]), Feature("b", 0.0, 2000.0, 200.0)]
    win = make_window(
        Scene(Eyes(40.0, 20.0, 72), fs, ["eyes", "features"], [], View((0.0, 2600.0), 6000.0))
    )
    win.resize(640, 480)
    win.model.select(len(fs) - 1)
    feats = win.actors.features
    assert feats.backdrop.active
    kept = view_pixels(win)
    feats.set_backdrop_min(10**9)
    full = view_pixels(win)
    diff = np.abs(kept.astype(int) - full.astype(int)).max(axis=2)
    assert (diff > 0).sum() == 0, f"{(diff > 0).sum()} pixels differ, by up to {diff.max()}"
    # the selected (later) feature's dot is the one on top either way
    assert np.array_equal(patch_colour(win, full, 0.0, 2000.0), feats._rgb_now[1][-1])


def test_a_screenshot_over_the_backdrop_equals_one_without_it(make_window, tmp_path):
    """vtkWindowToImageFilter (every screenshot, ``eyeviz app --screenshot``) gives each
    renderer a camera copy for its render and deletes each renderer's camera afterwards:
    the backdrop's renderer held the main renderer's, freed twice (a segmentation fault)."""
    fs = [
        Feature(f"f{i}", -3000.0 + 40.0 * i, 4000.0 + 15.0 * (i % 9), 30.0, OKABE_ITO[i % 7])
        for i in range(BACKDROP_MIN_FEATURES)
    ]
    sc = Scene(Eyes(40.0, 20.0, 72), fs, ["eyes", "features"], [], View((0.0, 2600.0), 6000.0))
    win = make_window(sc)
    win.resize(640, 480)
    feats = win.actors.features
    assert feats.backdrop.active
    kept = qimage_to_array(win.save_screenshot(tmp_path / "kept.png") and win.grab_image())
    again = qimage_to_array(win.grab_image())  # the main camera survived the first
    feats.set_backdrop_min(10**9)
    full = qimage_to_array(win.grab_image())
    assert np.array_equal(kept, full) and np.array_equal(again, full)


def test_the_selected_name_label_is_not_hidden_by_other_centre_dots(make_window):
    """Beyond six features only the selected feature is named; its label sat at the centre
    dots' depth, and in a crowd (10^4 features) the other features' dots covered it whole:
    the label must show over a field of dots as it does with the dots hidden."""
    fs = [
        Feature(f"c{i}_{j}", 0.0 + 70.0 * i, 2000.0 + 70.0 * j, 20.0, OKABE_ITO[(i + j) % 7])
        for i in range(25)
        for j in range(8)
    ]
    fs.append(Feature("the-selected-one", -100.0, 1900.0, 120.0, OKABE_ITO[5]))
    assert len(fs) >= BACKDROP_MIN_FEATURES
    sc = Scene(
        Eyes(40.0, 20.0, 72), fs, ["eyes", "features", "labels"], [], View((0.0, 2600.0), 6000.0)
    )
    win = make_window(sc)
    win.resize(900, 600)
    win.model.select(len(fs) - 1)
    feats, label = win.actors.features, win.actors.labels.feature_labels[0]

    def label_pixels() -> int:
        label.SetVisibility(True)
        shown = view_pixels(win)
        label.SetVisibility(False)
        hidden = view_pixels(win)
        label.SetVisibility(True)
        return int((np.abs(shown.astype(int) - hidden.astype(int)).max(axis=2) > 0).sum())

    assert label.GetInput().strip() == "the-selected-one"
    for kept in (True, False):  # over the backdrop, then with the discs in the main renderer
        feats.set_backdrop_min(BACKDROP_MIN_FEATURES if kept else 10**9)
        assert feats.backdrop.active == kept
        crowd = label_pixels()
        feats._centers_actor.SetVisibility(False)
        feats.backdrop.invalidate()
        alone = label_pixels()
        feats._centers_actor.SetVisibility(True)
        feats.backdrop.invalidate()
        assert alone > 200 and crowd >= 0.9 * alone, (kept, crowd, alone)
