"""Intervals to bitmaps: the window-table and packed paths against a direct definition."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from eyeviz.core import bits
from eyeviz.core.geometry import EyePair, intervals_to_bitmap


def _direct(L, R, m, width):
    k = np.arange(width)
    out = np.zeros((len(L), width), bool)
    for i, (lo, hi) in enumerate(zip(L, R, strict=True)):
        lit = {j % m for j in range(lo, hi + 1)}
        out[i] = [kk in lit for kk in k]
    return out


@st.composite
def intervals(draw):
    m = draw(st.sampled_from([4, 6, 8, 10, 16, 30, 64, 100, 720]))
    n = draw(st.integers(1, 12))
    L = np.array(draw(st.lists(st.integers(0, m - 1), min_size=n, max_size=n)))
    C = np.array(draw(st.lists(st.integers(0, m - 1), min_size=n, max_size=n)))
    width = draw(st.sampled_from([m, m // 2, 1, max(1, m - 3)]))
    return m, L, L + C, width


@settings(max_examples=200, deadline=None)
@given(intervals())
def test_bool_and_packed_bitmaps_match_the_definition(case):
    m, L, R, width = case
    want = _direct(L, R, m, width)
    got = bits.bool_bitmaps(L, R, m, width)
    assert got.dtype == bool and got.shape == want.shape
    assert (got == want).all()
    packed = bits.packed_bitmaps(L, R, m, width)
    assert (packed == np.packbits(want, axis=1)).all()


@pytest.mark.parametrize("width", [3000, 9000])
def test_wide_eyes_use_the_other_paths_and_agree(width):
    m = 2 * width
    rng = np.random.default_rng(width)
    L = rng.integers(0, m, 50)
    R = L + rng.integers(0, m, 50)
    L[:3], R[:3] = [0, m - 1, 5], [m - 1, m + 7, 5]
    want = _direct(L, R, m, width)
    assert (bits.bool_bitmaps(L, R, m, width) == want).all()
    assert (bits.packed_bitmaps(L, R, m, width) == np.packbits(want, axis=1)).all()


def test_bitmaps_of_features_keep_shape_and_agree_with_packed():
    eyes = EyePair(40, 20, 720)
    rng = np.random.default_rng(5)
    x = rng.uniform(-3000, 3000, (7, 9))
    y = rng.uniform(-3000, 3000, (7, 9))
    g = rng.uniform(1, 800, (7, 9))
    a, b = eyes.bitmaps(x, y, g)
    assert a.shape == (7, 9, 720)
    LA, RA, LB, RB = eyes.intervals(x, y, g)
    assert (intervals_to_bitmap(LB, RB, 720) == b).all()
    assert (bits.packed_bitmaps(LA, RA, 720, 360) == np.packbits(a[..., :360], axis=-1)).all()


def test_packed_per_byte_path_keeps_a_wrap_that_ends_on_ommatidium_zero():
    """Widths past the packed tables (> bits._PACKED_TABLE_MAX_W) wrap a run past m - 1
    onto 0, 1, ...; a run ending exactly on m (ommatidium 0) lights ommatidium 0 too."""
    m = 2 * (bits._PACKED_TABLE_MAX_W + 8)
    L = np.array([m - 3, m - 3, m - 1, 5])
    R = np.array([m, m + 1, m, 9])
    for w in (m, m // 2):
        want = np.packbits(_direct(L, R, m, w), axis=-1)
        np.testing.assert_array_equal(bits.packed_bitmaps(L, R, m, w), want)
