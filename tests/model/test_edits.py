"""The one check of a value typed or dragged into a feature (eyeviz.model.edits), used by
the planar and the 3D app models with their messages unchanged."""

from __future__ import annotations

import math
import typing

import pytest

from eyeviz.model import app_model, app_model3d
from eyeviz.model.app_model import AppModel
from eyeviz.model.app_model3d import AppModel3D
from eyeviz.model.edits import feature_value
from eyeviz.model.scene import Eyes, Feature, Scene


def test_converts_and_refuses_in_one_line():
    assert feature_value("x", "2.5") == 2.5 and isinstance(feature_value("y", 3), float)
    assert feature_value("x", -1.0) == -1.0  # a coordinate may be <= 0
    for bad in (math.inf, -math.inf, math.nan):
        with pytest.raises(ValueError, match=r"^z must be finite, got (inf|-inf|nan)$"):
            feature_value("z", bad)
    with pytest.raises(ValueError, match=r"^g \(feature radius\) must be > 0, got 0.0$"):
        feature_value("g", 0)
    with pytest.raises(ValueError, match=r"^g \(ball radius\) must be > 0, got -1.0$"):
        feature_value("g", -1, "ball radius")
    with pytest.raises(ValueError):
        feature_value("x", "a lot")


def test_both_app_models_use_it():
    """No private copy is left in the one app model (the 3D page's is the same class), and
    each kind names its own radius."""
    assert typing.get_origin(app_model3d.AppModel3D) is app_model.AppModel
    for mod in (app_model, app_model3d):
        assert getattr(mod, "feature_value", feature_value) is feature_value
        assert not hasattr(mod, "_number") and not hasattr(mod, "_finite")
    planar = AppModel(Scene(Eyes(40.0, 20.0, 720), [Feature("a", 0.0, 1500.0, 50.0, "#D55E00")]))
    with pytest.raises(ValueError, match=r"^g \(feature radius\) must be > 0, got 0.0$"):
        planar.live(0, g=0.0)
    with pytest.raises(ValueError, match=r"^y must be finite, got nan$"):
        planar.set_feature(0, y=math.nan)
    sph = AppModel3D(
        Scene(Eyes(40.0, 20.0, nside=8), [Feature("b", 0.0, 300.0, 60.0, "#0072B2", 0.0)])
    )
    with pytest.raises(ValueError, match=r"^g \(ball radius\) must be > 0, got -2.0$"):
        sph.live(0, g=-2.0)
    with pytest.raises(ValueError, match=r"^z must be finite, got inf$"):
        sph.live(0, z=math.inf)
    assert planar.scene.features[0].g == 50.0 and sph.scene.features[0].z == 0.0
