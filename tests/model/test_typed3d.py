"""Typed coordinates of a 3D ball (issue 32.6): r, azimuth, elevation keep the other two."""

from __future__ import annotations

import math

import pytest

from eyeviz.model.scene import Feature
from eyeviz.model.typed3d import typed_ball


def _ball() -> Feature:
    return Feature("b", x=300.0, y=400.0, g=50.0, z=0.0)


def test_r_keeps_the_direction_and_angles_keep_r():
    x, y, z, g = typed_ball(_ball(), "r", "1000")
    assert (x, y, z, g) == pytest.approx((600.0, 800.0, 0.0, 50.0))
    x, y, z, _ = typed_ball(_ball(), "el", "30")
    assert math.hypot(x, y, z) == pytest.approx(500.0)
    assert math.degrees(math.atan2(z, math.hypot(x, y))) == pytest.approx(30.0)
    assert math.degrees(math.atan2(y, x)) == pytest.approx(math.degrees(math.atan2(400, 300)))
    x, y, z, _ = typed_ball(_ball(), "az", "90")
    assert (x, y, z) == pytest.approx((0.0, 500.0, 0.0), abs=1e-9)
    assert typed_ball(_ball(), "z", "7")[2] == 7.0


@pytest.mark.parametrize(
    ("key", "text", "msg"),
    [("r", "0", "r must be > 0"), ("el", "91", "elevation must be within [-90, 90]"),
     ("az", "north", "azimuth must be a number, got 'north'"), ("g", "-1", "g (ball radius)"),
     ("x", "nan", "x must be finite"), ("w", "1", "cannot type 'w'")],
)  # fmt: skip
def test_bad_values_are_one_line(key, text, msg):
    with pytest.raises(ValueError) as e:
        typed_ball(_ball(), key, text)
    assert msg in str(e.value) and "\n" not in str(e.value)
