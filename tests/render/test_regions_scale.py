"""Per-feature regions at scale (issue 25): a Frame computes ambiguity regions and
posteriors for the first MAX_REGIONS features at most and counts the rest; the app's
selected feature is computed wherever it is; an exported figure notes the rest."""

import math

import matplotlib

matplotlib.use("Agg")

from eyeviz.model.frame import MAX_REGIONS, build_frame  # noqa: E402
from eyeviz.model.scene import Eyes, Feature, Scene, View  # noqa: E402


def _scene(n: int, layers) -> Scene:
    fs = []
    for i in range(n):
        phi = math.radians(60 + 60 * i / max(n - 1, 1))
        r = 1500.0 + 40.0 * i
        fs.append(Feature(f"f{i}", r * math.cos(phi), r * math.sin(phi), 60.0, "#0072B2"))
    return Scene(Eyes(40.0, 20.0, 72), fs, list(layers), [], View((0.0, 2500.0), 9000.0))


def test_regions_capped_in_scene_order_and_counted():
    n = MAX_REGIONS + 7
    sc = _scene(n, ["eyes", "features", "ambiguity", "posterior"])
    fr = build_frame(sc, predictions={})
    assert sorted(fr.ambiguity) == list(range(MAX_REGIONS))
    assert sorted(fr.posterior) == list(range(MAX_REGIONS))
    assert fr.regions_left_out == 7
    small = build_frame(_scene(5, sc.layers), predictions={})
    assert sorted(small.ambiguity) == list(range(5)) and small.regions_left_out == 0


def test_the_selected_feature_beyond_the_cap_has_its_posterior():
    n = MAX_REGIONS + 7
    sc = _scene(n, ["eyes", "features", "posterior"])
    fr = build_frame(sc, predictions={}, only=n - 1)
    assert list(fr.posterior) == [n - 1] and fr.regions_left_out == 0


def test_exported_figure_notes_what_was_left_out():
    from eyeviz.render.mpl.vector import figure

    n = MAX_REGIONS + 3
    sc = _scene(n, ["eyes", "features", "ambiguity"])
    fig = figure(sc, predictions={})
    texts = [t.get_text() for t in fig.findobj(matplotlib.text.Text)]
    assert any("3 more without ambiguity" in t for t in texts), texts
