"""``build_frame(named=...)``: the name labels of the given features only, each the one the
full Frame holds (issue 25: the app's view names its selection alone among many features,
eyeviz.render.vtk.actors.view_frame)."""

from eyeviz.model.frame import build_frame
from eyeviz.model.scene import OKABE_ITO, Eyes, Feature, Scene


def _scene(n: int) -> Scene:
    fs = [
        Feature(f"f{i}", 90.0 * i - 400.0, 1500.0 + 7.0 * i, 20.0 + i, OKABE_ITO[i % 7])
        for i in range(n)
    ]
    return Scene(Eyes(40.0, 20.0, 72), fs, ["eyes", "features", "labels"])


def test_named_features_get_the_full_frames_labels():
    sc = _scene(12)
    full = build_frame(sc)
    feats = {lab.feature: lab for lab in full.labels if lab.kind == "feature"}
    assert sorted(feats) == list(range(12))
    part = build_frame(sc, named=[7, 2, 40, -1])  # out-of-range rows are left out
    assert [lab for lab in part.labels if lab.kind == "feature"] == [feats[7], feats[2]]
    assert [lab for lab in part.labels if lab.kind == "eye"] == [
        lab for lab in full.labels if lab.kind == "eye"
    ]
    assert [lab for lab in build_frame(sc, named=[]).labels if lab.kind == "feature"] == []
