"""Domain3D: the paper's defaults read from DEFAULTS, every field checked with one line
naming it, and a dict round trip."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from eyeviz import EyevizError
from eyeviz.core.bounds import MAX_NSIDE
from eyeviz.core.domain import DEFAULTS
from eyeviz.core.domain3d import DEFAULT_EL_MAX, DEFAULTS3D, PAPER_DOMAIN3D, Domain3D


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
