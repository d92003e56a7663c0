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
