"""Caps far below a facet (issue 35, item 4): their lit sets at a bounded cost, exactly."""

from __future__ import annotations

import numpy as np
import pytest

from eyeviz.core import exact3d
from eyeviz.core.geometry3d import EyePair3D


@pytest.fixture
def precisions(monkeypatch):
    """Record every (ball, cell) decision's working precision in exact3d."""
    seen: list[int] = []
    real = exact3d._decide

    def spy(*args):
        seen.append(args[-1])
        return real(*args)

    monkeypatch.setattr(exact3d, "_decide", spy)
    return seen


def test_the_campaign_ball_is_decided_on_a_few_cells_at_a_bounded_precision(precisions):
    """EyePair3D(40, 20, 8).lit(0, 1e12, 0, 1e-300) took 141 s: every candidate cell went
    to mpmath at ~6,500 bits. Its direction lies 4e-11 rad from a cell vertex, so a few
    cells need the exact test, at the precision of a cap of chord 2^-(96 + input bits)."""
    la, lb = EyePair3D(40.0, 20.0, 8).lit(0.0, 1e12, 0.0, 1e-300)
    assert la.tolist() == [375] and lb.tolist() == [376]
    assert 0 < len(precisions) <= 16
    assert max(precisions) <= 256 + 6 * (96 + 41) + 8


@pytest.mark.parametrize("g", [1e-20, 1e-300, 5e-324])
@pytest.mark.parametrize(
    "ball",
    [
        (40.0, 1.0, 2.0),  # eye B: on the meridian between two polar faces
        (40.0, 0.0, 3.0),  # on the north pole: the four cells around it
        (-40.0, 5.0, -7.0),  # eye A: on a meridian of the south cap
        (43.0, 3.0, 1.0),  # inside one cell
        (45.0, 5.0, 5.0 * 2**0.5),
    ],
)
def test_a_tiny_cap_on_a_boundary_lights_every_cell_around_its_centre(ball, g):
    """A cap centred on an edge or vertex meets every cell whose closure holds the centre
    (its interior reaches into each), whatever its size: the same cells as a cap of 1e-6
    rad, which no other boundary comes near."""
    e = EyePair3D(40.0, 20.0, 8)
    r = float(np.linalg.norm(ball))
    want = e.lit(*ball, 1e-6 * r)
    got = e.lit(*ball, g)
    for w, v in zip(want, got, strict=True):
        assert v.tolist() == w.tolist()


def test_tiny_and_ordinary_balls_in_one_call_keep_their_order():
    """Tiny caps are routed apart; the lit sets come back per ball, in the input order."""
    e = EyePair3D(40.0, 20.0, 16)
    rng = np.random.default_rng(3)
    p = rng.uniform(-300, 300, (12, 3))
    g = np.where(np.arange(12) % 3 == 0, 1e-200, rng.uniform(1, 40, 12))
    got = e.lit_csr(p[:, 0], p[:, 1], p[:, 2], g)
    for i in range(12):
        one = e.lit(*p[i], g[i])
        for (ptr, idx), w in zip(got, one, strict=True):
            assert idx[ptr[i] : ptr[i + 1]].tolist() == w.tolist()


def test_cell_lit_shrinks_the_precision_of_tiny_caps_only():
    """The exact test's answer for a tiny cap is that of a cap of chord 2^-(96 + bits):
    a cell whose closure holds the centre is lit, a neighbour 1e-11 rad away is not."""
    from fractions import Fraction

    from eyeviz.core import healpix

    n = 8
    X, Y, Z = Fraction(40), Fraction(10**12), Fraction(0)
    for pix, want in ((375, True), (376, False), (344, False), (408, False)):
        ix, iy, face = (int(v[0]) for v in healpix.pix2xyf(n, np.array([pix])))
        got = exact3d.cell_lit(n, X, Y, Z, Fraction(1e-300), face, ix, iy, pix)
        assert got is want
