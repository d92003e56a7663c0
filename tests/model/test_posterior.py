"""The posterior over centres (issue 10 item 5): inside the key's polyhedron, normalised,
consistent with the limit's own quadrature, empty keys handled, cached per key."""

from __future__ import annotations

import math

import numpy as np
import pytest

from eyeviz.core.ambiguity import halfplanes
from eyeviz.core.domain import Domain
from eyeviz.estimators import analytic
from eyeviz.model import posterior as pm

PAPER = Domain()
CASES = [
    (PAPER, (300.0, 3000.0, 60.0)),
    (PAPER, (0.0, 1500.0, 150.0)),
    (PAPER, (-900.0, 3800.0, 400.0)),
    (Domain(80.0, 20.0, 720), (500.0, 2500.0, 100.0)),
    (Domain(40.0, 20.0, 1440), (-300.0, 2000.0, 40.0)),
]


def _wmedian(v, w):
    o = np.argsort(v)
    cw = np.cumsum(w[o])
    return float(np.interp(0.5 * cw[-1], cw - 0.5 * w[o], v[o]))


@pytest.mark.parametrize("domain, feature", CASES)
def test_points_lie_in_the_keys_polyhedron_and_weights_sum_to_one(domain, feature):
    pair = domain.eyes
    post = pm.posterior_of(pair, *feature, domain=domain)
    assert not post.empty and post.n > 50
    assert post.key == pm.key_of(pair, *feature)
    a, b, c, _ = halfplanes(pair, post.key)
    slack = post.x[:, None] * a[:, 0] + post.y[:, None] * a[:, 1] + post.g[:, None] * b - c
    scale = np.hypot(post.x, post.y)[:, None]
    assert (slack >= -1e-9 * scale).all()  # every (x, y, g) in the polyhedron
    # and they reproduce the key (the strict edges excepted)
    iv = np.stack(pair.intervals(post.x, post.y, post.g), 1)
    assert np.mean(np.all(iv == post.key, axis=1)) > 0.98
    assert abs(post.weight.sum() - 1) < 1e-12 and (post.weight > 0).all()
    assert post.density.max() == 1.0 and (post.density > 0).all()
    assert (post.g >= np.hypot(post.x, post.y) * math.sin(pair.gamma / 2) - 1e-9).all()
    assert (post.g <= domain.g_max + 1e-9).all()
    r = np.hypot(post.x, post.y)
    assert (r >= domain.r_min - 1e-6).all() and (r <= domain.r_max + 1e-6).all()
    # the cells hold their centres
    assert np.allclose(post.cells.mean(axis=1), np.column_stack([post.x, post.y]), rtol=1e-3)


@pytest.mark.parametrize("domain, feature", CASES)
def test_density_agrees_with_the_limits_own_quadrature(domain, feature):
    """Two independent integrations of the same posterior: the grid's 1/r-weighted median of
    r (Eq. 34's optimum) is the limit estimator's, within the grid's resolution."""
    post = pm.posterior_of(domain.eyes, *feature, domain=domain)
    r = np.hypot(post.x, post.y)
    med = _wmedian(r, post.weight / r)
    cell = (r.max() - r.min()) / (pm.N_R - 2)
    assert abs(med - post.r_hat) < max(cell, 2e-3 * post.r_hat), (med, post.r_hat, cell)
    phi = np.arctan2(post.y, post.x)
    assert abs(_wmedian(phi, post.weight / phi) - post.phi_hat) < 2e-3


def test_multi_pass_moves_the_mass_outwards():
    one = pm.posterior_of(PAPER.eyes, 300.0, 3000.0, 60.0)
    multi = pm.posterior_of(PAPER.eyes, 300.0, 3000.0, 60.0, prior="multi")
    r1, rm = np.hypot(one.x, one.y), np.hypot(multi.x, multi.y)
    assert (rm * multi.weight).sum() > (r1 * one.weight).sum()
    assert multi.r_hat > one.r_hat


def test_empty_key_is_handled():
    pair = PAPER.eyes
    post = pm.posterior_of(pair, 0.0, 3000.0, 5.0)  # g < r sin(gamma/2): the prior never
    assert post.empty and post.n == 0 and post.weight.size == 0 and post.cells.shape[0] == 0
    k = np.array(post.key)[:, None]
    r, phi = analytic.estimate(*k, PAPER)
    assert post.r_hat == pytest.approx(float(r[0])) and post.phi_hat == pytest.approx(float(phi[0]))
    # beyond r_max the same bitmaps also come from centres the prior draws: only those
    far = pm.posterior_of(pair, 0.0, 9000.0, 100.0)
    assert not far.empty and np.hypot(far.x, far.y).max() <= PAPER.r_max + 1e-6


def test_cached_per_key_and_design():
    pair = PAPER.eyes
    a = pm.posterior_of(pair, 300.0, 3000.0, 60.0)
    assert pm.posterior_of(pair, 300.0 + 1e-6, 3000.0, 60.0) is a  # same bitmaps
    b = pm.posterior_of(Domain(80.0, 20.0, 720).eyes, 300.0, 3000.0, 60.0)
    assert b is not a and b.domain.h == 80.0
    with pytest.raises(ValueError, match="design"):
        pm.posterior_of(pair, 300.0, 3000.0, 60.0, domain=Domain(80.0))


def test_a_key_outside_the_half_bitmaps_is_refused():
    with pytest.raises(ValueError, match="half bitmaps"):
        pm.posterior_for_key((10, 9, 20, 21), PAPER)
    with pytest.raises(ValueError, match="half bitmaps"):
        pm.posterior_for_key((350, 365, 352, 366), PAPER)


def test_r_interval_and_readout():
    pair = PAPER.eyes
    post = pm.posterior_of(pair, 1700.0, 2200.0, 120.0)
    lo, hi = post.r_interval(0.9)
    r = np.hypot(post.x, post.y)
    inside = post.weight[(r >= lo) & (r <= hi)].sum()
    assert 0.85 < inside < 0.95 and lo < post.r_hat < hi
    # over every g: far wider than the feature's own-g region (r in [2674, 2894])
    assert hi - lo > 1000
    text = pm.readout(pair, 1700.0, 2200.0, 120.0)
    assert text.startswith(f"90 % in r ∈ [{lo:.0f}, {hi:.0f}]") and f"r {post.r_hat:.0f}" in text
    assert pm.readout(pair, 0.0, 3000.0, 5.0).startswith("none: the prior never")
    assert all(math.isnan(v) for v in pm.posterior_of(pair, 0.0, 3000.0, 5.0).r_interval())


@pytest.mark.parametrize("domain, feature", CASES)
def test_a_regular_key_gets_the_grid_filled_tightly_inside_the_bfv(domain, feature):
    """Not the sliver fallback (nodes as points, density 1): cells with area, a density
    that varies, at least 40 % of the grid's cells holding mass (the grid spans the
    nodes' r and phi with one cell of margin), and the mean g of each cell in the BFV."""
    pair = domain.eyes
    post = pm.posterior_of(pair, *feature, domain=domain)
    c = post.cells
    d1, d2 = c[:, 2] - c[:, 0], c[:, 3] - c[:, 1]
    area = 0.5 * np.abs(d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0])
    assert (area > 0).all() and post.density.min() < 0.5
    assert post.n >= 0.4 * pm.N_R * pm.N_PHI
    assert pair.in_bfv(post.x, post.y, post.g).all()


@pytest.mark.parametrize("domain, feature", CASES)
def test_the_grid_covers_every_node_of_the_limits_quadrature(domain, feature):
    """The cells span the r and phi of every posterior node with weight (the grid's edges
    lie one cell outside the nodes' extremes)."""
    from eyeviz.estimators.limit import posterior_nodes

    post = pm.posterior_of(domain.eyes, *feature, domain=domain)
    nd = posterior_nodes([post.key], domain, "single")
    keep = nd.w[0] > 0
    rn, pn = nd.r[0][keep], nd.phi[0][keep]
    rc = np.hypot(post.cells[..., 0], post.cells[..., 1])
    pc = np.arctan2(post.cells[..., 1], post.cells[..., 0])
    assert rc.min() < rn.min() and rc.max() > rn.max()
    assert pc.min() < pn.min() and pc.max() > pn.max()


def _density_by_brute_force(domain: Domain, key, x: float, y: float, n: int = 40_000):
    """The module docstring's density at one centre, integrated over g by the midpoint
    rule on a fine grid of (0, g_max], the allowed g found by asking the eyes for each g's
    key (not the half-planes) and checking the prior's support directly."""
    pair = domain.eyes
    s = math.sin(pair.gamma / 2)
    psi = math.asin(domain.l / domain.h)
    r, phi = math.hypot(x, y), math.atan2(y, x)
    dg = domain.g_max / n
    g = dg * (np.arange(n) + 0.5)
    iv = pair.intervals(np.full(n, x), np.full(n, y), g)
    a = np.arcsin(np.minimum(g / r, 1.0))
    ok = np.all([iv[i] == key[i] for i in range(4)], axis=0)
    ok &= (g >= r * s) & (psi + a <= phi) & (phi <= math.pi - psi - a)
    ok &= domain.r_min <= r <= domain.r_max
    width = math.pi - 2 * psi - 2 * a[ok]
    return float(np.sum(1.0 / (r * (domain.g_max - r * s) * width)) * dg), int(ok.sum())


@pytest.mark.parametrize("phi_deg", [33.3, 32.9])
def test_the_density_at_a_centre_is_the_prior_integrated_over_the_keys_g(phi_deg):
    """The density's shape (the 1/width factor of Eq. 15) and the BFV's bound on g, against
    a brute-force integral: at 32.9 deg, 0.03 deg inside the BFV's edge for g = 100, the
    bound g <= r sin(phi - psi) cuts the g the key allows at these centres."""
    pair = PAPER.eyes
    X, Y = 2000.0 * math.cos(math.radians(phi_deg)), 2000.0 * math.sin(math.radians(phi_deg))
    key = pm.key_of(pair, X, Y, 100.0)
    xs, ys = np.array([X, X - 5.0, X + 5.0]), np.array([Y, Y - 5.0, Y + 5.0])
    dens, _ = pm._density(PAPER, key, "single", xs, ys)
    seen = 0
    for x, y, d in zip(xs, ys, dens, strict=True):
        want, hits = _density_by_brute_force(PAPER, key, float(x), float(y))
        seen += hits > 100
        assert d == pytest.approx(want, rel=0.01, abs=1e-3 * float(dens.max())), (x, y)
    assert seen >= 2  # most centres have mass: the comparison is not of zeros
