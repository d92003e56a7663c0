"""The spherical lit sets against the independent high-precision reference, random and
adversarial balls (cap tangent at an equator vertex, at a pole, at +y from above, eye
centre on the sphere, caps centred on a pole), at small nside: 100 % agreement."""

from __future__ import annotations

import numpy as np
import pytest

from eyeviz.core.geometry3d import EyePair3D
from eyeviz.reference.healpix_reference import pixel_centre, reference_lit

H = 40.0


def adversarial(rng: np.random.Generator, k: int = 2):
    """(x, y, z, g) rows built to touch cell vertices exactly, for eye B at (40, 0, 0)."""
    rows = []
    for _ in range(k):
        s = float(rng.integers(1, 40))
        free = float(rng.integers(-300, 300)) / 4
        rows += [
            (H + free, s, 0.0, s),  # resting on z = 0 ... and on y = 0: vertex at phi 0 / pi
            (H + 3 * s, 4 * s, free, 5 * s),  # dx^2 + dy^2 = g^2: touches a pole
            (H + 3 * s, abs(free) + 1, 4 * s, 5 * s),  # dx^2 + dz^2 = g^2: touches +y
            (H + s, free, 0.0, s),  # touching the vertical x = h + g: vertex at pi/2
            (H + 3.0, 4.0, 0.0, 5.0),  # the eye centre on the ball's sphere: whole eye
            (H, 0.0, free if free else 7.0, s / 2),  # centred on a pole direction
        ]
    return np.array(rows).T


def _compare(nside, x, y, z, g):
    e = EyePair3D(H, 20.0, nside)
    (pa, ia), (pb, ib) = e.lit_csr(x, y, z, g)
    bad = []
    for i in range(x.size):
        ref = reference_lit(nside, x[i], y[i], z[i], g[i], H)
        if not np.array_equal(ref, ib[pb[i] : pb[i + 1]]):
            bad.append((x[i], y[i], z[i], g[i]))
    assert not bad, f"{len(bad)} of {x.size} differ, first {bad[0]}"


@pytest.mark.parametrize("nside", [2, 4, 6])
def test_adversarial_balls_agree_with_the_reference(nside):
    rng = np.random.default_rng(nside)
    x, y, z, g = adversarial(rng, 1)
    _compare(nside, x, y, z, g)


@pytest.mark.parametrize("nside", [2, 4])
def test_random_balls_agree_with_the_reference(nside):
    rng = np.random.default_rng(10 + nside)
    p = rng.normal(size=(3, 5)) * rng.uniform(30, 300, 5)
    _compare(nside, p[0], p[1], p[2], rng.uniform(1, 100, 5))


@pytest.mark.slow
@pytest.mark.parametrize("nside", [2, 4, 6, 8])
def test_many_balls_agree_with_the_reference(nside):
    rng = np.random.default_rng(100 + nside)
    x, y, z, g = adversarial(rng, 4)
    p = rng.normal(size=(3, 20)) * rng.uniform(30, 300, 20)
    _compare(
        nside,
        np.concatenate([x, p[0]]),
        np.concatenate([y, p[1]]),
        np.concatenate([z, p[2]]),
        np.concatenate([g, rng.uniform(1, 100, 20)]),
    )


def test_reference_centres_are_exact_rationals():
    z, tt = pixel_centre(6, 12 * 36 // 2)  # the first pixel of ring 3n... or of the equator
    assert z.denominator % 3 == 0 or z == 0
    assert 0 <= tt < 4


EXTREME = [
    (1e15, 3e14, -2e14, 1e13),  # far away
    (H + 1e-9, 1e-9, 0.0, 5e-10),  # tiny and next to the eye centre
    (41.0, 0.0, 0.0, float(np.nextafter(1.0, 0.0))),  # grazing: the eye centre 1 ulp out
    (H + 3.0, 4.0, 0.0, float(np.nextafter(5.0, 0.0))),  # grazing with a 3-4-5 triangle
    (-1e6, 3.0, 1e6, 1.41e6),  # a huge cap
    (H, 1e-310, 5.0, 4.995),  # subnormal y: a cap about the north pole
    (0.1, 0.2, 0.3, 0.05),
]


@pytest.mark.slow
@pytest.mark.parametrize("ball", EXTREME)
def test_extreme_scales_agree_with_the_reference(ball):
    _compare(4, *(np.array([v]) for v in ball))


@pytest.mark.slow
@pytest.mark.parametrize(
    "ball",
    [(1e-200, 1e-200, 1e-200, 1e-210), (H, 0.0, 1e-300, 1e-301)],  # exponents 600 apart
)
def test_inputs_needing_thousands_of_bits_agree_with_the_reference(ball):
    _compare(4, *(np.array([v]) for v in ball))
