"""Scene.copy (issue 25): a field-by-field deep copy, cheap at 10^4 features."""

import copy
import dataclasses

from eyeviz.model.scene import Eyes, Feature, Scene, Trajectory, View
from eyeviz.model.steps import Step


def _scene() -> Scene:
    return Scene(
        Eyes(41.0, 19.0, 360),
        [Feature("a", 1.0, 2.0, 3.0, "#112233"), Feature("b", -4.0, 5.0, 6.0, "#445566")],
        ["eyes", "features"],
        ["analytic"],
        View((7.0, 8.0), 900.0),
        "title",
        Trajectory("circular", 500.0, 10.0),
        [Step("one", ["eyes"], ["a"])],
    )


def test_copy_knows_every_field():
    # a new field must be copied by Scene.copy too: this list is its checklist
    names = {c: [f.name for f in dataclasses.fields(c)] for c in (Scene, Feature, Eyes, View)}
    assert names == {
        Scene: [
            "eyes",
            "features",
            "layers",
            "estimators",
            "view",
            "title",
            "trajectory",
            "steps",
        ],
        Feature: ["name", "x", "y", "g", "color", "z"],
        Eyes: ["h", "l", "m", "nside", "file", "units", "frame"],
        View: ["center", "width"],
    }


def test_copy_equals_deepcopy_and_shares_nothing_mutable():
    sc = _scene()
    c = sc.copy()
    assert c == sc == copy.deepcopy(sc)
    assert c.eyes is not sc.eyes and c.view is not sc.view
    assert c.trajectory is not sc.trajectory and c.steps[0] is not sc.steps[0]
    assert c.features is not sc.features
    assert all(a is not b for a, b in zip(c.features, sc.features, strict=True))
    spherical = Scene(Eyes(40.0, 20.0, nside=4), [Feature("s", 0.0, 1.0, 2.0, "#000000", 3.0)])
    assert spherical.copy() == spherical and spherical.copy().eyes.m == 16


def test_mutating_the_copy_leaves_the_original():
    sc = _scene()
    before = copy.deepcopy(sc)
    c = sc.copy()
    c.eyes.h, c.eyes.m = 50.0, 720
    c.features[0].x = 99.0
    c.features[1].name = "renamed"
    c.features.append(Feature("new", 0.0, 0.0, 1.0))
    c.layers.append("bfv")
    c.estimators.clear()
    c.view.width = 1.0
    c.view.center = (0.0, 0.0)
    assert c.trajectory is not None
    c.trajectory.distance = 1.0
    c.steps[0].layers.append("features")
    c.steps[0].caption = "changed"
    c.title = "other"
    assert sc == before
