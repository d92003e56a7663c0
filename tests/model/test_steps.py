"""Lecture steps in a scene file ([[steps]], eyeviz.model.steps): read, checked with one
line naming the key and its line, written back, and applied without touching the scene."""

import pytest

from eyeviz.model.scene import SceneError, dumps, load, loads
from eyeviz.model.steps import MAX_STEPS, apply_step
from eyeviz.resources import scene_path

HEAD = """[eyes]
h = 40.0
l = 20.0
m = 36

[[features]]
name = "a"
x = 0.0
y = 200.0
g = 20.0

[[features]]
name = "b"
x = 50.0
y = 300.0
g = 20.0
"""


def test_steps_are_read_in_order_and_round_trip():
    sc = loads(
        HEAD
        + """
[[steps]]
caption = "eyes"
layers = ["eyes"]
features = []

[[steps]]
caption = "then a"
layers = ["eyes", "features", "tangents"]
features = ["a"]

[[steps]]
caption = "all"
layers = ["eyes", "features"]
"""
    )
    assert [s.caption for s in sc.steps] == ["eyes", "then a", "all"]
    assert sc.steps[0].features == [] and sc.steps[2].features is None
    assert loads(dumps(sc)) == sc


def test_apply_step_shows_its_layers_and_features_and_leaves_the_scene_alone():
    step = '\n[[steps]]\ncaption = "a"\nlayers = ["eyes", "tangents"]\nfeatures = ["b"]\n'
    sc = loads(HEAD + step)
    before = dumps(sc)
    shown = apply_step(sc, sc.steps[0])
    assert shown.layers == ["eyes", "tangents"]
    assert [f.name for f in shown.features] == ["b"]
    assert dumps(sc) == before  # a copy: the scene is unchanged
    assert shown.steps == sc.steps and shown.view == sc.view


@pytest.mark.parametrize(
    ("step", "message"),
    [
        ('caption = 3\nlayers = ["eyes"]', "<s>:19: steps[0].caption: must be a string, got int"),
        ('layers = ["eyes", "nope"]', "<s>:19: steps[0].layers: unknown layer 'nope'"),
        ('layers = "eyes"', "<s>:19: steps[0].layers: must be a list of strings"),
        ('layers = ["eyes", "eyes"]', "<s>:19: steps[0].layers: a name is given twice"),
        ('layers = ["eyes"]\nfeatures = ["c"]', "<s>:20: steps[0].features: no feature named 'c'"),
        ('layers = ["eyes"]\ncolour = "red"', "<s>:20: steps[0].colour: unknown key"),
        ('caption = "a\\u0007b"', "<s>:19: steps[0].caption: 'a\\x07b' contains the control"),
    ],
)
def test_a_bad_step_is_refused_in_one_line_naming_the_key_and_line(step, message):
    with pytest.raises(SceneError) as err:
        loads(HEAD + "\n[[steps]]\n" + step + "\n", "<s>")
    text = str(err.value)
    assert text.startswith(message), text
    assert "\n" not in text


def test_steps_not_an_array_and_too_many_steps_are_refused():
    with pytest.raises(SceneError, match=r"steps: must be an array of tables"):
        loads('steps = "all"\n' + HEAD, "<s>")
    many = "".join('\n[[steps]]\nlayers = ["eyes"]\n' for _ in range(MAX_STEPS + 1))
    with pytest.raises(SceneError, match=rf"steps: {MAX_STEPS + 1} steps, more than {MAX_STEPS}"):
        loads(HEAD + many, "<s>")


def test_a_step_showing_predictions_needs_an_estimator():
    text = HEAD + '[predictions]\nestimators = []\n\n[[steps]]\nlayers = ["predictions"]\n'
    with pytest.raises(SceneError, match=r"predictions.estimators: a step shows predictions"):
        loads(text, "<s>")


def test_the_lecture_scene_walks_from_the_eyes_to_the_predictions():
    sc = load(scene_path("lecture"))
    assert len(sc.steps) >= 8
    first, last = sc.steps[0], sc.steps[-1]
    assert first.features == [] and "eyes" in first.layers
    assert "predictions" in last.layers
    # every layer the order names appears, in that order
    order = ["eyes", "features", "tangents", "sectors", "bitmaps", "bfv", "predictions"]
    firsts = [next(i for i, s in enumerate(sc.steps) if name in s.layers) for name in order]
    assert firsts == sorted(firsts)
    assert all(s.caption for s in sc.steps)


SPHERE_HEAD = HEAD.replace("m = 36", "nside = 8").replace("g = 20.0\n", "z = 30.0\ng = 20.0\n", 1)


def test_a_spherical_scene_s_steps_take_the_3d_layers_and_refuse_planar_only_ones():
    text = (
        SPHERE_HEAD + '\n[[steps]]\ncaption = "the plane"\nlayers = ["eyes", "plane", "tangents"]\n'
    )
    sc = loads(text, "<s>")
    assert sc.kind == "spherical" and sc.steps[0].layers == ["eyes", "plane", "tangents"]
    assert loads(dumps(sc)) == sc
    shown = apply_step(sc, sc.steps[0])
    assert shown.features == sc.features and shown.features[0].z == 30.0
    bad = SPHERE_HEAD + '\n[[steps]]\ncaption = "x"\nlayers = ["eyes", "sectors"]\n'
    with pytest.raises(SceneError, match=r"^<s>:\d+: steps\[0\]\.layers: unknown layer 'sectors'"):
        loads(bad, "<s>")
    planar = HEAD + '\n[[steps]]\ncaption = "x"\nlayers = ["plane"]\n'
    with pytest.raises(SceneError, match=r"steps\[0\]\.layers: unknown layer 'plane'"):
        loads(planar, "<s>")


def test_the_sphere_lecture_walks_from_the_eyes_to_the_binocular_field():
    sc = load(scene_path("sphere_lecture"))
    assert sc.kind == "spherical" and len(sc.steps) >= 7
    first = sc.steps[0]
    assert first.features == [] and first.layers == ["eyes", "labels"]
    order = ["eyes", "features", "tangents", "bitmaps", "plane", "bfv", "readout"]
    firsts = [next(i for i, s in enumerate(sc.steps) if name in s.layers) for name in order]
    assert firsts == sorted(firsts)
    assert all(s.caption for s in sc.steps)
    assert sc.steps[-1].features is None  # every ball at the end


@pytest.mark.parametrize(
    ("step", "message"),
    [
        ('layers = ["eyes"]\ncamera = "top"', "steps[0].camera: unknown camera 'top'"),
        ('layers = ["eyes"]\ncamera = 3', "steps[0].camera: must be a name or a table"),
        ('layers = ["eyes"]\ncamera = { center = [0.0, 1.0] }', "steps[0].camera: missing width"),
        ('layers = ["eyes"]\ncamera = { center = [0, 1], width = -2 }', "steps[0].camera.width"),
        ('layers = ["eyes"]\ncamera = { center = [nan, 1], width = 2 }', "steps[0].camera.center"),
        ('layers = ["eyes"]\npanels = ["maps"]', "steps[0].panels: unknown panel 'maps'"),
    ],
)
def test_a_bad_step_camera_or_panel_is_refused_in_one_line(step, message):
    with pytest.raises(SceneError) as err:
        loads(HEAD + "\n[[steps]]\n" + step + "\n", "<s>")
    assert message in str(err.value) and "\n" not in str(err.value)


def test_step_cameras_and_panels_are_read_and_round_trip_on_both_sides():
    planar = loads(
        HEAD + '\n[[steps]]\ncaption = "a"\nlayers = ["eyes"]\n'
        'camera = { center = [0.0, 150.0], width = 400.0 }\npanels = ["readout"]\n'
    )
    assert planar.steps[0].camera == {"center": [0.0, 150.0], "width": 400.0}
    assert planar.steps[0].panels == ["readout"] and loads(dumps(planar)) == planar
    cam = "{ position = [0, -900, 400], focal_point = [0, 200, 0], view_up = [0, 0, 1] }"
    sphere = loads(
        SPHERE_HEAD + f'\n[[steps]]\ncaption = "a"\nlayers = ["eyes"]\ncamera = {cam}\n'
        '\n[[steps]]\ncaption = "b"\nlayers = ["eyes"]\ncamera = "side"\npanels = ["maps"]\n'
    )
    assert sphere.steps[0].camera["focal_point"] == [0.0, 200.0, 0.0]
    assert sphere.steps[1].camera == "side" and sphere.steps[1].panels == ["maps"]
    assert loads(dumps(sphere)) == sphere
    same = SPHERE_HEAD + '\n[[steps]]\ncaption = "a"\nlayers = ["eyes"]\n'
    with pytest.raises(SceneError, match="position must differ from focal_point"):
        loads(same + "camera = { position = [1, 2, 3], focal_point = [1, 2, 3], "
              "view_up = [0, 0, 1] }\n")  # fmt: skip
