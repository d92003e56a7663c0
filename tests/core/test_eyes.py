"""The eye-model seam (eyeviz.core.eyes): planar, HEALPix and measured pairs implement it."""

from __future__ import annotations

import numpy as np
import pytest

from eyeviz import EyevizError
from eyeviz.core.eyes import EyeModel, design_kind, eyes_from_design
from eyeviz.core.geometry import EyePair


def test_planar_pair_is_an_eye_model():
    eyes = EyePair(40.0, 20.0, 720)
    assert isinstance(eyes, EyeModel)
    assert (eyes.kind, eyes.dims, eyes.facet_counts) == ("planar", 2, (720, 720))
    assert eyes.design == {"h": 40.0, "l": 20.0, "m": 720}


def test_design_round_trip_gives_the_same_pair():
    eyes = EyePair(25.0, 7.5, 36)
    again = eyes_from_design(eyes.design)
    assert again == eyes


def test_seam_predicates_agree_with_the_planar_methods():
    eyes = eyes_from_design({"h": 40.0, "l": 20.0, "m": 720})
    x, y, g = np.array([0.0, 300.0, -50.0]), np.array([1500.0, 900.0, 40.0]), np.array([50, 5, 3])
    oa, ob = eyes.bitmaps(x, y, g)
    assert (oa.shape[1], ob.shape[1]) == eyes.facet_counts == (720, 720) and len(oa) == 3
    va, vb = eyes.visible(x, y, g)
    assert np.array_equal(va, oa.sum(axis=-1) >= 2)
    assert np.array_equal(vb, ob.sum(axis=-1) >= 2)


@pytest.mark.parametrize(
    ("design", "kind"),
    [
        ({"h": 1, "l": 0.5, "m": 8}, "planar"),
        ({"h": 1, "l": 0.5, "nside": 2}, "spherical"),
        ({"eye": "ab" * 32, "n_a": 3, "n_b": 4}, "measured"),
    ],
)
def test_design_kind(design, kind):
    assert design_kind(design) == kind


@pytest.mark.parametrize(
    "design",
    [{"h": 1, "l": 0.5}, {"h": 1, "l": 0.5, "m": 8, "nside": 2}, {"m": 8, "eye": "ab" * 32}],
)
def test_design_must_name_exactly_one_facet_parameter(design):
    with pytest.raises(EyevizError, match="exactly one of m .*, nside .* or eye") as exc:
        eyes_from_design(design)
    assert "\n" not in str(exc.value)


def test_model_checks_still_apply():
    with pytest.raises(ValueError, match="m must be an even integer"):
        eyes_from_design({"h": 40.0, "l": 20.0, "m": 7})


def _tiny_measured():
    from eyeviz.core.measured import MeasuredEye, MeasuredEyePair

    rng = np.random.default_rng(3)
    eyes = []
    for sign, n in ((-1, 5), (1, 7)):
        pos = rng.normal(0, 0.1, (n, 3)) + [sign * 2.0, 0, 0]
        ax = rng.normal(0, 1, (n, 3)) + [0, 3, 0]
        eyes.append(MeasuredEye(pos, ax, np.full(n, 0.2), name="AB"[sign > 0]))
    return MeasuredEyePair(eyes[0], eyes[1])


def test_facet_counts_on_every_model():
    """Each model answers (n_A, n_B), and its bitmaps have those widths per eye."""
    from eyeviz.core.geometry3d import EyePair3D

    planar, healpix, measured = EyePair(40.0, 20.0, 36), EyePair3D(40.0, 20.0, 4), _tiny_measured()
    assert planar.facet_counts == (36, 36) and planar.m == 36
    assert healpix.facet_counts == (192, 192) and (healpix.npix, healpix.m) == (192, 16)
    assert measured.facet_counts == (5, 7)
    for eyes in (healpix, measured):
        assert isinstance(eyes, EyeModel)
        oa, ob = eyes.bitmaps(np.array([0.0, 1.0]), np.array([50.0, 40.0]), np.zeros(2), 5.0)
        assert (oa.shape[-1], ob.shape[-1]) == eyes.facet_counts
    oa, ob = planar.bitmaps(0.0, 1500.0, 50.0)
    assert (oa.shape[-1], ob.shape[-1]) == planar.facet_counts
    # the count is facet_counts everywhere: no model keeps a `facets` count property
    assert not any(isinstance(vars(type(e)).get("facets"), property) for e in (planar, healpix))


def test_a_measured_design_names_its_kind_but_not_its_arrays():
    pair = _tiny_measured()
    assert design_kind(pair.design) == "measured"
    with pytest.raises(EyevizError, match="names its eyes by fingerprint only") as exc:
        eyes_from_design(pair.design)
    assert "\n" not in str(exc.value)
