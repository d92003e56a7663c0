"""eyeviz's own eyes as measured eyes (as_measured): facets, widths, lit sets by hand."""

from __future__ import annotations

import math

import numpy as np
import pytest

from eyeviz.core import healpix
from eyeviz.core.geometry import EyePair
from eyeviz.core.geometry3d import EyePair3D
from eyeviz.core.measured_from import as_measured, healpix_width
from eyeviz.measured import load_eyes, save_eyes


def _sees(p, a, acc, c, g) -> bool:
    """Distance from the ball centre to the closed cone {p + t u, angle(u, a) <= acc/2}
    <= g, written out independently of eyeviz.core.measured (margins keep off ties)."""
    v = np.asarray(c, float) - p
    r = float(np.linalg.norm(v))
    if r == 0:
        return True
    th = math.acos(max(-1.0, min(1.0, float(v @ a) / (r * float(np.linalg.norm(a))))))
    beyond = th - acc / 2
    d = 0.0 if beyond <= 0 else (r if beyond >= math.pi / 2 else r * math.sin(beyond))
    return d <= g


def test_healpix_facets_are_the_cells():
    cells = EyePair3D(40.0, 20.0, 4)
    m = as_measured(cells)
    assert m.facet_counts == (cells.npix, cells.npix)
    u = healpix.centers(4)
    u = u / np.linalg.norm(u, axis=1)[:, None]
    for e, cx in ((m.eye_a, -40.0), (m.eye_b, 40.0)):
        assert np.array_equal(e.axes, u)
        assert np.allclose(e.positions - [cx, 0, 0], 20.0 * u, rtol=0, atol=1e-12)
        assert np.all(e.acceptance == math.sqrt(4 * math.pi / cells.npix))
        assert np.all(e.focal_offset == 20.0)
    assert healpix_width(4) == pytest.approx(math.sqrt(math.pi / 3) / 4)
    # facet i's axis lies in RING pixel i
    assert np.array_equal(healpix.vec2pix_ring(4, u[:, 0], u[:, 1], u[:, 2]), np.arange(192))


def test_planar_ring():
    eyes = EyePair(40.0, 20.0, 8)
    m = as_measured(eyes)
    assert m.facet_counts == (8, 8)
    ax = m.eye_b.axes
    assert np.all(ax[:, 2] == 0) and np.all(m.eye_b.positions[:, 2] == 0)
    ang = np.arctan2(ax[:, 1], ax[:, 0]) % (2 * math.pi)
    assert np.allclose(ang, (np.arange(8) + 0.5) * math.pi / 4)
    assert np.all(m.eye_b.acceptance == eyes.gamma)


def test_nside2_lit_sets_by_hand():
    cells = EyePair3D(40.0, 20.0, 2)
    m = as_measured(cells)
    ca = np.array([-40.0, 0.0, 0.0])
    u = m.eye_a.unit_axes
    # 1. a small ball far along facet 21's axis: facet 21 alone, in both models
    c = ca + 1000 * u[21]
    assert m.lit(*c, 5.0)[0].tolist() == [21]
    assert cells.lit(*c, 5.0)[0].tolist() == [21]
    # 2. a small far ball on a vertex shared by four cells: the cells light all four,
    #    the inscribed discs none
    corner = healpix.boundaries(2, [21])[0][0]
    c = ca + 1000 * corner
    assert len(cells.lit(*c, 1.0)[0]) >= 3
    assert m.lit(*c, 1.0)[0].size == 0
    # 3. a ball just in front of facet 21's lens: its cone sees it, the cell too
    c = m.eye_a.positions[21] + 1.0 * u[21]
    assert 21 in m.lit(*c, 0.5)[0].tolist()
    # 4. the same lit sets as the written-out cone test for a spread of balls
    rng = np.random.default_rng(5)
    for _ in range(40):
        d = rng.normal(size=3)
        c = ca + rng.uniform(25, 300) * d / np.linalg.norm(d)
        g = rng.uniform(0.5, 30)
        got = m.lit(*c, g)[0].tolist()
        want = [
            i
            for i in range(m.eye_a.n)
            if _sees(m.eye_a.positions[i], m.eye_a.axes[i], m.eye_a.acceptance[i], c, g)
        ]
        assert got == want


def test_exports_round_trip(tmp_path):
    for model in (EyePair3D(40.0, 20.0, 2), EyePair(40.0, 20.0, 8)):
        m = as_measured(model)
        save_eyes(model, tmp_path / "x.eye")  # any eyeviz pair is accepted
        back = load_eyes(tmp_path / "x.eye")
        for e, f in ((m.eye_a, back.eye_a), (m.eye_b, back.eye_b)):
            assert e.positions.tobytes() == f.positions.tobytes()
            assert e.axes.tobytes() == f.axes.tobytes()
            assert e.acceptance.tobytes() == f.acceptance.tobytes()


def test_as_measured_passes_measured_and_refuses_others():
    m = as_measured(EyePair3D(40.0, 20.0, 2))
    assert as_measured(m) is m
    with pytest.raises(TypeError, match="eye pair"):
        as_measured("bee")
