"""The limit's fast path for new keys (issue 25) against the reference computation it
replaced, row by row; its weighted medians against :func:`limit.weighted_median`."""

from __future__ import annotations

import numpy as np
import pytest

from eyeviz import dataset
from eyeviz.core.bounds import MAX_M
from eyeviz.estimators import limit, limit_solve
from eyeviz.estimators.base import PAPER_DOMAIN, Domain, bitmaps_to_intervals

# float rounding: far inside the quadrature's stated bound (module docstring of
# eyeviz.estimators.limit: r within 9e-3 relative, phi within 1e-4 rad). Two nodes of
# equal float32 value that straddle the median can swap order after a one-ulp change,
# which moves the interpolated median by up to the gap to the next node (1.0e-4 relative
# for 1 key of these 1,604 on the paper's design): a few keys may exceed the tolerance,
# none the gap bound
R_TOL, PHI_TOL, FEW, GAP = 2e-5, 1e-5, 0.005, 1e-3


def _keys(dom: Domain, rows: int, seed: int) -> np.ndarray:
    """Distinct keys of Algorithm 1's rows, then random keys (mostly impossible) and
    keys at the ends of the half bitmap, one-ommatidium runs, LA = RA, LB = RB."""
    ds = dataset.generate(rows, eyes=dom.eyes, seed=seed)
    real = np.unique(np.stack(bitmaps_to_intervals(ds.omega_a, ds.omega_b)[:4], 1), axis=0)
    rng = np.random.default_rng(seed)
    w = dom.width
    lo = rng.integers(0, w, (rows // 2, 2))
    hi = np.minimum(lo + rng.integers(0, 8, lo.shape), w - 1)
    rand = np.stack([lo[:, 0], hi[:, 0], lo[:, 1], hi[:, 1]], 1)
    near = real[: rows // 4].copy()
    edges = np.concatenate(
        [
            np.column_stack([near[:, 0], near[:, 1], np.zeros(len(near), int), near[:, 3]]),
            np.column_stack([near[:, :3], np.full(len(near), w - 1)]),
            np.column_stack([near[:, :2], near[:, 3] - 1, near[:, 3]]),
            np.column_stack([near[:, 0], near[:, 0], near[:, 2:]]),
            np.column_stack([near[:, 0], near[:, 0] + 1, near[:, 2], near[:, 2]]),
            np.column_stack([np.zeros(len(near), int), near[:, 1:]]),
        ]
    )
    return np.concatenate([real, rand, np.clip(edges, 0, w - 1)])


@pytest.mark.parametrize(
    "design, prior, rows",
    [
        (dict(), "single", 1600),
        (dict(), "multi", 600),
        (dict(m=1440), "single", 600),
        (dict(h=2000.0), "multi", 600),  # eyes farther apart than r_min: no shortcuts
        (dict(m=8), "single", 300),
        (dict(m=MAX_M), "single", 200),  # keys beyond the int64 packing of the cache
    ],
)
def test_fast_path_equals_the_reference(design, prior, rows):
    """Thousands of keys (real, random, at the ends of the bitmap, single-ommatidium
    runs) over designs from m = 8 to m = 2^20: the same empty keys (flagged, answered by
    triangulation) and the same estimates up to float rounding."""
    dom = Domain(**design)
    keys = _keys(dom, rows, seed=7)
    r0, p0, e0 = limit._reference_estimates(keys, dom, prior)
    r1, p1, e1 = limit.limit_estimates(keys, dom, prior)
    np.testing.assert_array_equal(e1, e0)
    assert (~e0).sum() > rows // 10 and e0.sum() > 0  # both kinds present
    live = ~e0
    err_r = np.abs(r1[live] / r0[live] - 1)
    err_p = np.abs(p1[live] - p0[live])
    assert np.mean(err_r > R_TOL) <= FEW and err_r.max() <= GAP
    assert np.mean(err_p > PHI_TOL) <= FEW and err_p.max() <= 3 * PHI_TOL
    assert np.isnan(r1[e0]).all() and np.isnan(p1[e0]).all()


@pytest.mark.parametrize("design", [dict(), dict(m=1440, h=80.0), dict(m=MAX_M)])
def test_each_key_alone_equals_the_key_in_any_batch(design):
    """A key's answer is a function of that key alone: computed alone, in a batch and
    in a shuffled batch of other keys, bit for bit (the medians' integer width, dropped
    bits and blocks are each row's own)."""
    dom = Domain(**design)
    keys = _keys(dom, 300, seed=3)
    rng = np.random.default_rng(1)
    keys = keys[rng.permutation(len(keys))[:250]]
    batch = limit.limit_estimates(keys, dom)
    order = rng.permutation(len(keys))
    shuffled = limit.limit_estimates(keys[order], dom)
    for got, want in zip(shuffled, batch, strict=True):
        np.testing.assert_array_equal(got, want[order])
    for i in range(0, len(keys), 5):
        alone = limit.limit_estimates(keys[i : i + 1], dom)
        for got, want in zip(alone, batch, strict=True):
            np.testing.assert_array_equal(got[0], want[i])


def test_row_medians_equal_weighted_median():
    """Random rows with zero weights, ties, a lone weighted node, spans too wide for
    the 32-bit integer: the same medians as the public weighted_median (argsort-equal
    order; the CDF summed in another order: float rounding)."""
    rng = np.random.default_rng(5)
    N, P = 300, 864
    v = (1000 + 4000 * rng.random((N, P))).astype(np.float32)
    v[:40] = np.round(v[:40] / 50) * 50  # ties
    v[40:60] *= np.float32(1e12) ** rng.random((20, P)).astype(np.float32)  # wide: 64-bit
    v[60:80] *= (np.float32(1.5) ** (8 * rng.random((20, P)))).astype(np.float32)  # drops
    w = rng.random((N, P)).astype(np.float32)
    w[rng.random((N, P)) < 0.3] = 0
    w[80, :] = 0
    w[80, 17] = 1.0  # a lone weighted node
    got = limit_solve.row_medians(v, w)
    want = limit.weighted_median(v, w)
    exact = np.r_[0:40, 80:N]  # no dropped bits: the same order; weighted_median's
    # float32 CDF against a float64 one (with ties 50 apart, 1e-5 of the gap)
    np.testing.assert_allclose(got[exact], want[exact], rtol=1e-5)
    np.testing.assert_allclose(got, want, rtol=1e-4)  # <= 2^8 ulps of order error
    assert got[80] == v[80, 17]


def test_row_medians_ignore_values_outside_the_weighted_span():
    """Nodes of zero weight outside the weighted nodes' span (rays with no stretch sit
    at the eye) are clamped to its ends, which moves no median."""
    rng = np.random.default_rng(2)
    N, P = 50, 864
    v = (2000 + 100 * rng.random((N, P))).astype(np.float32)
    w = rng.random((N, P)).astype(np.float32)
    out = rng.random((N, P)) < 0.25
    w[out] = 0
    v[out] = np.where(rng.random(out.sum()) < 0.5, 40.0, 1e6).astype(np.float32)
    pos = w > 0
    span = (np.where(pos, v, np.inf).min(axis=1), np.where(pos, v, 0).max(axis=1))
    got = limit_solve.row_medians(v, w, span)
    np.testing.assert_allclose(got, limit.weighted_median(v, w), rtol=1e-6)
    np.testing.assert_array_equal(got, limit_solve.row_medians(v, w))


def test_paper_design_keys_drop_few_bits():
    """On the paper's design the 32-bit codes of r drop at most 3 bits and those of phi
    none (row_medians' docstring), on 20,000 fresh rows' keys."""
    ds = dataset.generate(20_000, seed=31337)
    keys = np.unique(np.stack(bitmaps_to_intervals(ds.omega_a, ds.omega_b)[:4], 1), axis=0)
    p = limit_solve.plan(PAPER_DOMAIN, 12, 6)
    cu, su, sd, cd, lo, hi, ok = limit_solve.rays(keys, p)
    live = ok.any(axis=1)
    args = (a[live] for a in (cu, su, sd, cd, lo, hi))
    vals, wts, span, empty = limit_solve._nodes(*args, p, "single")
    width = span[1].view(np.int32).astype(np.int64) - span[0].view(np.int32)
    bits = np.frexp(np.maximum(width, 0).astype(float))[1] - (31 - 10)
    n = live.sum()
    assert bits[:n].max() <= 3 and bits[n:].max() <= 0
    # every weighted node lies in its row's span
    pos = wts > 0
    assert (np.where(pos, vals, np.inf).min(axis=1) >= span[0]).all()
    assert (np.where(pos, vals, 0).max(axis=1) <= span[1]).all()


@pytest.mark.parametrize("phi_deg", [32.9, 33.2, 180.0 - 32.9, 180.0 - 33.2])
def test_keys_at_the_bfvs_edges_equal_the_reference(phi_deg):
    """Features just inside either edge of the BFV (Prop. 4; psi = 30 deg on the paper's
    design), where the BFV lines cut the rays: the fast path's constraints (in 1 / rho,
    from per-key sines) give the reference's answers."""
    t = np.radians(phi_deg)
    r = np.array([1200.0, 2000.0, 3500.0])
    g = np.array([60.0, 100.0, 200.0])
    keys = np.stack(PAPER_DOMAIN.eyes.intervals(r * np.cos(t), r * np.sin(t), g), 1)
    r0, p0, e0 = limit._reference_estimates(keys, PAPER_DOMAIN)
    r1, p1, e1 = limit.limit_estimates(keys, PAPER_DOMAIN)
    np.testing.assert_array_equal(e1, e0)
    assert not e0.all()
    np.testing.assert_allclose(r1[~e0], r0[~e0], rtol=R_TOL)
    np.testing.assert_allclose(p1[~e0], p0[~e0], atol=PHI_TOL)
