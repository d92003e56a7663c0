"""limit3d on hostile rows (issue 35, item 7): a key no ball of the domain can light (a
row lighting the whole eye took 33 s of draws and retries) gets no draws at all; it is
answered by analytic3d and flagged. The bound :func:`max_lit` holds for real balls."""

from __future__ import annotations

import numpy as np

from eyeviz.core.domain import Domain3D
from eyeviz.estimators import limit3d
from eyeviz.estimators.analytic3d import estimate


def test_max_lit_bounds_the_largest_balls_of_the_domain():
    d = Domain3D(nside=16)
    eyes = d.eyes
    rng = np.random.default_rng(7)
    n = 200
    r = np.full(n, d.r_min)  # the nearest and largest balls light the most
    az = rng.uniform(0.6, np.pi - 0.6, n)
    el = rng.uniform(-d.el_max, d.el_max, n)
    x, y, z = r * np.cos(el) * np.cos(az), r * np.cos(el) * np.sin(az), r * np.sin(el)
    (pa, _), (pb, _) = eyes.lit_csr(x, y, z, np.full(n, d.g_max))
    most = int(max(np.diff(pa).max(), np.diff(pb).max()))
    assert 0 < most <= limit3d.max_lit(d) < d.npix


def test_max_lit_bounds_a_ball_r_min_from_the_origin_on_the_eyes_side():
    # the bound's cap is that of a ball of g_max whose centre is r_min - h from an eye (r_min
    # from the origin, on the line of the eyes): a domain whose r_min is near h, where that
    # cap is wide (asin(50 / 60) = 56 degrees), and its nearest balls about that direction
    d = Domain3D(h=40.0, l=20.0, nside=16, r_min=100.0, r_max=200.0, g_max=50.0)
    a = np.linspace(-0.3, 0.3, 7)
    x, y, z = d.r_min * np.cos(a), d.r_min * np.sin(a), np.zeros(a.size)
    (_, _), (pb, _) = d.eyes.lit_csr(x, y, z, np.full(a.size, d.g_max))
    most = int(np.diff(pb).max())
    assert d.npix / 5 < most <= limit3d.max_lit(d) < d.npix


def test_a_whole_eye_key_gets_no_draws_and_is_flagged(monkeypatch):
    d = Domain3D(nside=8)
    est = limit3d.load(d, samples=16)
    seen: list[int] = []
    real = est._posterior

    def counting(la, lb):
        seen.extend(np.diff(la[0]).tolist())
        return real(la, lb)

    monkeypatch.setattr(est, "_posterior", counting)
    whole = (np.array([0, d.npix]), np.arange(d.npix))
    x, y, z, g = 0.0, 1500.0, 0.0, 50.0
    (pa, ia), (pb, ib) = d.eyes.lit_csr(np.array([x]), np.array([y]), np.array([z]), [g])
    lit_a = (np.array([0, d.npix, d.npix + pa[1]]), np.concatenate([whole[1], ia]))
    lit_b = (np.array([0, d.npix, d.npix + pb[1]]), np.concatenate([whole[1], ib]))
    p = est.predict(lit_a, lit_b)
    assert d.npix not in seen and seen == [int(pa[1])]  # only the real key was sampled
    assert p.flagged.tolist() == [True, False] and p.n_accepted[0] == 0
    fr, fa, fe, _ = estimate(d, (whole[0], whole[1]), (whole[0], whole[1]))
    assert np.array_equal(
        [p.r[0], p.azimuth[0], p.elevation[0]], [fr[0], fa[0], fe[0]], equal_nan=True
    )
