"""The design grid: every (h, l, m) with l < h; bad input ends in one named line."""

import pytest

from eyeviz import EyevizError
from eyeviz.study.grid import DEFAULT_H, DEFAULT_L, DEFAULT_M, design_grid, parse_list
from eyeviz.study.point import DesignPoint


def test_parse_list():
    assert parse_list("h", "10, 20,40") == [10.0, 20.0, 40.0]
    assert parse_list("m", [180, 360]) == [180.0, 360.0]
    assert parse_list("l", "1e1") == [10.0]


@pytest.mark.parametrize(
    ("text", "words"),
    [
        ("10,x", ["h", "'x'", "not a number"]),
        ("", ["h", "empty"]),
        ("10,,20", ["h", "empty item"]),
        ("10,nan", ["h", "nan", "finite"]),
        ("inf", ["h", "finite"]),
    ],
)
def test_parse_list_refuses_non_numbers(text, words):
    with pytest.raises(EyevizError) as err:
        parse_list("h", text)
    msg = str(err.value)
    assert "\n" not in msg
    for w in words:
        assert w in msg


def test_default_grid_is_every_design_with_l_below_h():
    points = design_grid(n=1000)
    combos = {(p.h, p.l, p.m) for p in points}
    expected = {(h, l, m) for h in DEFAULT_H for l in DEFAULT_L for m in DEFAULT_M if l < h}
    assert combos == expected
    assert len(points) == len(expected) == 60  # 12 (h, l) pairs x 5 m
    assert (40.0, 20.0, 720) in combos  # the paper's design (Table 3)
    assert all(isinstance(p, DesignPoint) and p.n == 1000 for p in points)
    assert len({p.key for p in points}) == len(points)


def test_grid_options_reach_every_point_and_duplicates_drop():
    pts = design_grid(
        "20,20,40", "10", "8,8", r_min=500, r_max=900, g_max=3, prior="multi", n=7, seed=5
    )
    assert [(p.h, p.l, p.m) for p in pts] == [(20.0, 10.0, 8), (40.0, 10.0, 8)]
    for p in pts:
        assert (p.r_min, p.r_max, p.g_max, p.prior, p.n, p.seed) == (500, 900, 3, "multi", 7, 5)


@pytest.mark.parametrize(
    ("kwargs", "words"),
    [
        ({"h": "5,10", "l": "10,20"}, ["no design", "l < h", "h: 5, 10", "l: 10, 20"]),
        ({"h": "5", "l": "5"}, ["no design", "l < h"]),
        ({"m": "180,361"}, ["m must be an even integer", "361"]),
        ({"m": "2"}, ["m must be an even integer", "got 2"]),
        ({"m": "7.5"}, ["m must be an even integer", "7.5"]),
        ({"n": 0}, ["n must be", "got 0"]),
        ({"n": -3}, ["n must be", "-3"]),
        ({"n": 2.5}, ["n must be an integer"]),
        ({"seed": -1}, ["seed", "-1"]),
        ({"prior": "double"}, ["prior", "'double'"]),
        ({"h": "-10", "l": "5"}, ["h must be", "-10"]),
        ({"r_min": 5000, "r_max": 1000}, ["r_max", "1000"]),
        ({"r_max": 1e12}, ["distance bins"]),
        ({"m": "1,2,3"}, ["m must be an even integer", "got 1"]),
        ({"h": "ten"}, ["h:", "'ten'", "not a number"]),
    ],
)
def test_bad_grids_end_in_one_named_line(kwargs, words):
    with pytest.raises(EyevizError) as err:
        design_grid(**kwargs)
    msg = str(err.value)
    assert "\n" not in msg
    for w in words:
        assert w in msg, msg


def test_one_number_is_a_list_of_one_and_a_non_list_is_one_line():
    """design_grid(m=720) was a TypeError ('int' object is not iterable)."""
    assert design_grid(h=40, l=20.0, m=720, n=10) == design_grid("40", "20", "720", n=10)
    for bad in (None, object()):
        with pytest.raises(EyevizError, match="^m must be numbers separated by commas or a list"):
            design_grid(m=bad)
    with pytest.raises(EyevizError, match="^h: True is not a finite number"):
        design_grid(h=True)


@pytest.mark.parametrize("grid", ["planar", "3d"])
def test_a_seed_the_table_cannot_hold_is_refused_before_any_point(grid):
    """A 20-digit seed was taken, its first point computed, and then refused when its
    row was checked before the append (the tables' integers have at most 19 digits)."""
    from eyeviz.study.grid import design_grid3d

    make = design_grid if grid == "planar" else design_grid3d
    res = {"m": "16"} if grid == "planar" else {"nside": "4"}
    assert make("40", "20", **res, n=10, seed=10**19 - 1)[0].seed == 10**19 - 1
    with pytest.raises(
        EyevizError, match=r"^seed must be an integer >= 0 and <= 9999999999999999999"
    ):
        make("40", "20", **res, n=10, seed=10**19)
