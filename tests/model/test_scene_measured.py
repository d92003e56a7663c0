"""Scenes of measured eyes (``[eyes] file``, docs/measured.md): loading, saving back a
relative path, refusing a bad eye file in one line, the state against the pair called
directly, and the facet patches the 3D view draws (no Qt, no VTK)."""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest

from eyeviz.measured import EyeSizeWarning, load_eyes, shipped_eye
from eyeviz.model import shapes3d
from eyeviz.model.app_model3d import AppModel3D
from eyeviz.model.facets3d import MeasuredSurface, hexagon_mesh, surface_of
from eyeviz.model.scene import SceneError, dumps, load, loads, save
from eyeviz.model.state3d import compute_state3d

SCENES = Path(__file__).resolve().parents[2] / "eyeviz" / "assets" / "scenes"
BEE = SCENES / "bee.toml"


def _measured(text: str, tmp_path: Path, eye: str = "AM_60185-real.eye") -> Path:
    shutil.copy(shipped_eye(eye), tmp_path / "bee.eye")
    p = tmp_path / "s.toml"
    p.write_text('[eyes]\nfile = "bee.eye"\n' + text, encoding="utf-8")
    return p


def test_bee_scene_opens_as_measured_balls():
    sc = load(BEE)
    assert sc.kind == "spherical" and sc.eyes.kind == "measured"
    assert sc.eyes.file.samefile(shipped_eye("AM_60185-real.eye"))
    pair = sc.eyes.model()
    assert pair.kind == "measured" and pair.facet_counts == (3187, 3187)
    assert sc.eyes.h == pair.h and sc.eyes.l == pair.l
    assert len(sc.features) >= 3 and "cones" in sc.layers


def test_bee_balls_are_in_the_binocular_field_and_the_state_is_the_pairs():
    sc = load(BEE)
    st = compute_state3d(sc)
    pair = load_eyes(shipped_eye("AM_60185-real.eye"))
    assert st.facet_counts == (3187, 3187)
    for i, f in enumerate(sc.features):
        assert 5.0 <= float(np.sqrt(f.x**2 + f.y**2 + f.z**2)) <= 100.0  # bee scale, mm
        la, lb = pair.lit(f.x, f.y, f.z, f.g)
        np.testing.assert_array_equal(st.lit(i, "A"), la)
        np.testing.assert_array_equal(st.lit(i, "B"), lb)
        assert la.size >= 2 and lb.size >= 2 and bool(st.in_bfv[i])
    own = shapes3d.facet_owner(st, "B")
    assert own.shape == (3187,) and set(np.flatnonzero(own >= 0)) == set(
        np.concatenate([st.lit(i, "B") for i in range(st.n)])
    )


def test_bumblebee_scenes_open():
    large, small = load(SCENES / "bumblebees.toml"), load(SCENES / "bumblebee_small.toml")
    assert large.eyes.model().facet_counts == (4827, 4827)
    assert small.eyes.model().facet_counts == (1889, 1889)
    assert large.features == small.features  # the same balls: switch to compare
    big, little = compute_state3d(large), compute_state3d(small)
    assert bool(big.in_bfv.all()) and not bool(little.in_bfv.all())
    assert (big.facets_a + big.facets_b > little.facets_a + little.facets_b).all()


def test_relative_file_is_resolved_against_the_scene_and_saved_back_relative(tmp_path):
    p = _measured("[[features]]\nname = 'a'\nx = 0.0\ny = 5.0\nz = -6.0\ng = 0.4\n", tmp_path)
    sc = load(p)
    assert sc.eyes.file.samefile(tmp_path / "bee.eye") and sc.eyes.file.is_absolute()
    # saved in a sub-folder: the path is written relative to it and loads back equal
    (tmp_path / "sub").mkdir()
    save(sc, tmp_path / "sub" / "t.toml")
    text = (tmp_path / "sub" / "t.toml").read_text(encoding="utf-8")
    assert 'file = "../bee.eye"' in text and "nside" not in text and "\nh = " not in text
    assert load(tmp_path / "sub" / "t.toml") == sc
    assert loads(dumps(sc), "x") == sc  # without a folder: the absolute path


@pytest.mark.parametrize(
    ("content", "why"),
    [
        ("1 2 3\n", "eyes.file"),
        ("not an eye file at all\n", "eyes.file"),
        ("0 0 0 1 0 0 nan 0\n0 0 0 0 1 0 0.1 0\n", "eyes.file"),
    ],
)
def test_a_bad_eye_file_is_one_line_naming_the_key(tmp_path, content, why):
    p = _measured("", tmp_path)
    (tmp_path / "bee.eye").write_text(content, encoding="utf-8")
    with pytest.raises(SceneError) as exc:
        load(p)
    msg = str(exc.value)
    assert "\n" not in msg and why in msg and str(p) in msg


def test_missing_file_units_and_mixed_keys_are_refused(tmp_path):
    p = tmp_path / "s.toml"
    p.write_text('[eyes]\nfile = "nowhere.eye"\n', encoding="utf-8")
    with pytest.raises(SceneError, match="eyes.file: no such eye file"):
        load(p)
    p = _measured('units = "furlong"\n', tmp_path)
    text = p.read_text(encoding="utf-8").replace("\nunits", "units")
    p.write_text('[eyes]\nfile = "bee.eye"\nunits = "furlong"\n', encoding="utf-8")
    with pytest.raises(SceneError, match="eyes.units: must be one of mm, m, um"):
        load(p)
    p.write_text('[eyes]\nfile = "bee.eye"\nframe = "x,y"\n', encoding="utf-8")
    with pytest.raises(SceneError, match="eyes.frame"):
        load(p)
    p.write_text('[eyes]\nfile = "bee.eye"\nnside = 8\n', encoding="utf-8")
    with pytest.raises(SceneError, match="eyes.nside: a scene naming an eye file"):
        load(p)
    p.write_text('[eyes]\nh = 40.0\nl = 20.0\nnside = 8\nunits = "mm"\n', encoding="utf-8")
    with pytest.raises(SceneError, match="eyes.units"):
        load(p)
    assert text  # the first file was written


def test_units_scale_the_eyes(tmp_path):
    p = _measured("", tmp_path)
    p.write_text('[eyes]\nfile = "bee.eye"\nunits = "um"\n', encoding="utf-8")
    with pytest.warns(EyeSizeWarning):  # 3 um apart: implausible, and said so
        sc = load(p)
    assert sc.eyes.units == "um" and sc.eyes.h == pytest.approx(load(BEE).eyes.h / 1000.0)
    assert 'units = "um"' in dumps(sc)


def test_layers_by_model(tmp_path):
    p = _measured('[layers]\nshow = ["eyes", "predictions"]\n', tmp_path)
    with pytest.raises(SceneError, match="'predictions' applies to spherical eyes"):
        load(p)
    with pytest.raises(SceneError, match="'cones' applies to measured eyes"):
        loads('[eyes]\nh = 40.0\nl = 20.0\nnside = 8\n[layers]\nshow = ["cones"]\n')
    with pytest.raises(SceneError, match="'cones' is planar-only|unknown layer 'cones'"):
        loads('[eyes]\nm = 720\n[layers]\nshow = ["cones"]\n')


def test_app_model_drags_a_measured_ball_and_undo_restores_it():
    m = AppModel3D(load(BEE))
    before = m.state.lit(0, "A").copy()
    m.begin_live("Move near")
    m.live(0, x=1.5)
    assert not np.array_equal(m.state.lit(0, "A"), before) or m.state.lit(0, "B").size
    m.end_live()
    assert m.scene.features[0].x == 1.5


def test_hexagons_sit_at_the_lenses_facing_the_axes():
    pair = load_eyes(shipped_eye("AM_60185-real.eye"))
    eye = pair.eye_a
    pts, faces = hexagon_mesh(eye)
    assert pts.shape == (6 * eye.n, 3) and faces.size == 7 * eye.n
    hexes = pts.reshape(eye.n, 6, 3)
    np.testing.assert_allclose(hexes.mean(axis=1), eye.positions, atol=1e-12)
    normal = np.cross(hexes[:, 1] - hexes[:, 0], hexes[:, 2] - hexes[:, 0])
    assert ((normal * eye.unit_axes).sum(axis=1) > 0).all()  # counter-clockwise from outside
    # about the size of the lattice: a hexagon's circumradius against the nearest lens
    rad = np.linalg.norm(hexes[:, 0] - eye.positions, axis=1)
    assert 0.01 < float(np.median(rad)) < 0.05  # mm: a bee's facets are ~20 um across
    s = surface_of(pair)
    assert isinstance(s, MeasuredSurface) and s is surface_of(pair) and s.full
    assert s.counts() == (3187, 3187) and s.centres == pair.centers


def test_the_default_view_looks_from_the_balls_side():
    # a bee's balls lie below its eyes: the 3/4 view looks up at the facets they light;
    # HEALPix scenes with balls above keep the view from above
    bee = shapes3d.view_camera(compute_state3d(load(BEE)), "default", 1.5)
    assert bee.position[2] < bee.focal_point[2]
    sphere = shapes3d.view_camera(compute_state3d(load(SCENES / "sphere_teaching.toml")))
    assert sphere.position[2] > sphere.focal_point[2]


def test_acceptance_cones_open_at_half_the_acceptance_and_reach_the_ball():
    pair = load_eyes(shipped_eye("AM_60185-real.eye"))
    pos, ax, acc = pair.facets("A")
    idx = np.arange(0, 3187, 97)
    centre = np.array([0.0, 11.3, -16.4])
    pts, take = shapes3d.acceptance_cones(pos[idx], ax[idx], acc[idx], centre, res=12)
    assert np.array_equal(take, np.arange(idx.size))
    cones = pts.reshape(idx.size, 13, 3)
    np.testing.assert_array_equal(cones[:, 0], pos[idx])  # the apex is the lens
    u = ax[idx] / np.linalg.norm(ax[idx], axis=1, keepdims=True)
    rim = cones[:, 1:] - cones[:, :1]
    cos = (rim * u[:, None, :]).sum(axis=-1) / np.linalg.norm(rim, axis=-1)
    half = np.broadcast_to(acc[idx, None] / 2, cos.shape)
    np.testing.assert_allclose(np.arccos(np.clip(cos, -1, 1)), half, atol=1e-7)
    along = (rim * u[:, None, :]).sum(axis=-1)  # cut at the ball's distance from the lens
    dist = np.linalg.norm(centre - pos[idx], axis=1)[:, None]
    np.testing.assert_allclose(along, np.broadcast_to(dist, along.shape))
    many = np.repeat(pos[:1], 2500, axis=0)
    _, kept = shapes3d.acceptance_cones(many, np.repeat(ax[:1], 2500, 0), np.full(2500, 0.05),
                                        centre)  # fmt: skip
    assert kept.size <= shapes3d.MAX_ACCEPTANCE_CONES  # a sample beyond the bound
