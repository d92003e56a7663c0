"""One app model for every eye model (issue 37.2): the planar and the 3D pages' models are
one class, and what differs by scene kind is the state function of STATE_FUNCTIONS."""

from __future__ import annotations

import typing

import pytest

from eyeviz.model import app_model3d
from eyeviz.model.app_model import STATE_FUNCTIONS, AppModel
from eyeviz.model.scene import Eyes, Feature, Scene
from eyeviz.model.state import SceneState
from eyeviz.model.state3d import SceneState3D


def _planar() -> Scene:
    return Scene(
        Eyes(40.0, 20.0, 720),
        [Feature("a", 0.0, 1500.0, 50.0, "#D55E00")],
        ["eyes", "features", "predictions", "ambiguity"],
    )


def _spherical() -> Scene:
    return Scene(
        Eyes(40.0, 20.0, nside=8),
        [Feature("b", 0.0, 300.0, 60.0, "#0072B2", 0.0)],
        ["eyes", "features", "predictions"],
    )


def test_both_pages_share_one_class_and_each_kind_its_state_function():
    planar, sph = AppModel(_planar()), app_model3d.AppModel3D(_spherical())
    assert type(planar) is type(sph) is AppModel
    assert typing.get_origin(app_model3d.AppModel3D) is AppModel
    assert set(STATE_FUNCTIONS) == {"planar", "spherical"}  # Scene.kind's values
    assert isinstance(planar.state, SceneState) and isinstance(sph.state, SceneState3D)
    # the model follows its scene's kind: a spherical scene set into a planar model
    planar.set_scene(_spherical())
    assert isinstance(planar.state, SceneState3D) and planar.functions is sph.functions


def test_a_drag_changes_the_kinds_own_coordinates():
    planar, sph = AppModel(_planar()), app_model3d.AppModel3D(_spherical())
    with pytest.raises(ValueError, match=r"^live\(\) changes x, y or g only, got z$"):
        planar.live(0, z=5.0)
    with pytest.raises(ValueError, match=r"^live\(\) changes x, y, z or g only, got m$"):
        sph.live(0, m=5.0)
    sph.begin_live("Move b")
    sph.live(0, z=40.0)
    assert sph.state.z[0] == 40.0  # computed at the move (no row update in space)
    assert sph.end_live()
    planar.begin_live("Move a")
    planar.live(0, x=100.0)
    assert planar.state.x[0] == 100.0 and planar.end_live()


def test_the_planar_pages_overlays_are_not_computed_for_a_spherical_scene():
    sph = app_model3d.AppModel3D(_spherical())
    assert sph.scene.shows("predictions")
    assert sph.predictions == {} and sph.ambiguity is None
    assert sph.predictor is None  # nothing loaded: the 3D page computes its own


def test_names_of_added_and_duplicated_features_follow_each_page():
    planar, sph = AppModel(_planar()), app_model3d.AppModel3D(_spherical())
    planar.add_feature(10.0, 2000.0, 30.0)
    planar.duplicate_feature(0)
    assert [f.name for f in planar.scene.features] == ["a", "feature 1", "a (copy)"]
    sph.add_ball(0.0, 400.0, 10.0, 20.0)
    sph.duplicate_ball(0)
    assert [f.name for f in sph.scene.features] == ["b", "ball 1", "b copy 1"]
    assert sph.scene.features[1].z == 10.0 and sph.selected == 2
    sph.delete_ball(2)
    assert [f.name for f in sph.scene.features] == ["b", "ball 1"]
