"""The parameter record (eyeviz.core.domain.Domain): its bounds and its derived width."""

from __future__ import annotations

import pytest

from eyeviz.core.domain import DEFAULTS, Domain


def test_width_is_the_integer_half_of_m():
    for m in (4, 720, 36000):
        w = Domain(m=m).width
        assert isinstance(w, int) and w == m // 2
    assert Domain().width == int(DEFAULTS["m"]) // 2


def test_distances_and_size_only_need_to_be_positive_and_ordered():
    d = Domain(r_min=0.25, r_max=0.5, g_max=0.125)  # below 1, above 0: all fine
    assert (d.r_min, d.r_max, d.g_max) == (0.25, 0.5, 0.125)


@pytest.mark.parametrize(
    "kw, name",
    [
        ({"r_min": 0.0}, "r_min"),
        ({"r_min": -1.0}, "r_min"),
        ({"r_min": 0.0, "r_max": 0.0}, "r_min"),
        ({"r_max": 0.0, "r_min": -2.0}, "r_min"),
        ({"r_min": 300.0, "r_max": 300.0}, "r_min must be < r_max"),
        ({"r_min": 400.0, "r_max": 300.0}, "r_min must be < r_max"),
        ({"g_max": 0.0}, "g_max"),
        ({"m": 7}, "m must be an even integer"),
    ],
)
def test_bad_parameters_are_refused_naming_the_parameter(kw, name):
    with pytest.raises(ValueError, match=name):
        Domain(**kw)


def test_r_max_must_be_positive_itself():
    with pytest.raises(ValueError, match="^r_max"):
        Domain(r_min=1.0, r_max=0.0)


def test_one_door_makes_the_domain_of_every_kind_of_eyes(toy_pair):
    from eyeviz.core.domain import Domain3D, domain_for, domain_from_dict
    from eyeviz.core.geometry import EyePair
    from eyeviz.core.geometry3d import EyePair3D

    planar = domain_for(EyePair(30.0, 10.0, 36), r_min=500.0, g_max=None)
    assert planar == Domain(30.0, 10.0, 36, r_min=500.0) and planar.kind == "planar"
    assert planar.facet_counts == (36, 36) and planar.origin == (0.0, 0.0)
    assert Domain.from_eyes(EyePair(30.0, 10.0, 36), r_min=500.0) == planar
    sph = domain_for(EyePair3D(30.0, 10.0, 4), r_min=500.0)
    assert sph == Domain3D(30.0, 10.0, 4, r_min=500.0) and sph.kind == "spherical"
    assert sph.facet_counts == (192, 192) and sph.origin == (0.0, 0.0, 0.0)
    meas = domain_for(toy_pair)
    assert meas == Domain3D.for_eyes(toy_pair) and meas.kind == "measured"
    assert domain_from_dict(planar.to_dict()) == planar
    assert domain_from_dict(sph.to_dict()) == sph
    assert domain_from_dict(meas.to_dict(), eyes=toy_pair) == meas


def test_a_record_takes_only_its_own_kinds_and_ranges():
    from eyeviz.core.domain import Domain3D, domain_for, domain_from_dict
    from eyeviz.core.geometry import EyePair
    from eyeviz.core.geometry3d import EyePair3D

    with pytest.raises(ValueError, match="^a planar domain takes planar eyes, got 'spherical'$"):
        Domain.for_eyes(EyePair3D(30.0, 10.0, 4))
    with pytest.raises(
        ValueError, match="^a 3D domain takes spherical or measured eyes, got 'planar'$"
    ):
        Domain3D.for_eyes(EyePair(30.0, 10.0, 36))
    with pytest.raises(ValueError, match="takes planar, spherical or measured eyes, got None"):
        domain_for(object())
    with pytest.raises(ValueError, match="^unknown range 'el_max' \\(r_min, r_max, g_max\\)$"):
        domain_for(EyePair(30.0, 10.0, 36), el_max=0.5)
    with pytest.raises(ValueError, match="exactly one of m .* got m and nside"):
        domain_from_dict({"m": 36, "nside": 4})


def test_each_record_names_its_design_and_says_it_in_words(toy_pair):
    """What callers ask the domain instead of comparing its kind (issue 37)."""
    from eyeviz.core.domain import Domain3D, domain_for

    planar = Domain(30.0, 10.0, 36)
    assert dict(zip(planar.design_names, planar.design, strict=True)) == {
        "h": 30.0, "l": 10.0, "m": 36}  # fmt: skip
    sph = Domain3D(30.0, 10.0, 4)
    assert sph.design_names == ("h", "l", "nside")
    assert sph.design_text == "(h, l, nside) = (30.0, 10.0, 4)"
    meas = domain_for(toy_pair)
    assert meas.design_names == ("h", "l", "fingerprint")
    assert meas.design[2] == toy_pair.fingerprint
    fp = str(toy_pair.fingerprint)[:12]
    assert meas.design_text == f"h={meas.h:g} l={meas.l:g} measured pair {fp}"
