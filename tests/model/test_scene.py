"""Scene TOML load/save: round trip, shipped scenes, and one-line errors naming key+line."""

import subprocess
import sys
from pathlib import Path

import pytest

from eyeviz import EyevizError
from eyeviz.model.scene import (
    LAYERS,
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
    assert s.features and set(s.layers) <= set(LAYERS)
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
        (("m = 720", "m = 720\n[view]\nwidth = 0.0"), ["view.width", "> 0"]),
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
