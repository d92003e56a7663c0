"""The compiled HEALPix ``cell`` quadrature against its numpy reference, pair by pair, and
the inside test that spares the cells a cap holds (issue 34 item 1).

The kernel transcribes :func:`eyeviz.core.responses_cells.integrate` (the same pieces,
crossings and rules; only the order of the sums differs), so the two agree to rounding:
1e-13 of a cell. :func:`cells_inside` must never call a cell inside that the reference
finds cut by the cap's edge.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from eyeviz.core import healpix
from eyeviz.core import responses_cells as rc
from eyeviz.core.geometry3d import EyePair3D
from eyeviz.core.responses import healpix_values

NSIDES = [1, 2, 3, 8, 18, 64, 180]


def _pairs(nside: int, seed: int):
    """Caps of random centre and radius (tiny to a hemisphere) and, per cap, the cells its
    edge may cross: those whose centre is within a cell's diameter of the edge, plus the
    cells holding the cap's centre and a pole."""
    rng = np.random.default_rng(seed)
    pix, tc, pc, b = [], [], [], []
    cell = math.sqrt(4 * math.pi / healpix.npix(nside))
    every = np.arange(healpix.npix(nside))
    if every.size > 60_000:  # a sample of the cells: enough near each edge, and fast
        every = np.sort(rng.choice(every, 60_000, replace=False))
    c = healpix.centers(nside, every)
    for k in range(6):
        w = rng.normal(size=3)
        if k == 0:
            w = np.array([1e-3, 2e-3, 1.0])  # near the north pole
        if k == 1:
            w = np.array([0.3, 0.4, -0.9])  # south, the polar cap
        w /= np.linalg.norm(w)
        rad = [1e-7 * cell, 0.3 * cell, 2.5 * cell, 0.4, math.pi / 2][k % 5] * (1 + rng.random())
        rad = min(rad, math.pi / 2)
        ang = np.arccos(np.clip(c @ w, -1, 1))
        near = every[np.abs(ang - rad) <= 1.5 * cell][:60]
        own = healpix.vec2pix_ring(nside, *w[:, None])
        sel = np.unique(np.concatenate([near, own, [0]]))
        pix.append(sel)
        tc.append(np.full(sel.size, math.acos(w[2])))
        pc.append(np.full(sel.size, math.atan2(w[1], w[0]) % (2 * math.pi)))
        b.append(np.full(sel.size, rad))
    return tuple(np.concatenate(v) for v in (pix, tc, pc, b))


@pytest.mark.parametrize("nside", NSIDES)
def test_kernel_equals_the_reference_pair_by_pair(nside):
    pix, tc, pc, b = _pairs(nside, 34 + nside)
    want = rc.integrate(nside, pix, tc, pc, b)
    got = rc.integrate_compiled(nside, pix, tc, pc, b)
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-13)
    assert ((want > 0) & (want < 1)).sum() >= 6  # cut cells are among them
    # the inside test: only cells the reference finds whole (to its tolerance)
    ins = rc.cells_inside(nside, pix, tc, pc, b)
    assert (want[ins] >= 1 - 1e-11).all()
    # and both paths of cell_fraction give the same shares
    np.testing.assert_allclose(
        rc.cell_fraction(nside, pix, tc, pc, b, jit=True),
        rc.cell_fraction(nside, pix, tc, pc, b, jit=False),
        rtol=0,
        atol=1e-13,
    )


def test_the_inside_test_spares_most_of_a_large_cap():
    """At nside 180 a ball of 4.6 degrees lights ~690 cells; all but its edge's are
    decided whole (exactly 1), and those sum with the cut cells to the cap's area."""
    pair = EyePair3D(40.0, 20.0, 180)
    x, y, z, g = (np.array([v]) for v in (0.0, 1500.0, 0.0, 120.0))
    (ptr, idx), _ = pair.lit_csr(x, y, z, g)
    vals = healpix_values(180, -40.0, (x, y, z, g), ptr, idx)
    whole = int((vals == 1.0).sum())
    assert whole >= 0.75 * idx.size
    b = math.asin(120.0 / math.hypot(40.0, 1500.0))
    cap = 4 * math.pi * math.sin(b / 2) ** 2
    assert abs(vals.sum() * 4 * math.pi / pair.npix - cap) <= 1e-12 * cap
