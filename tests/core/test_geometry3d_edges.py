"""Spherical geometry at the edges its other tests do not reach: a one-ball call with a
bad radius or a NaN (the compiled single-ball path), balls a hair from the binocular
wedge's boundary, and eye overlaps of balls at the scale of the eyes."""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np
import pytest

from eyeviz.core import kernels
from eyeviz.core.geometry3d import EyePair3D


@pytest.mark.parametrize(
    "ball",
    [(100.0, 900.0, 5.0, 0.0), (100.0, 900.0, 5.0, -3.0), (math.nan, 900.0, 5.0, 10.0),
     (100.0, math.inf, 5.0, 10.0), (100.0, 900.0, 5.0, math.nan)],
)  # fmt: skip
def test_one_ball_of_python_floats_with_a_bad_radius_or_coordinate_is_refused(ball):
    kernels.warm()  # a drag frame's path: one ball straight to the compiled kernel
    pair = EyePair3D(40.0, 20.0, 16)
    one_line = r"(> 0: 1 value\(s\) are not|1 non-finite value\(s\) \(NaN or inf\))$"
    with pytest.raises(ValueError, match=one_line):  # no index for a single ball
        pair.lit_csr(*ball)


def _in_bfv_exact(h, l, x, y, z, g) -> bool:
    X, Y, Z, G, H, L = (Fraction(v) for v in (x, y, z, g, h, l))
    return Y >= G and (H * H - L * L) * (Y * Y + Z * Z) >= (L * abs(X) + G * H) ** 2


def test_balls_a_few_ulps_from_the_wedge_boundary_are_decided_exactly():
    # h = 5, l = 3: w = sqrt(h^2 - l^2) = 4 exactly, so the boundary 4 |(y, z)| = 3 |x| + 5 g
    # is met by g = (4 hypot(y, z) - 3 |x|) / 5, irrational for most (y, z): the balls
    # straddle it by a few ulps, where the float comparison alone is wrong for some
    pair = EyePair3D(5.0, 3.0, 4)
    rng = np.random.default_rng(5)
    xs, ys, zs, gs = [], [], [], []
    for _ in range(150):
        y, z = float(rng.uniform(1, 50)), float(rng.uniform(-50, 50))
        x = float(rng.uniform(-1, 1)) * math.hypot(y, z)
        g = (4 * math.hypot(y, z) - 3 * abs(x)) / 5
        for _ in range(4):
            g = math.nextafter(g, 0.0)
        for _ in range(9):
            xs.append(x), ys.append(y), zs.append(z), gs.append(g)
            g = math.nextafter(g, math.inf)
    x, y, z, g = (np.array(v) for v in (xs, ys, zs, gs))
    got = pair.in_bfv(x, y, z, g)
    want = [_in_bfv_exact(5.0, 3.0, *b) for b in zip(xs, ys, zs, gs, strict=True)]
    assert got.tolist() == want
    naive = (4 * np.hypot(y, z) >= 3 * np.abs(x) + 5 * g) & (y >= g)
    assert (naive != np.array(want)).sum() >= 5  # the float comparison alone errs here


def test_eye_overlaps_at_the_eyes_scale_match_exact_arithmetic():
    # balls the size of the eyes and as near (coordinates of order l): every coordinate
    # matters to the distance, not only x
    pair = EyePair3D(4.0, 2.0, 4)
    rng = np.random.default_rng(8)
    x = rng.uniform(-8, 8, 400).round(2)
    y = rng.uniform(-4, 4, 400).round(2)
    z = rng.uniform(-4, 4, 400).round(2)
    g = rng.uniform(0.1, 3, 400).round(2)
    oa, ob = pair.overlaps_eye(x, y, z, g)
    for got, cx in ((oa, -4.0), (ob, 4.0)):
        want = [
            (Fraction(a) - Fraction(cx)) ** 2 + Fraction(b) ** 2 + Fraction(c) ** 2
            <= (Fraction(d) + 2) ** 2
            for a, b, c, d in zip(x, y, z, g, strict=True)
        ]
        assert got.tolist() == want
        assert 20 < sum(want) < 380


@pytest.mark.parametrize("jit", ["0", "1"])
def test_a_ball_whose_sphere_passes_a_few_ulps_from_the_eye_centre(monkeypatch, jit):
    # the eye is whole (every facet lit) iff its centre is in the closed ball, d <= g;
    # d is irrational here and g steps over the floats around it, where sqrt's and the
    # squares' rounding leave the float comparison wrong for some
    monkeypatch.setenv("EYEVIZ_JIT", jit)
    if jit == "1":
        kernels.warm()
    pair = EyePair3D(40.0, 20.0, 2)
    rng = np.random.default_rng(12)
    xs, ys, zs, gs = [], [], [], []
    for _ in range(60):
        a, b, c = (float(v) for v in rng.uniform(-3, 3, 3))
        a = (40.0 + a) - 40.0  # exact both ways: the ball's x is 40 + a to the bit
        g = math.sqrt(a * a + b * b + c * c)
        for _ in range(3):
            g = math.nextafter(g, 0.0)
        for _ in range(7):
            xs.append(40.0 + a), ys.append(b), zs.append(c), gs.append(g)
            g = math.nextafter(g, math.inf)
    x, y, z, g = (np.array(v) for v in (xs, ys, zs, gs))
    ((pb, _),) = pair.lit_csr(x, y, z, g)[1:]
    got = np.diff(pb) == pair.npix
    dx = x - 40.0  # exact (see a above)
    want = [
        Fraction(u) ** 2 + Fraction(v) ** 2 + Fraction(w) ** 2 <= Fraction(r) ** 2
        for u, v, w, r in zip(dx, y, z, g, strict=True)
    ]
    assert got.tolist() == want
    naive = np.sqrt(dx * dx + y * y + z * z) <= g
    assert (naive != np.array(want)).sum() >= 3  # a plain sqrt comparison errs on some
