"""Scene TOML load/save: round trip, shipped scenes, and one-line errors naming key+line."""

import subprocess
import sys
from pathlib import Path

import pytest

from eyeviz import EyevizError
from eyeviz.model.layers import layer_names
from eyeviz.model.scene import (
    Eyes,
    Feature,
    Scene,
    SceneError,
    Trajectory,
    View,
    dumps,
    load,
    loads,
    save,
)

SCENES = Path(__file__).resolve().parents[2] / "assets" / "scenes"
BASE = """
[eyes]
h = 40.0
l = 20.0
m = 720

[[features]]
name = "a"
x = 0.0
y = 1500.0
g = 50.0

[[features]]
name = "b"
x = 100.0
y = 2000.0
g = 20.0
"""


@pytest.mark.parametrize("name", ["default", "figure2", "figure3b", "figure5"])
def test_shipped_scenes_load_and_round_trip(name, tmp_path):
    s = load(SCENES / f"{name}.toml")
    assert s.features and set(s.layers) <= set(layer_names())
    out = tmp_path / "s.toml"
    save(s, out)
    assert load(out) == s


def test_default_is_table_3():
    s = load(SCENES / "default.toml")
    assert (s.eyes.h, s.eyes.l, s.eyes.m) == (40.0, 20.0, 720)
    assert s.eyes.pair().theta == pytest.approx(2.0943951023931957)  # 120 deg


def test_round_trip_every_field():
    s = Scene(
        Eyes(35.5, 12.25, 36000),
        [Feature('quote " and \\ name', -1e-300, 12345.678901234567, 0.1, "#abcdef")],
        ["eyes", "trajectory", "predictions"],
        ["compact", "analytic"],
        View((1.5, -2.0), 123.0),
        "a title",
        Trajectory("circular", 2500.0, 50.0),
    )
    assert loads(dumps(s)) == s


def test_missing_colours_take_okabe_ito_in_order():
    s = loads(BASE)
    assert [f.color for f in s.features] == ["#D55E00", "#0072B2"]
    assert s.layers == ["eyes", "bfv", "features", "bitmaps", "readout"]


@pytest.mark.parametrize(
    "edit, words",
    [
        (("m = 720", "m = 7"), ["<t>:5", "eyes.m", "even integer >= 4"]),
        (("h = 40.0", "h = 10.0"), ["<t>:3", "eyes.h", "h must be > l"]),
        (("g = 20.0", "g = -1.0"), ["<t>:17", "features[1].g", "> 0"]),
        (('name = "b"', 'name = "a"'), ["<t>:14", "features[1].name", "duplicate"]),
        (("y = 1500.0", 'y = "far"'), ["<t>:10", "features[0].y", "number"]),
        (("y = 1500.0", "y = nan"), ["features[0].y", "finite"]),
        (("g = 50.0", "g = 50.0\ncolour = 'red'"), ["features[0].colour", "unknown key"]),
        (("g = 50.0", "g = 50.0\ncolor = 'red'"), ["features[0].color", "#rrggbb"]),
        (("m = 720", "m = 720\n[layers]\nshow = ['eyes', 'nope']"), ["layers.show", "'nope'"]),
        (("m = 720", "m = 720 x"), ["not valid TOML", "line 5"]),
        (
            ("m = 720", "m = 720\n[trajectory]\nkind = 'zigzag'\ndistance = 1.0\ng = 1.0"),
            ["trajectory.kind", "horizontal"],
        ),
        (("m = 720", "m = 720\n[view]\nwidth = 0.0"), ["view.width", ">= 1e-06"]),
    ],
)
def test_errors_name_key_line_and_rule(edit, words):
    text = BASE.replace(*edit)
    with pytest.raises(SceneError) as info:
        loads(text, "<t>")
    msg = str(info.value)
    assert "\n" not in msg
    for w in words:
        assert w in msg, msg
    assert isinstance(info.value, EyevizError)


def test_load_names_the_file(tmp_path):
    with pytest.raises(SceneError, match="no such scene file"):
        load(tmp_path / "missing.toml")
    bad = tmp_path / "bad.toml"
    bad.write_bytes(b"\xff\xfe\x00")
    with pytest.raises(SceneError, match="bad.toml"):
        load(bad)


def test_save_is_atomic_and_leaves_no_temp(tmp_path):
    out = tmp_path / "s.toml"
    out.write_text("old")
    save(loads(BASE), out)
    assert load(out) == loads(BASE)
    assert [p.name for p in tmp_path.iterdir()] == ["s.toml"]


def test_scene_module_imports_nothing_heavy():
    code = (
        "import sys, eyeviz.model.scene, eyeviz.model.state; "
        "heavy = ('torch', 'PyQt5', 'pyvista', 'vtk', 'matplotlib'); "
        "bad = [m for m in heavy if m in sys.modules]; "
        "print(bad); sys.exit(1 if bad else 0)"
    )
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert r.returncode == 0, r.stdout + r.stderr


# --- hostile scene files (issue 13) -----------------------------------------------------


@pytest.mark.parametrize(
    "edit, words",
    [
        (("m = 720", "m = 2000000000"), ["<t>:5: eyes.m", "<= 1048576, got 2000000000"]),
        (("m = 720", "m = 9223372036854775807"), ["eyes.m", "<= 1048576"]),
        (("m = 720", "m = 1048578"), ["<t>:5: eyes.m: m must be an even integer", "<= 1048576"]),
        (("m = 720", "m = 720.5"), ["<t>:5: eyes.m", "even integer", "got 720.5"]),
        (("x = 0.0", "x = " + "9" * 400), ["features[0].x", "within"]),
        (("x = 0.0", "x = 1e300"), ["<t>:9: features[0].x", "within +-1e+12"]),
        (("g = 50.0", "g = 1e308"), ["features[0].g", "within"]),
        (("m = 720", "m = 720\n[view]\nwidth = 5e-324"), ["view.width", ">= 1e-06"]),
        (("m = 720", "m = 720\n[view]\ncenter = [1e300, 0]"), ["view.center", "within"]),
        (('name = "a"', 'name = "a\\nb"'), ["<t>:8: features[0].name", "control character"]),
        (('name = "a"', 'name = "a\\u0000b"'), ["features[0].name", "'\\x00'"]),
        (('name = "a"', 'name = "' + "n" * 1_000_000 + '"'), ["longer than 200"]),
        (("m = 720", 'm = 720\n[layers]\nshow = ["eyes\\r"]'), ["layers.show", "control"]),
    ],
)
def test_hostile_values_one_line(edit, words):
    msg = _one_line_error(BASE.replace(*edit))
    for w in words:
        assert w in msg, msg
    assert len(msg) < 300


def _one_line_error(text):
    with pytest.raises(SceneError) as info:
        loads(text, "<t>")
    msg = str(info.value)
    assert "\n" not in msg
    return msg


def test_deep_nesting_and_huge_numbers_one_line():
    assert "nested too deeply" in _one_line_error("a = " + "[" * 100_000 + "]" * 100_000)
    assert "nested too deeply" in _one_line_error("a = " + "{b = " * 5000 + "1" + "}" * 5000)
    msg = _one_line_error("a = " + "9" * 5000)  # an int tomllib refuses to build
    assert "not valid TOML" in msg or "a: unknown key" in msg


def test_too_many_features():
    many = "".join(
        f'[[features]]\nname = "f{i}"\nx = 0.0\ny = {i + 100}.0\ng = 1.0\n' for i in range(10_001)
    )
    assert "10001 features, more than 10000" in _one_line_error(many)


def test_file_bounds(tmp_path):
    big = tmp_path / "big.toml"
    big.write_text(BASE + "#" * (8 << 20))
    with pytest.raises(SceneError, match="bytes, more than 8388608"):
        load(big)
    with pytest.raises(SceneError, match="is not a regular file"):
        load("/dev/zero")
    with pytest.raises(SceneError, match="is not a regular file"):
        load(tmp_path)
    fifo = tmp_path / "f.toml"
    import os

    os.mkfifo(fifo)
    with pytest.raises(SceneError, match="is not a regular file"):
        load(fifo)  # would block forever if opened


def test_names_that_cannot_be_saved_are_refused_at_save_too(tmp_path):
    s = loads(BASE)
    s.features[0].name = "a\nb"
    with pytest.raises(SceneError, match="control character"):
        save(s, tmp_path / "s.toml")
    assert list(tmp_path.iterdir()) == []


def test_dumps_is_tomli_w_quoted_and_stable():
    s = loads(BASE)
    s.title = 'quote " backslash \\ tab-free ünïcode'
    s.features[0].name = 'it\'s "x"'
    text = dumps(s)
    assert loads(text) == s and dumps(loads(text)) == text
    assert "[[features]]" in text and 'show = ["eyes", "bfv"' in text


@pytest.mark.parametrize(
    "table",
    [
        "[layers]\nshow = 'eyes'",  # a string is not a list of strings
        "[layers]\nshow = ['eyes', 3]",
        "[predictions]\nestimators = 'analytic'",
    ],
)
def test_a_list_of_strings_must_be_a_list_of_strings(table):
    with pytest.raises(SceneError, match="must be a list of strings"):
        loads(BASE.replace("m = 720", "m = 720\n" + table), "<t>")


def test_no_estimator_is_refused_only_when_the_predictions_layer_is_shown():
    none = "m = 720\n[predictions]\nestimators = []\n[layers]\nshow = "
    sc = loads(BASE.replace("m = 720", none + "['eyes', 'features']"), "<t>")
    assert sc.estimators == [] and not sc.shows("predictions")
    with pytest.raises(SceneError, match="needs at least one estimator"):
        loads(BASE.replace("m = 720", none + "['eyes', 'predictions']"), "<t>")


def test_a_scene_of_the_most_features_saves_and_loads_back(tmp_path):
    """A scene may hold MAX_FEATURES features; saved with full-precision coordinates and
    long names it must stay under the reader's size limit (10^4 features made a 1.15 MB
    file against a 1 MiB limit, so the app's Save refused a scene it had opened)."""
    import math

    from eyeviz.files import limits
    from eyeviz.model.scene import Eyes, Feature, Scene, load, save

    n = limits.MAX_FEATURES
    feats = [
        Feature(
            f"feature number {i} with a rather long descriptive name, " + "é" * 40,
            -1234.5678901234567 + math.pi * i,
            2345.678901234567 + math.e * i,
            12.345678901234567 + (i % 7) / 3,
            "#0072b2",
        )
        for i in range(n)
    ]
    sc = Scene(Eyes(40.0, 20.0, 720), feats, ["eyes", "features"])
    out = tmp_path / "big.toml"
    save(sc, out)
    back = load(out)
    assert len(back.features) == n
    assert back.features[-1] == feats[-1]  # full precision kept
