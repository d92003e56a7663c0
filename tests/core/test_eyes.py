"""The eye-model seam (eyeviz.core.eyes): the planar EyePair is one implementation."""

from __future__ import annotations

import numpy as np
import pytest

from eyeviz import EyevizError
from eyeviz.core.eyes import EyeModel, design_kind, eyes_from_design
from eyeviz.core.geometry import EyePair


def test_planar_pair_is_an_eye_model():
    eyes = EyePair(40.0, 20.0, 720)
    assert isinstance(eyes, EyeModel)
    assert (eyes.kind, eyes.dims, eyes.facets) == ("planar", 2, 720)
    assert eyes.design == {"h": 40.0, "l": 20.0, "m": 720}


def test_design_round_trip_gives_the_same_pair():
    eyes = EyePair(25.0, 7.5, 36)
    again = eyes_from_design(eyes.design)
    assert again == eyes


def test_seam_predicates_agree_with_the_planar_methods():
    eyes = eyes_from_design({"h": 40.0, "l": 20.0, "m": 720})
    x, y, g = np.array([0.0, 300.0, -50.0]), np.array([1500.0, 900.0, 40.0]), np.array([50, 5, 3])
    oa, ob = eyes.bitmaps(x, y, g)
    assert oa.shape == (3, eyes.facets) and ob.shape == (3, eyes.facets)
    va, vb = eyes.visible(x, y, g)
    assert np.array_equal(va, oa.sum(axis=-1) >= 2)
    assert np.array_equal(vb, ob.sum(axis=-1) >= 2)


@pytest.mark.parametrize(
    ("design", "kind"),
    [({"h": 1, "l": 0.5, "m": 8}, "planar"), ({"h": 1, "l": 0.5, "nside": 2}, "spherical")],
)
def test_design_kind(design, kind):
    assert design_kind(design) == kind


@pytest.mark.parametrize("design", [{"h": 1, "l": 0.5}, {"h": 1, "l": 0.5, "m": 8, "nside": 2}])
def test_design_must_name_exactly_one_facet_parameter(design):
    with pytest.raises(EyevizError, match="exactly one of m .* or nside") as exc:
        eyes_from_design(design)
    assert "\n" not in str(exc.value)


def test_model_checks_still_apply():
    with pytest.raises(ValueError, match="m must be an even integer"):
        eyes_from_design({"h": 40.0, "l": 20.0, "m": 7})
