"""The `limit` estimator: quadrature against a brute-force posterior, contract, flags, cache."""

from __future__ import annotations

import math
import re

import numpy as np
import pytest

from eyeviz import dataset, estimators
from eyeviz.estimators.base import PAPER_DOMAIN, Domain, bitmaps_to_intervals
from eyeviz.estimators.limit import LimitEstimator, posterior_nodes, posterior_samples


def _wquantile(v, w, q):
    o = np.argsort(v)
    cw = np.cumsum(w[o])
    return v[o][np.searchsorted(cw, q * cw[-1])]


def _mc_posterior(domain: Domain, key, prior: str, box, n: int, seed: int):
    """Algorithm 1's prior sampled in a box of (r, phi, g), reweighted exactly.

    Restricting r to [r0, r1] keeps the conditional of the uniform r (multi: weight r);
    restricting g and phi to sub-ranges is corrected by the ratio of the allowed range to
    the prior's full range at that (r, g). Keeps the samples whose intervals are the key.
    """
    rng = np.random.default_rng(seed)
    eyes = domain.eyes
    s = math.sin(eyes.gamma / 2)
    psi = eyes.psi
    (r0, r1), (p0, p1), (g0, g1) = box
    r = rng.uniform(r0, r1, n)
    glo = np.maximum(r * s, g0)
    ghi = np.minimum(domain.g_max, g1)
    g = glo + (ghi - glo) * rng.random(n)
    a = np.arcsin(np.minimum(g / r, 1.0))
    flo = np.maximum(psi + a, p0)
    fhi = np.minimum(math.pi - psi - a, p1)
    phi = flo + (fhi - flo) * rng.random(n)
    w = (ghi - glo) / (domain.g_max - r * s) * (fhi - flo) / (math.pi - 2 * psi - 2 * a)
    if prior == "multi":
        w = w * r
    ok = (ghi > glo) & (fhi > flo) & (r * s <= domain.g_max)
    x, y = r * np.cos(phi), r * np.sin(phi)
    iv = eyes.intervals(x, y, g)
    ok &= np.all(np.stack(iv, 1) == np.asarray(key), axis=1)
    return r[ok], phi[ok], g[ok], w[ok]


@pytest.mark.parametrize(
    "feature, prior",
    [
        ((0.0, 1200.0, 150.0), "single"),
        ((700.0, 2400.0, 300.0), "single"),
        ((-900.0, 3200.0, 420.0), "multi"),
    ],  # fmt: skip
)
def test_matches_brute_force_posterior(feature, prior):
    eyes = PAPER_DOMAIN.eyes
    key = tuple(int(v) for v in eyes.intervals(*feature))
    est = LimitEstimator(PAPER_DOMAIN, prior)
    r_est, phi_est = est.predict_intervals(*key)
    assert not est.last_flagged
    r_f = math.hypot(feature[0], feature[1])
    phi_f = math.atan2(feature[1], feature[0])
    box = (
        (0.6 * r_f, 1.6 * r_f),
        (phi_f - 0.02, phi_f + 0.02),
        (0.4 * feature[2], 2.0 * feature[2]),
    )
    r, phi, g, w = _mc_posterior(PAPER_DOMAIN, key, prior, box, 4_000_000, seed=3)
    # the box holds the whole posterior: no sample lies on its edges in r or g
    assert r.size > 400
    assert r.min() > box[0][0] * 1.01 and r.max() < box[0][1] * 0.99
    assert phi.min() > box[1][0] + 1e-3 and phi.max() < box[1][1] - 1e-3
    assert g.min() > box[2][0] * 1.01 and g.max() < box[2][1] * 0.99
    # the key's prior mass: quadrature (u-grid cell (gamma/n)^2, (t-, t+) -> (phi_A, delta)
    # Jacobian 1/2) against the MC estimate (r1 - r0) * mean(weight * [key])
    n = 12
    mass = float(posterior_nodes([key], PAPER_DOMAIN, prior, n, 6).w.sum()) * eyes.gamma**2
    mass /= 2 * n * n
    mc = (box[0][1] - box[0][0]) * w.sum() / 4_000_000
    assert abs(mass / mc - 1) < 5 / math.sqrt(w.sum() ** 2 / (w * w).sum()) + 0.01, (mass, mc)
    wr, wp = w / r, w / phi
    for v, ww, est_v in ((r, wr, r_est), (phi, wp, phi_est)):
        n_eff = ww.sum() ** 2 / (ww * ww).sum()
        z = 4 * 0.5 / math.sqrt(n_eff)  # four standard errors of the median's rank
        lo, hi = _wquantile(v, ww, 0.5 - z), _wquantile(v, ww, 0.5 + z)
        slack = 0.004 * abs(est_v) if v is r else 1e-4  # integration precision (docstring)
        assert lo - slack <= est_v <= hi + slack, (v is r, lo, est_v, hi)


@pytest.mark.parametrize("design", [dict(m=1440), dict(h=80.0), dict(l=10.0)])
def test_contract_other_designs(design):
    dom = Domain(**design)
    est = estimators.load("limit", domain=dom, prior="single")
    assert "limit" in estimators.available()
    assert est.domain == dom and est.prior == "single" and est.n_weights == 0
    ds = dataset.generate(400, eyes=dom.eyes, seed=11)
    p = est.predict(ds.omega_a, ds.omega_b)
    assert p.r.shape == (400,) and p.phi.shape == (400,)
    assert p.valid.all() and p.in_domain.dtype == bool and p.in_domain.mean() > 0.95
    assert np.isfinite(p.r).all() and not est.last_flagged.any()
    ana = estimators.load("analytic", domain=dom).predict(ds.omega_a, ds.omega_b)
    err = lambda r: np.mean(np.abs(r - ds.r) / ds.r)  # noqa: E731
    assert err(p.r) < err(ana.r)  # the limit beats triangulation on any eyes
    one = est.predict(ds.omega_a[0], ds.omega_b[0])
    assert np.ndim(one.r) == 0 and one.r == p.r[0]
    with pytest.raises(ValueError, match="m/2"):
        est.predict(ds.omega_a[:, :10], ds.omega_b[:, :10])


def test_bad_prior_refused():
    with pytest.raises(ValueError, match="prior"):
        estimators.load("limit", prior="uniform")


def test_empty_posterior_is_triangulated_and_flagged():
    eyes = PAPER_DOMAIN.eyes
    # g = 5 at r = 3000: below r sin(gamma/2) = 13, the prior never draws it; lights one
    # ommatidium per eye (not visible by Def. 1)
    x, y, g = np.array([0.0, 0.0]), np.array([3000.0, 1500.0]), np.array([5.0, 150.0])
    LA, RA, LB, RB = eyes.intervals(x, y, g)
    est = LimitEstimator()
    p = est.predict_intervals(LA, RA, LB, RB)
    assert est.last_flagged.tolist() == [True, False] == p.flagged.tolist()
    # row-aligned through bitmaps too, with an invalid (empty) row in between
    w = PAPER_DOMAIN.width
    oa, ob = eyes.bitmaps(x, y, g)
    oa = np.vstack([oa[:1, :w], np.zeros((1, w), bool), oa[1:, :w]])
    ob = np.vstack([ob[:1, :w], np.zeros((1, w), bool), ob[1:, :w]])
    q = est.predict(oa, ob)
    assert q.flagged.tolist() == [True, False, False] and q.valid.tolist() == [True, False, True]
    assert est.predict(oa[0], ob[0]).flagged
    ana = estimators.load("analytic").predict_intervals(LA, RA, LB, RB)
    assert p.r[0] == ana.r[0] and p.phi[0] == ana.phi[0] and np.isfinite(p.r).all()
    s = posterior_samples((int(LA[0]), int(RA[0]), int(LB[0]), int(RB[0])))
    assert s["empty"] and s["x"].size == 0 and s["r"] == p.r[0]


def test_cache_and_determinism():
    ds = dataset.generate(300, seed=4)
    a = LimitEstimator(cache_size=50)
    p1 = a.predict(ds.omega_a, ds.omega_b)
    misses = a.misses
    assert 40 <= len(a._cache) <= 50 and misses > 250  # bounded: LRU down to 7/8
    b = LimitEstimator()
    p2 = b.predict(ds.omega_a, ds.omega_b)
    np.testing.assert_array_equal(p1.r, p2.r)
    np.testing.assert_array_equal(p1.phi, p2.phi)
    hits = b.hits
    p3 = b.predict(ds.omega_a, ds.omega_b)
    assert b.misses == misses and b.hits == hits + misses  # all from the cache
    np.testing.assert_array_equal(p3.r, p2.r)


def test_posterior_samples_for_the_app():
    eyes = PAPER_DOMAIN.eyes
    om_a, om_b = eyes.bitmaps(np.array([300.0]), np.array([2500.0]), np.array([200.0]))
    w = PAPER_DOMAIN.width
    s = posterior_samples((om_a[0, :w], om_b[0, :w]), PAPER_DOMAIN, "multi")
    assert not s["empty"] and abs(s["weight"].sum() - 1) < 1e-5
    assert s["x"].shape == s["y"].shape == s["g"].shape == s["weight"].shape
    r = np.hypot(s["x"], s["y"])
    assert r.min() < s["r"] < r.max() and s["g"].max() - s["g"].min() > 5  # over all g
    key = np.array([int(v) for v in eyes.intervals(300.0, 2500.0, 200.0)])
    iv = np.stack(eyes.intervals(s["x"], s["y"], s["g"]), 1)
    assert np.mean(np.all(iv == key, axis=1)) > 0.99  # the points are the key's polyhedron


def test_eyes_farther_apart_than_the_prior_range_warn_nothing():
    """h beyond r_min/r_max: rays that miss the r circles are handled, not NaN-warned."""
    import warnings

    dom = Domain(h=1e6, l=1.0, m=720)
    key = [int(v) for v in dom.eyes.intervals(0.0, 3000.0, 60.0)]
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        nd = posterior_nodes([key], dom)
        r = nd.r[0][nd.w[0] > 0]
    assert r.size and r.min() >= dom.r_min * (1 - 1e-6) and r.max() <= dom.r_max * (1 + 1e-6)


@pytest.mark.parametrize("phi_deg", [32.9, 180.0 - 32.9])
def test_nodes_of_a_key_at_the_bfvs_edge_stay_inside_the_bfv(phi_deg):
    """A feature 0.03 deg inside either edge of the BFV (r = 2000, g = 100): its key's
    tangent sectors reach past the edge, and every node with weight satisfies
    psi + asin(g/r) <= phi <= pi - psi - asin(g/r) (Prop. 4), up to float32 rounding;
    some lie on the edge, so the bound is what cuts them."""
    d = PAPER_DOMAIN
    psi = math.asin(d.l / d.h)
    t = math.radians(phi_deg)
    iv = d.eyes.intervals(np.array([2000 * math.cos(t)]), np.array([2000 * math.sin(t)]), [100.0])
    nd = posterior_nodes([[int(v[0]) for v in iv]], d)
    on = nd.w[0] > 0
    assert on.sum() > 20
    a = np.arcsin(np.minimum(nd.g[0][on] / nd.r[0][on], 1.0))
    phi = nd.phi[0][on]
    beyond = np.maximum(psi + a - phi, phi - (math.pi - psi - a))  # > 0: outside the BFV
    assert beyond.max() < 1e-5, beyond.max()
    assert beyond.max() > -1e-3, beyond.max()


def test_each_rows_answer_is_its_own_at_the_largest_m():
    """At m = 2^20 the packed key ((LA w + RA) w + LB) w + RB overflows int64: LA = 10 and
    LA = 138 (2^7 apart, times w^3 = 2^57) with the other three ends equal packed to the
    same code, so the second row got the first row's answer (and its flag) when both were
    in one batch (issue 25)."""
    import numpy as np

    from eyeviz import estimators
    from eyeviz.core.bounds import MAX_M
    from eyeviz.core.domain import Domain

    rows = [(10, 200, 30, 40), (138, 200, 30, 40)]
    alone = [
        estimators.load("limit", domain=Domain(m=MAX_M)).predict_intervals(
            *(np.array([v]) for v in k)
        )
        for k in rows
    ]
    both = estimators.load("limit", domain=Domain(m=MAX_M)).predict_intervals(
        *(np.array(c) for c in zip(*rows, strict=True))
    )
    for i in range(2):
        assert both.r[i] == alone[i].r[0] and both.phi[i] == alone[i].phi[0]
    assert both.r[0] != both.r[1]


def _argsort_median(v, w):
    """The weighted median as computed before issue 25 (argsort, two gathers)."""
    order = np.argsort(v, axis=1, kind="stable")
    vs = np.take_along_axis(v, order, 1).astype(np.float64)
    ws = np.take_along_axis(w, order, 1)
    cw = np.cumsum(ws, axis=1)
    mid = (cw - 0.5 * ws) / cw[:, -1:]
    i1 = np.clip((mid < 0.5).sum(axis=1), 1, v.shape[1] - 1)
    rows = np.arange(v.shape[0])
    m0, m1 = mid[rows, i1 - 1], mid[rows, i1]
    t = np.clip((0.5 - m0) / (m1 - m0), 0.0, 1.0)
    return vs[rows, i1 - 1] + t * (vs[rows, i1] - vs[rows, i1 - 1])


def test_sorted_code_median_equals_the_argsort_median():
    from eyeviz.estimators.limit import weighted_median

    ds = dataset.generate(400, seed=11)
    from eyeviz.estimators.base import bitmaps_to_intervals

    keys = np.unique(np.stack(bitmaps_to_intervals(ds.omega_a, ds.omega_b)[:4], 1), axis=0)
    nd = posterior_nodes(keys, PAPER_DOMAIN)
    live = nd.w.sum(axis=1) > 0
    for v in (nd.r[live], nd.phi[live], -nd.phi[live]):
        w = nd.w[live] / np.abs(v)
        np.testing.assert_allclose(weighted_median(v, w), _argsort_median(v, w), rtol=1e-6)


def test_answers_stay_within_the_stated_error_bound():
    """Against the fine quadrature (n = 48, K = 16) the default stays within the module
    docstring's bound: relative error of r at most 9e-3, phi within 1e-4 rad."""
    from eyeviz.estimators.base import bitmaps_to_intervals
    from eyeviz.estimators.limit import limit_estimates

    ds = dataset.generate(600, seed=5)
    keys = np.unique(np.stack(bitmaps_to_intervals(ds.omega_a, ds.omega_b)[:4], 1), axis=0)
    keys = keys[:150]
    r, p, e = limit_estimates(keys, PAPER_DOMAIN)
    ref_r, ref_p, ref_e = limit_estimates(keys, PAPER_DOMAIN, "single", 48, 16)
    assert not e.any() and not ref_e.any()
    assert np.abs(r / ref_r - 1).max() <= 9e-3
    assert np.abs(p - ref_p).max() <= 1e-4


def test_impossible_keys_skip_the_nodes(monkeypatch):
    """A key no ray of which is feasible (g = 5 at r = 3000) is empty from the rays alone,
    on the default and on the 4x grid: no quadrature nodes are computed for it (before,
    it paid the nodes of both grids: 13.5x a real key)."""
    from eyeviz.estimators import limit, limit_solve

    eyes = PAPER_DOMAIN.eyes
    key = np.stack(eyes.intervals(np.array([0.0]), np.array([3000.0]), np.array([5.0])), 1)
    calls = []
    real_nodes = limit_solve._nodes
    monkeypatch.setattr(
        limit_solve, "_nodes", lambda cu, *a: calls.append(len(cu)) or real_nodes(cu, *a)
    )
    r, p, e = limit.limit_estimates(key, PAPER_DOMAIN)
    assert e.all() and calls == []
    good = np.stack(eyes.intervals(np.array([0.0]), np.array([3000.0]), np.array([150.0])), 1)
    limit.limit_estimates(np.vstack([good, key]), PAPER_DOMAIN)
    assert calls == [1]  # the real key's nodes only


def test_cached_rows_are_answered_without_solving(monkeypatch):
    """A batch whose keys are all cached is one array lookup: nothing solved, same
    answers; the cache stays within its size."""
    from eyeviz.estimators import limit

    ds = dataset.generate(3000, seed=8)
    est = LimitEstimator(cache_size=1 << 12)
    p1 = est.predict(ds.omega_a, ds.omega_b)
    monkeypatch.setattr(limit, "limit_estimates", lambda *a, **k: pytest.fail("solved again"))
    p2 = est.predict(ds.omega_a, ds.omega_b)
    np.testing.assert_array_equal(p1.r, p2.r)
    np.testing.assert_array_equal(p1.flagged, p2.flagged)
    small = LimitEstimator(cache_size=64)
    monkeypatch.undo()
    small.predict(ds.omega_a, ds.omega_b)
    assert len(small._cache) <= 64


def test_cached_lookup_of_shuffled_rows_matches_each_row():
    """The cached path searches the rows' codes in sorted order and scatters the answers
    back: a shuffled, duplicated batch gets each row's own answer, and ``hits`` counts
    the distinct keys found."""
    ds = dataset.generate(2000, seed=12)
    est = LimitEstimator(cache_size=1 << 12)  # merged into the sorted arrays, none dropped
    p1 = est.predict(ds.omega_a, ds.omega_b)
    rng = np.random.default_rng(3)
    idx = rng.integers(0, 2000, 5000)
    hits = est.hits
    p2 = est.predict(ds.omega_a[idx], ds.omega_b[idx])
    np.testing.assert_array_equal(p2.r, p1.r[idx])
    np.testing.assert_array_equal(p2.phi, p1.phi[idx])
    np.testing.assert_array_equal(p2.flagged, p1.flagged[idx])
    LA, RA, LB, RB, ok = bitmaps_to_intervals(ds.omega_a[idx], ds.omega_b[idx])
    keys = np.stack([LA, RA, LB, RB], axis=1)[ok]
    assert est.hits - hits == len(np.unique(keys, axis=0))  # each distinct key, once


# keys of fresh paper-design rows (seed 31337) that no ray of the default 12 x 12 grid
# reaches (slivers); the 4x grid finds each of them
SLIVERS = [[63, 64, 63, 65], [63, 75, 63, 76], [64, 97, 66, 98], [157, 184, 161, 190],
           [222, 226, 227, 229]]  # fmt: skip


def test_slivers_are_found_and_impossible_keys_skip_the_4x_grid(monkeypatch):
    """A key empty on the default grid goes to the 4x grid only when a ray of the 2x
    grid reaches it: slivers keep their 4x-grid answer; an impossible key (g = 5 at
    r = 3000) never pays the 4x grid's rays (before: the 12 and 48 grids, 14x a real
    key batched; now the 12 and 24 grids)."""
    from eyeviz.estimators import limit

    keys = np.array(SLIVERS)
    r, p, e = limit.limit_estimates(keys, PAPER_DOMAIN)
    r48, p48, e48 = limit.limit_estimates(keys, PAPER_DOMAIN, "single", 48, 6)
    assert not e.any() and not e48.any()
    np.testing.assert_array_equal(r, r48)
    np.testing.assert_array_equal(p, p48)
    eyes = PAPER_DOMAIN.eyes
    imp = np.stack(eyes.intervals(np.array([0.0]), np.array([3000.0]), np.array([5.0])), 1)
    from eyeviz.estimators import limit_solve

    grids = []
    real_rays = limit_solve.rays
    monkeypatch.setattr(limit_solve, "rays", lambda kk, p: grids.append(p.n) or real_rays(kk, p))
    assert limit.limit_estimates(imp, PAPER_DOMAIN)[2].all()
    assert grids == [12, 24]


def test_hits_of_a_few_rows_against_a_large_cache():
    """A few rows against a cache of thousands count their distinct keys along their own
    sorted entries (no pass over the whole cache): the same count and answers as a
    fresh look-up."""
    ds = dataset.generate(3000, seed=21)
    est = LimitEstimator(cache_size=1 << 12)
    p1 = est.predict(ds.omega_a, ds.omega_b)
    cache = est._cache
    assert cache.codes.size > 4 * 8  # merged into the sorted arrays
    idx = np.array([5, 5, 17, 99, 5, 17])
    hits, misses = est.hits, est.misses
    p2 = est.predict(ds.omega_a[idx], ds.omega_b[idx])
    np.testing.assert_array_equal(p2.r, p1.r[idx])
    np.testing.assert_array_equal(p2.phi, p1.phi[idx])
    LA, RA, LB, RB, ok = bitmaps_to_intervals(ds.omega_a[idx], ds.omega_b[idx])
    keys = np.stack([LA, RA, LB, RB], axis=1)[ok]
    assert est.hits - hits == len(np.unique(keys, axis=0)) and est.misses == misses


def test_in_domain_of_extreme_integers_is_false():
    """The base validation issue 25 sped up compares interval ends, never subtracts them
    for a decision: runs of int64 extremes (whose differences wrap) are not in the
    domain (this row was once in it at m = 1440), and such rows are not valid."""
    from eyeviz.estimators.base import in_domain

    row = [8453531506701483716, -6970123064301365628, 6988049752160692281, -3371325149471528585]
    dom = Domain(m=1440, h=80.0)
    assert not in_domain(*row, dom)
    LA, RA, LB, RB = (np.array([v, 5]) for v in (*row[:2], row[2], row[3]))
    LA[1], RA[1], LB[1], RB[1] = 5, 9, 6, 10
    p = LimitEstimator(dom).predict_intervals(LA, RA, LB, RB)
    assert p.valid.tolist() == [False, True] and not p.in_domain[0]
    assert p.in_domain[1] == in_domain(5, 9, 6, 10, dom)


@pytest.mark.parametrize("cache_size", [64, 1 << 12])  # entries merged and dropped; kept
def test_one_row_calls_equal_the_batch(cache_size):
    """One row a call (its own short path) gives each row's batch answer and flag, and
    counts a miss per new key and a hit per known one, from the dict of recent keys and
    from the sorted arrays alike."""
    ds = dataset.generate(300, seed=9)
    LA, RA, LB, RB, ok = bitmaps_to_intervals(ds.omega_a, ds.omega_b)
    iv = np.stack([LA, RA, LB, RB], 1)[ok]
    imp = PAPER_DOMAIN.eyes.intervals(np.array([0.0]), np.array([3000.0]), np.array([5.0]))
    iv = np.vstack([iv, np.stack(imp, 1), iv[:40]])  # an impossible key; repeats
    batch = LimitEstimator().predict_intervals(*iv.T)
    est = LimitEstimator(cache_size=cache_size)
    for _ in range(2):
        got = [est.predict_intervals(*(np.array([v]) for v in k)) for k in iv]
        np.testing.assert_array_equal([g.r[0] for g in got], batch.r)
        np.testing.assert_array_equal([g.phi[0] for g in got], batch.phi)
        np.testing.assert_array_equal([g.flagged[0] for g in got], batch.flagged)
    assert batch.flagged.sum() == 1
    n_keys = len(np.unique(iv, axis=0))
    assert est.hits + est.misses == 2 * len(iv)
    if cache_size > 2 * n_keys:  # nothing dropped: each key solved once
        assert est.misses == n_keys


@pytest.mark.parametrize(
    ("kw", "want"),
    [
        ({"n": 0}, "n must be an integer >= 1 and <= 256, got 0"),  # was ZeroDivisionError
        ({"n": -3}, "n must be an integer >= 1"),  # was a numpy reduction error
        ({"n": 1.7}, "n must be an integer >= 1"),  # was truncated to 1
        ({"n": 10**6}, "n must be an integer >= 1 and <= 256, got 1000000"),  # 7 TiB
        ({"k": 0}, "k must be an integer >= 1 and <= 64, got 0"),
        ({"cache_size": -1}, "cache_size must be an integer >= 0, got -1"),  # KeyError at m=2^20
        ({"cache_size": "x"}, "cache_size must be an integer >= 0, got 'x'"),
    ],
)
def test_grid_and_cache_parameters_are_refused_in_one_line(kw, want):
    for m in (720, 1 << 20):
        with pytest.raises(ValueError, match="^" + re.escape(want)) as exc:
            estimators.load("limit", domain=Domain(m=m), **kw)
        assert "\n" not in str(exc.value)


def test_a_cache_of_no_keys_answers_as_the_default():
    cols = [np.array(v) for v in ([100, 5, 100], [104, 9, 104], [110, 12, 110], [114, 16, 114])]
    for m in (720, 1 << 20):
        want = LimitEstimator(Domain(m=m)).predict_intervals(*cols)
        got = LimitEstimator(Domain(m=m), cache_size=0).predict_intervals(*cols)
        np.testing.assert_array_equal(got.r, want.r)
        np.testing.assert_array_equal(got.flagged, want.flagged)
