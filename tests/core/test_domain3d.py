"""Domain3D: the paper's defaults read from DEFAULTS, every field checked with one line
naming it, and a dict round trip."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from eyeviz import EyevizError
from eyeviz.core.bounds import MAX_NSIDE
from eyeviz.core.domain import DEFAULT_EL_MAX, DEFAULTS, DEFAULTS3D, PAPER_DOMAIN3D, Domain3D


def test_defaults_are_the_papers_and_the_stated_band():
    d = Domain3D()
    for k in ("h", "l", "r_min", "r_max", "g_max"):
        assert getattr(d, k) == DEFAULTS[k]
    assert d.m == DEFAULTS["m"] == 720 and d.nside == 180
    assert d.npix == 12 * 180**2 == 388_800
    assert d.el_max == DEFAULT_EL_MAX == math.pi / 6 == DEFAULTS3D["el_max"]
    assert math.isclose(d.psi, math.asin(20 / 40)) and math.isclose(d.gamma, 2 * math.pi / 720)
    assert PAPER_DOMAIN3D == d and d.design == (40.0, 20.0, 180)


@pytest.mark.parametrize(
    "kw, message",
    [
        (dict(nside=7), "nside must be an even integer >= 2 and <= 1048576, got 7"),
        (dict(nside=0), "nside must be an even integer >= 2"),
        (dict(nside=MAX_NSIDE + 2), "nside must be an even integer >= 2 and <= 1048576"),
        (dict(nside=True), "nside must be an even integer"),
        (dict(nside="180"), "nside must be an even integer"),
        (dict(h=20.0, l=20.0), "l must be < h"),
        (dict(h=10.0, l=20.0), "l must be < h"),
        (dict(l=0.0), "l must be a finite number > 0, got 0.0"),
        (dict(h=math.inf), "h must be a finite number > 0, got inf"),
        (dict(el_max=0.0), "el_max must be a finite number > 0 and < 1.5708, got 0.0"),
        (dict(el_max=math.pi / 2), "el_max must be a finite number > 0 and < 1.5708"),
        (dict(el_max=-0.1), "el_max must be a finite number > 0"),
        (dict(el_max=math.nan), "el_max must be a finite number > 0 and < 1.5708, got nan"),
        (dict(r_min=3000.0, r_max=2000.0), "r_min must be < r_max"),
        (dict(r_min=-1.0), "r_min must be a finite number > 0, got -1.0"),
        (dict(g_max=0.0), "g_max must be a finite number > 0, got 0.0"),
    ],
)
def test_refusals_are_one_line_naming_the_parameter(kw, message):
    with pytest.raises(EyevizError) as info:
        Domain3D(**kw)
    text = str(info.value)
    assert text.startswith(message) and "\n" not in text, text


def test_values_are_converted_and_the_record_is_frozen():
    d = Domain3D(h=np.float64(30), l=10, nside=np.int64(16), r_min=500, r_max=900.5)
    assert type(d.nside) is int and d.nside == 16 and type(d.l) is float and d.r_max == 900.5
    with pytest.raises(dataclasses.FrozenInstanceError):
        d.nside = 8  # type: ignore[misc]


def test_dict_round_trip_and_unknown_keys():
    d = Domain3D(h=30, l=10, nside=16, r_min=100, r_max=400, g_max=60, el_max=0.25)
    back = Domain3D.from_dict(d.to_dict())
    assert back == d and back.to_dict() == d.to_dict()
    assert Domain3D.from_dict({"nside": 8, "ignored": 1}) == Domain3D(nside=8)
    with pytest.raises(EyevizError, match="nside must be an even integer"):
        Domain3D.from_dict({"nside": 9})
    with pytest.raises(EyevizError, match="must be a dict"):
        Domain3D.from_dict([("nside", 8)])  # type: ignore[arg-type]


def test_eyes_are_the_spherical_pair_of_the_design():
    from eyeviz.core.geometry3d import EyePair3D

    d = Domain3D(h=30, l=10, nside=16)
    eyes = d.eyes
    assert isinstance(eyes, EyePair3D)
    assert (eyes.h, eyes.l, eyes.nside, eyes.npix, eyes.m) == (30.0, 10.0, 16, d.npix, d.m)
    assert math.isclose(eyes.psi, d.psi)


# --- a measured pair's domain (docs/measured.md) ----------------------------------------


def test_measured_domain_defaults_are_the_papers_ratios_at_the_animals_scale(honeybee):
    """r_max = h / dphi (the paper's r_max = 5000 is 40 / (2 pi / 720) = 4584 to 10 %),
    r_min = r_max / 5, g_max = r_min / 2, el_max = pi/2; h, l the pair's own."""
    from eyeviz.core.domain import facet_spacing, measured_ranges

    d = Domain3D.for_eyes(honeybee)
    dphi = np.median([facet_spacing(e.unit_axes) for e in (honeybee.eye_a, honeybee.eye_b)])
    u = honeybee.eye_a.unit_axes  # every facet's nearest neighbour: the sample's target
    c = u @ u.T
    np.fill_diagonal(c, -2.0)
    full = float(np.median(np.arccos(np.clip(c.max(axis=1), -1, 1))))
    assert math.isclose(dphi, full, rel_tol=0.01) and 1.1 < math.degrees(full) < 1.2
    assert (d.kind, d.nside, d.facet_counts) == ("measured", None, (3187, 3187))
    assert (d.h, d.l) == (honeybee.h, honeybee.l)
    assert math.isclose(d.r_max, honeybee.h / dphi) and math.isclose(d.r_min, d.r_max / 5)
    assert math.isclose(d.g_max, d.r_min / 2) and d.el_max == math.pi / 2
    assert 10 < d.r_min < 20 and 70 < d.r_max < 90  # millimetres: a bee's working range
    assert measured_ranges(honeybee)["r_max"] == d.r_max and d.gamma == dphi
    # the rule at the paper's eyes: h / gamma = 4584 against the paper's r_max = 5000
    assert abs(40 / (2 * math.pi / 720) - 5000) / 5000 < 0.1


def test_measured_domain_ranges_are_given_or_checked(toy_pair):
    d = Domain3D.for_eyes(toy_pair, r_min=3.0, r_max=9.0, g_max=None, el_max=1.0)
    assert (d.r_min, d.r_max, d.el_max) == (3.0, 9.0, 1.0) and d.g_max > 0
    assert Domain3D.for_eyes(toy_pair, el_max=math.pi / 2).el_max == math.pi / 2
    for kw, msg in (
        (dict(r_min=9.0, r_max=3.0), "r_min must be < r_max"),
        (dict(el_max=1.6), "el_max must be a finite number > 0 and <= 1.5708"),
        (dict(g_max=-1.0), "g_max must be a finite number > 0"),
        (dict(nside=4), "unknown range 'nside'"),
    ):
        with pytest.raises(EyevizError, match=msg) as info:
            Domain3D.for_eyes(toy_pair, **kw)
        assert "\n" not in str(info.value)
    with pytest.raises(EyevizError, match="takes h and l from the eyes and has no nside"):
        Domain3D(eyes=toy_pair)  # h, l of the paper, nside 180: not this pair's


def test_measured_domain_has_no_healpix_numbers_but_an_origin(toy_pair):
    d = Domain3D.for_eyes(toy_pair)
    for what in ("npix", "m", "psi"):
        with pytest.raises(EyevizError, match=f"{what} is a property of HEALPix eyes"):
            getattr(d, what)
    a, b = toy_pair.centers
    assert d.origin == tuple((p + q) / 2 for p, q in zip(a, b, strict=True))
    assert Domain3D().origin == (0.0, 0.0, 0.0) and Domain3D().facet_counts == (388_800,) * 2


def test_measured_domain_dict_round_trip_checks_the_fingerprint(toy_pair, honeybee):
    d = Domain3D.for_eyes(toy_pair, r_min=3.0)
    dd = d.to_dict()
    assert dd["eye"] == toy_pair.fingerprint and "nside" not in dd
    assert (dd["n_a"], dd["n_b"]) == toy_pair.facet_counts
    back = Domain3D.from_dict(dd, eyes=toy_pair)
    assert back == d and hash(back) == hash(d) and back.design == d.design
    with pytest.raises(EyevizError, match="fingerprint .* is not the design's"):
        Domain3D.from_dict(dd, eyes=honeybee)
    with pytest.raises(EyevizError, match="needs its eye pair"):
        Domain3D.from_dict(dd)
    assert d != Domain3D.for_eyes(honeybee, r_min=3.0, r_max=d.r_max, g_max=d.g_max)


def test_healpix_domain_of_its_eyes_is_the_same_record():
    from eyeviz.core.geometry3d import EyePair3D

    eyes = EyePair3D(30.0, 10.0, 16)
    d = Domain3D.for_eyes(eyes, r_min=500.0)
    assert d == Domain3D(30.0, 10.0, 16, r_min=500.0) and d.eyes is eyes
    assert d.kind == "spherical" and d.to_dict() == Domain3D(30.0, 10.0, 16, 500.0).to_dict()
