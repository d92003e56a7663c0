"""What a scene's side decides is a lookup by the eye model's kind (issue 37:
``model/scene_eyes.SIDES``, ``model/facet_patches.PATCHES``), not a branch on kind
strings: each shipped scene's side, the scene file's rules it sets, and the refusal of a
model with no row."""

from __future__ import annotations

from pathlib import Path

import pytest

from eyeviz.model import facet_patches
from eyeviz.model import scene as scene_mod
from eyeviz.model.scene_eyes import SIDES, Eyes

SCENES = sorted((Path(scene_mod.__file__).parents[1] / "assets" / "scenes").glob("*.toml"))


def test_every_eye_model_has_a_side_and_every_shipped_scene_reads_it():
    assert set(SIDES) == {"planar", "spherical", "measured"}
    assert len(SCENES) == 15
    seen = set()
    for path in SCENES:
        sc = scene_mod.load(path)
        side = SIDES[sc.eyes.kind]
        assert sc.eyes.spec is side and sc.kind == side.name
        assert sc.in_space == side.in_space == (sc.eyes.kind != "planar")
        seen.add(sc.eyes.kind)
    assert seen == set(SIDES)  # the shipped scenes cover every model


def _text(eyes: str, more: str = "") -> str:
    return f"[eyes]\n{eyes}\n[[features]]\nx = 100.0\ny = 1500.0\ng = 60.0\n{more}"


def test_the_scene_files_rules_come_from_the_side(tmp_path):
    planar = scene_mod.loads(_text("m = 720"))
    space = scene_mod.loads(_text("nside = 8"))
    assert planar.estimators == list(SIDES["planar"].estimators) == ["compact"]
    assert space.estimators == list(SIDES["spherical"].estimators)
    # features off the plane: balls in space only
    with pytest.raises(scene_mod.SceneError, match="planar scene's features lie on z = 0"):
        scene_mod.loads(_text("m = 720", "z = 5.0"))
    assert scene_mod.loads(_text("nside = 8").replace("g = 60.0", "g = 60.0\nz = 5.0"))
    # a trajectory: the planar side's only
    traj = '[trajectory]\nkind = "horizontal"\ndistance = 2000.0\ng = 50.0\n'
    assert scene_mod.loads(_text("m = 720") + traj).trajectory is not None
    with pytest.raises(scene_mod.SceneError, match="a spherical scene has no trajectory"):
        scene_mod.loads(_text("nside = 8") + traj)
    # a planar scene's file never gains a z key; one in space always has it
    assert "z =" not in scene_mod.dumps(planar) and "z = 0.0" in scene_mod.dumps(space)


def test_facet_outlines_are_a_row_per_model_in_space():
    from eyeviz.core.geometry3d import EyePair3D

    assert set(facet_patches.PATCHES) == {"spherical", "measured"}
    assert facet_patches.patches_caption(EyePair3D(40, 20, 8)) == "nside 8, 768 facets per eye"

    class Flat:
        kind = "planar"

    with pytest.raises(
        ValueError, match=r"no facet map for 'planar' eyes \(known: spherical, measured\)"
    ):
        facet_patches.facet_patches(Flat(), "A")


def test_the_planar_eyes_pair_is_refused_for_eyes_in_space():
    from eyeviz import EyevizError

    with pytest.raises(EyevizError, match="the scene's eyes are spherical: use Eyes.model"):
        Eyes(nside=8).pair()
    assert Eyes().pair().m == 720
