"""Feature names at scale (issue 25): beyond LABEL_ALL_MAX features one label, the selected
feature's, in its colour at its anchor; not one hidden text actor per feature."""

import numpy as np
import pytest
import pyvista as pv

from eyeviz.model.scene import OKABE_ITO, Eyes, Feature, Scene
from eyeviz.model.state import compute_state
from eyeviz.render.vtk.actors import SceneActors
from eyeviz.render.vtk.style import LABEL_ALL_MAX, rgbf


@pytest.fixture
def act():
    pl = pv.Plotter(off_screen=True, window_size=(400, 300))
    inset = pv.Renderer(pl)
    pl.ren_win.AddRenderer(inset)
    yield SceneActors(pl.renderer, inset)
    pl.close()


def _scene(n: int) -> Scene:
    fs = [
        Feature(f"f{i}", 100.0 * i, 1500.0, 30.0, OKABE_ITO[i % len(OKABE_ITO)]) for i in range(n)
    ]
    return Scene(Eyes(40.0, 20.0, 72), fs, ["eyes", "features", "labels"])


def _anchor(act, i):
    return next(lab for lab in act.frame.labels if lab.kind == "feature" and lab.feature == i)


def test_many_features_one_label_that_follows_the_selection(act):
    n = 40 * LABEL_ALL_MAX
    sc = _scene(n)
    st = compute_state(sc)
    for sel in (3, n - 1):
        act.update(sc, st, sel)
        labels = act.labels.feature_labels
        assert len(labels) == 1 and labels[0].GetVisibility()
        lab = _anchor(act, sel)
        assert labels[0].GetInput().strip() == f"f{sel}"
        np.testing.assert_allclose(labels[0].GetPosition()[:2], [lab.x, lab.y])
        np.testing.assert_allclose(labels[0].GetTextProperty().GetColor(), rgbf(OKABE_ITO[sel % 7]))
    act.update(sc, st, None)
    assert not act.labels.feature_labels[0].GetVisibility()


def test_few_features_one_label_each(act):
    sc = _scene(LABEL_ALL_MAX)
    act.update(sc, compute_state(sc), None)
    labels = act.labels.feature_labels
    assert len(labels) == LABEL_ALL_MAX and all(t.GetVisibility() for t in labels)
    assert [t.GetInput().strip() for t in labels] == [f.name for f in sc.features]
