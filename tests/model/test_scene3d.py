"""Spherical scenes (issue 22): [eyes] nside, features with z, the planar scenes unchanged,
and every refusal in one line naming the key (docs/spherical.md)."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

from eyeviz import EyevizError
from eyeviz.core.geometry import EyePair
from eyeviz.core.geometry3d import EyePair3D
from eyeviz.core.healpix import pix2ring
from eyeviz.model.scene import (
    SPHERICAL_LAYERS,
    Eyes,
    Feature,
    Scene,
    SceneError,
    dumps,
    load,
    loads,
    save,
)

SCENES = Path(__file__).resolve().parents[2] / "assets" / "scenes"
SPHERES = ["sphere_paper", "sphere_teaching", "sphere_equator"]
PLANAR = ["default", "figure2", "figure3b", "figure5", "predictions", "trajectory"]

BASE3D = """
[eyes]
h = 40.0
l = 20.0
nside = 8

[[features]]
name = "a"
x = 0.0
y = 300.0
z = 40.0
g = 50.0

[layers]
show = ["eyes", "features", "bitmaps"]
"""


@pytest.mark.parametrize("name", SPHERES)
def test_shipped_spherical_scenes_round_trip(name, tmp_path):
    s = load(SCENES / f"{name}.toml")
    assert s.kind == "spherical" and s.eyes.nside is not None
    assert s.eyes.m == 4 * s.eyes.nside  # the equator's planar eye
    assert isinstance(s.eyes.model(), EyePair3D)
    assert s.eyes.model().design == {"h": 40.0, "l": 20.0, "nside": s.eyes.nside}
    assert set(s.layers) <= set(SPHERICAL_LAYERS) and len(s.features) >= 3
    assert loads(dumps(s)) == s
    out = tmp_path / "s.toml"
    save(s, out)
    assert load(out) == s
    assert "nside = " in out.read_text() and "m = " not in out.read_text()


def test_shipped_spherical_scenes_have_balls_off_the_plane():
    for name in SPHERES:
        zs = [f.z for f in load(SCENES / f"{name}.toml").features]
        assert any(z > 0 for z in zs) and any(z < 0 for z in zs), name


def test_the_equator_scene_lights_the_planar_bitmap_on_the_equator():
    """Balls on z = 0 light, on each eye's equator ring (ring 2 nside), as many facets as
    the planar eye EyePair(h, l, 4 nside) lights ommatidia; their copies light none there."""
    s = load(SCENES / "sphere_equator.toml")
    e, n = s.eyes.model(), s.eyes.nside
    planar = EyePair(s.eyes.h, s.eyes.l, 4 * n)
    on_plane = [f for f in s.features if f.z == 0.0]
    assert len(on_plane) >= 2
    for f in s.features:
        for eye, lit in zip("AB", e.lit(f.x, f.y, f.z, f.g), strict=True):
            ring = pix2ring(n, lit)[0]
            on_eq = int((ring == 2 * n).sum())
            if f.z == 0.0:
                bm = planar.bitmaps(f.x, f.y, f.g)[0 if eye == "A" else 1]
                assert on_eq == int(np.sum(bm)) > 0, (f.name, eye)
            else:
                assert on_eq == 0, (f.name, eye)


@pytest.mark.parametrize("name", PLANAR)
def test_planar_scenes_unchanged(name):
    """A planar scene's eyes and text are as before spherical scenes: no z key, pair()."""
    s = load(SCENES / f"{name}.toml")
    assert s.kind == "planar" and s.eyes.nside is None
    assert all(f.z == 0.0 for f in s.features)
    text = dumps(s)
    assert loads(text) == s
    assert not any(line.startswith(("z =", "nside =")) for line in text.splitlines())
    assert isinstance(s.eyes.model(), EyePair) and s.eyes.pair() == s.eyes.model()


def test_planar_dumps_byte_identical_to_the_scene_module_before_3d(tmp_path):
    """The planar writer's output is pinned: the text of a scene written with every field."""
    s = Scene(Eyes(40.0, 20.0, 720), [Feature("a", 1.0, 2.0, 3.0, "#112233")])
    assert dumps(s) == (
        '[eyes]\nh = 40.0\nl = 20.0\nm = 720\n\n[[features]]\nname = "a"\nx = 1.0\n'
        'y = 2.0\ng = 3.0\ncolor = "#112233"\n\n[layers]\n'
        'show = ["eyes", "bfv", "features", "bitmaps", "readout"]\n\n'
        '[predictions]\nestimators = ["compact"]\n\n'
        "[view]\ncenter = [0.0, 2500.0]\nwidth = 8000.0\n"
    )


def test_planar_feature_at_z_zero_is_accepted_and_not_written():
    s = loads(BASE3D.replace("nside = 8", "m = 720").replace("z = 40.0", "z = 0.0"))
    assert s.kind == "planar" and s.features[0].z == 0.0
    assert "z =" not in dumps(s)


def test_spherical_round_trip_in_code():
    s = Scene(Eyes(40.0, 20.0, nside=16), [Feature("b", 1.0, 500.0, 9.0, "#112233", -7.5)])
    s.layers = ["eyes", "bitmaps"]
    t = dumps(s)
    assert "nside = 16" in t and "z = -7.5" in t
    assert loads(t) == s
    with pytest.raises(EyevizError, match="spherical"):
        s.eyes.pair()


def test_no_m_and_no_nside_is_the_planar_default():
    s = loads('[[features]]\nname = "a"\nx = 0.0\ny = 100.0\ng = 5.0\n')
    assert s.kind == "planar" and s.eyes.m == 720


def _refused(text: str, key: str, *words: str) -> str:
    with pytest.raises(SceneError) as ei:
        loads(text, "s.toml")
    msg = str(ei.value)
    assert "\n" not in msg and msg.startswith("s.toml:"), msg
    assert f": {key}: " in msg, msg
    for w in words:
        assert w in msg, msg
    return msg


def test_refusals_one_line_naming_the_key():
    _refused(BASE3D.replace("nside = 8", "nside = 8\nm = 720"), "eyes.nside", "m and nside")
    _refused(BASE3D.replace("nside = 8", "nside = 7"), "eyes.nside", "nside", "even")
    _refused(BASE3D.replace("nside = 8", "nside = 0"), "eyes.nside", "nside")
    _refused(BASE3D.replace("nside = 8", f"nside = {2**21}"), "eyes.nside", "nside")
    _refused(BASE3D.replace("nside = 8", 'nside = "8"'), "eyes.nside", "nside")
    _refused(BASE3D.replace("h = 40.0", "h = 10.0"), "eyes.h", "h must be > l")
    _refused(BASE3D.replace("z = 40.0", "z = 1e13"), "features[0].z", "within")
    _refused(BASE3D.replace("z = 40.0", "z = nan"), "features[0].z", "finite")
    _refused(BASE3D.replace("z = 40.0", 'z = "up"'), "features[0].z", "number")
    msg = _refused(
        BASE3D.replace("nside = 8", "m = 720"), "features[0].z", "'a'", "planar", "z = 0"
    )
    assert msg.startswith("s.toml:11:")  # the line of z
    for layer in ("sectors", "ambiguity", "posterior", "trajectory"):
        _refused(
            BASE3D.replace('"bitmaps"]', f'"bitmaps", "{layer}"]'),
            "layers.show",
            repr(layer),
            "planar-only",
        )
    _refused(
        BASE3D + '\n[trajectory]\nkind = "circular"\ndistance = 1000.0\ng = 50.0\n',
        "trajectory",
        "spherical",
    )


def test_predictions_is_a_spherical_layer_with_the_planar_key():
    """The 3D view's predictions layer (issue 23 item 4) is shown from a scene file, its
    estimators under the planar key ``[predictions] estimators``, saved and read back."""
    text = BASE3D.replace('"bitmaps"]', '"bitmaps", "predictions"]')
    s = loads(text + '\n[predictions]\nestimators = ["analytic3d", "limit3d"]\n', "s.toml")
    assert s.shows("predictions") and s.estimators == ["analytic3d", "limit3d"]
    assert loads(dumps(s), "t.toml") == s
    _refused(text + "\n[predictions]\nestimators = []\n", "predictions.estimators", "at least")


def test_cones_and_the_plane_are_spherical_layers():
    """tangents (the tangent cones) and plane (z = 0) are layers of the 3D view; plane is
    not a planar layer."""
    s = loads(BASE3D.replace('"bitmaps"]', '"bitmaps", "tangents", "plane"]'), "s.toml")
    assert s.shows("tangents") and s.shows("plane")
    planar = BASE3D.replace("nside = 8", "m = 720").replace("z = 40.0", "z = 0.0")
    _refused(planar.replace('"bitmaps"]', '"bitmaps", "plane"]'), "layers.show", "'plane'")


def test_scene_module_stays_light():
    """scene.py (and the eye seam it now imports) pulls in no matplotlib, Qt or VTK."""
    import subprocess

    path = str(SCENES / "sphere_teaching.toml")
    code = (
        f"import sys, eyeviz.model.scene as s; s.load({path!r}).eyes.model(); "
        "print(sorted(m for m in ('matplotlib', 'PyQt5', 'vtk', 'torch') if m in sys.modules))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"
