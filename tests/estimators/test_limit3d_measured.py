"""The information limit for a measured eye pair (limit3d's measured proposal) against
brute-force rejection sampling from the prior on a small eye with per-facet acceptance."""

from __future__ import annotations

import collections

import numpy as np
import pytest

from eyeviz.core.domain import Domain3D
from eyeviz.core.measured import MeasuredEye, MeasuredEyePair
from eyeviz.dataset.algorithm1_3d import generate3d
from eyeviz.estimators import registry
from eyeviz.estimators.analytic3d import estimate
from eyeviz.estimators.base import take_rows
from eyeviz.estimators.limit3d import Limit3DEstimator, posterior_samples3d, prior_density
from eyeviz.estimators.limit3d_proposal import _key_hash
from eyeviz.estimators.weighted import weighted_median


def small_pair(n_dirs: int = 90, seed: int = 0) -> MeasuredEyePair:
    """40 facets per eye: lenses on spheres of radius 0.5 about (-/+2, 0, 0) looking
    outwards (the front of a Fibonacci sphere), acceptance angles 0.3-0.5 rad per facet."""
    rng = np.random.default_rng(seed)
    k = np.arange(n_dirs) + 0.5
    z = 1 - 2 * k / n_dirs
    phi = np.pi * (1 + 5**0.5) * k
    d = np.stack([np.sqrt(1 - z * z) * np.cos(phi), np.sqrt(1 - z * z) * np.sin(phi), z], 1)
    d = d[d[:, 1] > 0.1]
    eyes = [
        MeasuredEye(np.array([sx, 0.0, 0.0]) + 0.5 * d, d, rng.uniform(0.3, 0.5, len(d)), name=nm)
        for sx, nm in ((-2.0, "A"), (2.0, "B"))
    ]
    return MeasuredEyePair(eyes[0], eyes[1], name="small")


#: the small pair's domain in the tests, and one farther off, where the provable box's
#: bound on the lens offsets holds (limit3d_measured: every ball 10 or more from the
#: origin, 8 or more from an eye of radius 0.5)
NEAR = {"r_min": 4.0, "r_max": 12.0, "g_max": 1.5, "el_max": 0.6}
FAR = {"r_min": 10.0, "r_max": 30.0, "g_max": 2.0, "el_max": 0.6}


def _commonest_keys(n_draws: int, n_keys: int, seed: int, ranges: dict = NEAR, pair=None):
    """The ``n_keys`` keys drawn most often among ``n_draws`` prior draws of the small
    pair (or ``pair``): each group of rows sharing a key is a sample of that key's exact
    posterior (rejection sampling)."""
    dom = Domain3D.for_eyes(small_pair() if pair is None else pair, **ranges)
    ds = generate3d(n_draws, dom, seed=seed)
    groups = collections.defaultdict(list)
    for i in range(len(ds)):
        a, b = ds.lit(i)
        groups[(a.tobytes(), b.tobytes())].append(i)
    top = sorted(groups.values(), key=len, reverse=True)[:n_keys]
    rows = np.array([g[0] for g in top])
    lit = (take_rows(ds.indptr_a, ds.indices_a, rows), take_rows(ds.indptr_b, ds.indices_b, rows))
    return dom, ds, [np.array(g) for g in top], lit


@pytest.fixture(scope="module")
def small():
    """The six commonest keys of 12,000 prior draws of the small pair."""
    return _commonest_keys(12_000, 6, seed=3)


def test_the_small_pair_has_per_facet_acceptance(small):
    dom = small[0]
    acc = dom.eyes.eye_a.acceptance
    assert dom.facet_counts == (40, 40) and np.unique(acc).size == 40


@pytest.fixture(scope="module")
def far():
    """The 30 commonest keys of 20,000 prior draws of the small pair in ``FAR``."""
    return _commonest_keys(20_000, 30, seed=3, ranges=FAR)


def test_matches_rejection_sampling_on_a_small_measured_eye(small):
    _agrees_with_rejection(small)


def test_matches_rejection_sampling_with_the_defensive_box(far):
    """The same where the provable box holds: a share of every batch drawn from it, every
    weight over the two boxes' mixture density (unbiased with no assumption that the
    bisection's box covers the posterior)."""
    dom, _, _, lit = far
    est = Limit3DEstimator(dom, samples=1024)
    prop = est._proposal
    st = prop.setup(*lit, _key_hash(*lit) ^ np.uint64(est.seed), 1.0)
    assert st["proven"].all() and (st["n_def"] > 0).all()
    # the 8 commonest keys; their posteriors are narrow in r, and the default accuracy
    # stops at a few draws. (On these keys main's proposal and this one agree with brute
    # force alike: over all 30, rms z 1.58 before, 1.72 with the defensive box.)
    rows = np.arange(8)
    sub = (take_rows(*lit[0], rows), take_rows(*lit[1], rows))
    _agrees_with_rejection((dom, far[1], far[2][:8], sub), accuracy=0.002)


def _agrees_with_rejection(small, **kw) -> None:
    dom, ds, groups, lit = small
    p = Limit3DEstimator(dom, samples=1024, **kw).predict(*lit)
    assert not p.flagged.any() and (p.n_accepted >= 20).all()
    z = []
    for j, g in enumerate(groups):
        r = ds.r[g]
        want = weighted_median(r[None], 1.0 / r[None])[0]  # MAPE-optimal, as the limit's
        se = np.hypot(1.2533 * r.std() / np.sqrt(g.size), p.mc_error[j] * p.r[j])
        z.append((p.r[j] - want) / se)
        el = ds.elevation[g]
        assert abs(p.elevation[j] - np.median(el)) < 4 * 1.2533 * el.std() / np.sqrt(g.size) + 0.02
    z = np.array(z)
    assert np.all(np.abs(z) < 4.0), z
    assert abs(z.mean()) < 1.5, z  # no bias shared by the keys (the mean of 6 has sd 0.41)


def test_posterior_samples_reproduce_the_key(small):
    dom, ds, groups, _ = small
    a, b = ds.lit(int(groups[0][0]))
    s = posterior_samples3d(Limit3DEstimator(dom, samples=256), a, b)
    assert s["x"].size > 0 and np.isclose(s["weight"].sum(), 1.0)
    for k in range(min(5, s["x"].size)):
        la, lb = dom.eyes.lit(s["x"][k], s["y"][k], s["z"][k], s["g"][k])
        assert np.array_equal(la, a) and np.array_equal(lb, b)
    o = np.asarray(dom.origin)
    r = np.linalg.norm(np.c_[s["x"], s["y"], s["z"]] - o, axis=1)
    assert np.allclose(r, s["r"])  # r about the domain's origin, as the data set's


def test_an_empty_posterior_is_flagged_and_answered_by_triangulation(small):
    """A key no ball makes (eye A's two outermost facets on opposite sides): no draw is
    accepted; the row is flagged and gets the triangulation's answer."""
    dom = small[0]
    ax = dom.eyes.eye_a.unit_axes
    i, j = int(np.argmin(ax[:, 0])), int(np.argmax(ax[:, 0]))
    la = (np.array([0, 2]), np.sort(np.array([i, j])))
    lb = (np.array([0, 2]), np.array([0, 1]))
    p = Limit3DEstimator(dom, samples=64).predict(la, lb)
    assert p.flagged[0] and p.n_accepted[0] == 0 and np.isnan(p.mc_error[0])
    r, az, el, _ = estimate(dom, la, lb)
    assert (p.r[0], p.azimuth[0], p.elevation[0]) == (r[0], az[0], el[0])


def test_the_measured_prior_has_no_cones():
    dom = Domain3D.for_eyes(small_pair(), r_min=4.0, r_max=12.0, g_max=1.5, el_max=0.6)
    r, g = np.full(3, 6.0), np.full(3, 1.2)
    el, az = np.array([0.1, 0.1, 0.7]), np.array([0.01, 1.5, 1.5])  # near the baseline
    p = prior_density(dom, "single", r, g, el, az)
    assert p[0] > 0 and p[0] == p[1] and p[2] == 0  # uniform in azimuth; el beyond el_max


def test_the_registry_loads_limit3d_for_measured_eyes(small):
    assert "limit3d" in registry.available_for("measured")
    est = registry.load("limit3d", domain=small[0])
    assert isinstance(est, Limit3DEstimator) and est.domain.kind == "measured"


def _box_coords(prop, st, c: np.ndarray) -> np.ndarray:
    """The measured proposal's box coordinates (N, G, 3) = (delta_1, delta_2, beta) of
    ball centres c (N, G, 3): A's direction in gnomonic coordinates about the key's
    reference, and the angle at o_B between the baseline and the ball
    (:meth:`MeasuredProposal._bcentres` inverted)."""
    v = c - prop.fa.centre
    v = v / np.linalg.norm(v, axis=2, keepdims=True)
    cu = np.einsum("ngj,nj->ng", v, st["u0"])
    d1 = np.einsum("ngj,nj->ng", v, st["e1"]) / cu
    d2 = np.einsum("ngj,nj->ng", v, st["e2"]) / cu
    w = c - prop.fb.centre
    cb = (w @ -prop.bhat) / np.linalg.norm(w, axis=2)
    return np.stack([d1, d2, np.arccos(np.clip(cb, -1.0, 1.0))], axis=-1)


def _outside_box(small, monkeypatch, **shrink) -> int:
    """How many of the brute-force posterior samples of the small pair's keys (rejection
    sampling from the prior) lie outside the measured proposal's box of their key: the
    box must hold the whole support of the posterior."""
    from eyeviz.estimators import limit3d_measured as lm

    for name, value in shrink.items():
        monkeypatch.setattr(lm, name, value)
    dom, ds, groups, lit = small
    est = Limit3DEstimator(dom, samples=1024)
    prop = est._proposal
    keys = _key_hash(*lit) ^ np.uint64(est.seed)
    st = prop.setup(*lit, keys, 1.0)
    # the coordinates are the proposal's: its own draws' centres map back to them
    rng = np.random.default_rng(0)
    x0 = st["box_lo"][:, None] + (st["box_hi"] - st["box_lo"])[:, None] * rng.random(
        (len(groups), 50, 3)
    )
    c0, rho, _ = prop._bcentres(st, x0[..., :2], x0[..., 2])
    ok = np.isfinite(rho)
    assert ok.sum() > 100
    assert np.allclose(_box_coords(prop, st, c0)[ok], x0[ok], rtol=0, atol=1e-9)
    out = 0
    o = np.asarray(dom.origin, float)
    for j, g in enumerate(groups):
        r, az, el = ds.r[g], ds.azimuth[g], ds.elevation[g]
        c = o + r[:, None] * np.stack(
            [np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)], axis=1
        )
        x = _box_coords(prop, {k: st[k][j : j + 1] for k in ("u0", "e1", "e2")}, c[None])[0]
        inside = (x >= st["box_lo"][j]) & (x <= st["box_hi"][j])
        out += int((~inside.all(axis=1)).sum())
    return out


def test_the_measured_proposal_box_holds_every_brute_force_posterior_sample(small, monkeypatch):
    """Coverage of the posterior's support (issue 33): every rejection sample of each key
    lies in the proposal's box (a draw outside the box is never proposed: a box missing
    part of the support biases the limit, which the medians' comparison may not see).
    The check can fail: the bisection's box unwidened (WIDEN 1) with a pilot of 128 draws
    misses 4 of the 568 samples, widened 2x without the pilot 10."""
    assert _outside_box(small, monkeypatch) == 0
    assert _outside_box(small, monkeypatch, WIDEN=1.0, PILOT=128) > 0
    assert _outside_box(small, monkeypatch, PILOT_ROUNDS=0) > 0


@pytest.mark.slow
def test_the_measured_proposal_box_holds_the_posterior_of_300_keys(monkeypatch):
    """The same coverage over the 300 commonest keys of a million prior draws (565,135
    posterior samples). With the pilot's 128 draws of before, the box missed 537 of them
    in 8 keys (up to 9 % of a key's posterior: the limit was biased there); 1,024 draws
    still missed 69 in one key."""
    many = _commonest_keys(1_000_000, 300, seed=11)
    assert sum(len(g) for g in many[2]) > 500_000
    assert _outside_box(many, monkeypatch) == 0
    assert _outside_box(many, monkeypatch, PILOT=128) > 0


@pytest.mark.slow
def test_the_provable_box_holds_the_posterior_of_300_keys():
    """The provable box over the 300 commonest keys of 300,000 prior draws in the far
    domain: every posterior sample inside, on every key."""
    dom, ds, groups, lit = _commonest_keys(300_000, 300, seed=11, ranges=FAR)
    out, n, proven = _outside_provable(dom, ds, groups, lit)
    assert proven == 300 and n > 50_000
    assert out == 0


def _ball_centres(dom, ds, rows) -> np.ndarray:
    """The centres (M, 3) of data set rows: the balls that made their keys."""
    o = np.asarray(dom.origin, float)
    r, az, el = ds.r[rows], ds.azimuth[rows], ds.elevation[rows]
    return o + r[:, None] * np.stack(
        [np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)], axis=1
    )


def _outside_provable(dom, ds, groups, lit, chunk: int = 8) -> tuple[int, int, int]:
    """(posterior samples outside their key's provable box, samples of keys where it
    holds, keys where it holds): each group of rows of ``ds`` shares one key of ``lit``."""
    prop = Limit3DEstimator(dom, samples=256)._proposal
    out = n = proven = 0
    for s0 in range(0, len(groups), chunk):
        rows = np.arange(s0, min(s0 + chunk, len(groups)))
        la, lb = take_rows(*lit[0], rows), take_rows(*lit[1], rows)
        st = prop.setup(la, lb, _key_hash(la, lb), 1.0)
        lo, hi, ok = prop.provable_box(st)
        for j, i in enumerate(rows):
            if not ok[j]:
                continue
            c = _ball_centres(dom, ds, groups[i])
            x = _box_coords(prop, {k: st[k][j : j + 1] for k in ("u0", "e1", "e2")}, c[None])[0]
            out += int((~((x >= lo[j]) & (x <= hi[j])).all(axis=1)).sum())
            n += len(groups[i])
            proven += 1
    return out, n, proven


def _shrunk_bound(monkeypatch) -> None:
    """The lit facets' bound S a third of itself: no longer a bound."""
    from eyeviz.estimators import limit3d_provable as lp

    real = lp._lens_tolerances

    def third(g_max, d_min, e):
        t, s, ok = real(g_max, d_min, e)
        return t, s / 3, ok

    monkeypatch.setattr(lp, "_lens_tolerances", third)


def test_the_provable_box_holds_every_brute_force_posterior_sample(far, monkeypatch):
    """Issue 33: the box from the acceptance cones (MeasuredProposal.provable_box, proved
    in limit3d_provable's docstring) holds every rejection sample of each key's posterior
    (4,600 samples of 30 keys), and the bound holds on every key of the far domain. It
    can fail: with the lit facets' bound S a third of itself, samples fall outside."""
    dom, ds, groups, lit = far
    out, n, proven = _outside_provable(dom, ds, groups, lit)
    assert proven == len(groups) and n > 4000
    assert out == 0
    _shrunk_bound(monkeypatch)
    assert _outside_provable(dom, ds, groups, lit)[0] > 0


def test_the_provable_box_holds_the_balls_of_honeybee_keys(monkeypatch):
    """On the honeybee (AM_60185), 160 fresh rows: the ball that made each key lies in its
    key's provable box (a posterior sample of that key), on every key where the bound
    holds, and it holds on most keys."""
    from eyeviz.files.eye_io import load_eyes, shipped_eye

    dom = Domain3D.for_eyes(load_eyes(shipped_eye("AM_60185-real.eye")))
    ds = generate3d(160, dom, seed=20261205)
    rows = np.arange(len(ds))
    lit = (take_rows(ds.indptr_a, ds.indices_a, rows), take_rows(ds.indptr_b, ds.indices_b, rows))
    groups = [np.array([i]) for i in rows]
    out, n, proven = _outside_provable(dom, ds, groups, lit)
    assert proven >= 0.9 * len(rows)
    assert out == 0


def test_the_measured_retries_keep_the_stage_that_finds_keys(small):
    """A key with nothing accepted is retried once, 24 batches in a window 2.5 times
    wider, with stream 2 as in limit3d.RETRY's second stage; other proposals keep RETRY's
    three stages, streams 1-3."""
    from eyeviz.estimators import limit3d

    est = Limit3DEstimator(small[0], samples=64)
    assert limit3d._retries(est._proposal) == ((2, 2.5, 24),)
    assert limit3d._retries(object()) == tuple(
        (i, w, r) for i, (w, r) in enumerate(limit3d.RETRY, start=1)
    )


@pytest.mark.parametrize("jit", ["1", "0"])
def test_sized_top_ups_give_the_answers_of_four_batches_at_a_time(far, monkeypatch, jit):
    """limit3d's top-ups drawing each key the batches its error predicts (the measured
    proposal's ``sample_counts``, keys grouped by their streams) give every key the same
    draws, so the same answers bit for bit, as ``_TOPUP`` batches at a time for every key;
    with fewer draws in all."""
    from eyeviz.estimators import limit3d_measured as lm

    monkeypatch.setenv("EYEVIZ_JIT", jit)
    dom, _, _, lit = far
    drawn = {True: 0, False: 0}
    sample = lm.MeasuredProposal._sampled

    def counting(self, st, keys, streams, nst, rows):
        out = sample(self, st, keys, streams, nst, rows)
        live = np.ones(keys.size, bool) if rows is None else rows
        drawn[bool(lm.MeasuredProposal.batch_counts)] += int(nst[live].sum()) * self.samples
        return out

    monkeypatch.setattr(lm.MeasuredProposal, "_sampled", counting)
    got = {}
    for sized in (True, False):
        monkeypatch.setattr(lm.MeasuredProposal, "batch_counts", sized)
        p = Limit3DEstimator(dom, samples=256, accuracy=0.01).predict(*lit)
        got[sized] = p
    a, b = got[True], got[False]
    assert 1 <= b.mc_capped.sum() <= 25 and (b.n_accepted > 0).all()
    for k in ("r", "azimuth", "elevation", "n_accepted", "flagged", "mc_capped"):
        assert np.array_equal(getattr(a, k), getattr(b, k)), k
    assert np.allclose(a.mc_error, b.mc_error, rtol=1e-12, equal_nan=True)
    assert drawn[True] < drawn[False]


def test_the_retries_stop_drawing_a_key_once_it_has_its_draws(small, monkeypatch):
    """limit3d._draw with reps > 1 (the retries, which keep each key's first ``samples``
    accepted draws in draw order) gives a key no more groups of batches once it has
    ``samples`` accepted draws: those first draws are the ones all the batches give, bit
    for bit, and some keys stop early while others go on (groups of 2 batches here)."""
    from eyeviz.estimators import limit3d

    monkeypatch.setattr(limit3d, "_GROUP", 2)
    dom, _, _, lit = small
    m = 32
    est = Limit3DEstimator(dom, samples=m)
    keys = _key_hash(*lit) ^ np.uint64(est.seed)
    got = est._draw(*lit, keys, 2.5, 2, reps=24)
    prop = est._proposal
    st = prop.setup(*lit, keys, 2.5)
    full = limit3d._compact(prop.sample(st, keys, [2 + 8 * rep for rep in range(24)]))
    got = limit3d._compact(got)  # the groups' accepted draws first, as _posterior takes them
    n_got, n_full = (got["w"] > 0).sum(axis=1), (full["w"] > 0).sum(axis=1)
    assert np.array_equal(np.minimum(n_got, m), np.minimum(n_full, m))
    assert (n_got < n_full).any() and ((n_got > m) & (n_full > n_got)).sum() < n_got.size
    assert (n_full > m).any() and (n_full < m).any()
    for n in range(n_got.size):
        k = min(int(n_got[n]), m)
        for name in full:
            assert np.array_equal(got[name][n, :k], full[name][n, :k]), (name, n)


def point_pair() -> MeasuredEyePair:
    """The small pair's facets with every lens of an eye at one point, its centre: the key
    check's bound (limit3d_cones.key_hits) is then tight, angle(a_j, c - o) <= alpha_j +
    asin(g / |c - o|) exactly where facet j sees the ball."""
    base = small_pair()
    eyes = [
        MeasuredEye(np.repeat(e.centroid[None], e.n, 0), e.axes, e.acceptance, name=e.name)
        for e in (base.eye_a, base.eye_b)
    ]
    return MeasuredEyePair(eyes[0], eyes[1], name="points")


@pytest.mark.parametrize(
    ("ranges", "most_left", "pair"), [(NEAR, 0.8, None), (FAR, 0.02, None), (FAR, 0.02, "points")]
)
def test_the_key_check_decides_as_the_exact_check(ranges, most_left, pair, monkeypatch):
    """limit3d_cones.key_hits (per key a bound rules most facets out, per draw most of the
    rest, the certified test the few left; kernels.measured_lit.key_check_kernel) against
    limit3d_exact.exact_hits (the pair's lit_csr and in_bfv) on the proposal's weighted
    draws, the same draws with g moved by 1e-7 and by 30 % either way, and the brute-force
    balls of the keys: the same verdict on every one, almost all decided by the kernel
    where the balls lie far from the eyes (FAR; NEAR's may come within a lens offset and
    a radius of the key's lenses, where the bound does not hold: exact_hits decides).
    Breaking a line of the kernel fails this test."""
    from eyeviz.estimators import limit3d_cones
    from eyeviz.estimators.limit3d_exact import exact_hits
    from eyeviz.estimators.limit3d_measured import _uniforms

    eyes = point_pair() if pair == "points" else None
    dom, ds, groups, lit = _commonest_keys(6000, 12, seed=5, ranges=ranges, pair=eyes)
    est = Limit3DEstimator(dom, samples=512)
    prop = est._proposal
    keys = _key_hash(*lit) ^ np.uint64(est.seed)
    st = prop.setup(*lit, keys, 1.0)
    out = prop._draws_kernel(st, _uniforms(keys, 512, 4, [0, 8]), None)
    n, m = out["w"].shape
    cand = np.flatnonzero(out["w"].ravel() > 0)
    c = np.stack([out[k].ravel()[cand] for k in "xyz"], axis=1)
    g = out["g"].ravel()[cand]
    o = np.asarray(dom.origin, float)
    balls = [(c, g * f, cand // m) for f in (1.0, 1 + 1e-7, 1 - 1e-7, 1.3, 0.7)]
    # the ends of each draw's g interval over every facet (its lit facets' largest cone
    # distance, its unlit ones' smallest), 1e-8 inside and outside: one facet decides
    lo, hi = _cone_interval(dom, c, cand // m, lit)
    for end in (lo, hi):
        balls += [(c, end * f, cand // m) for f in (1 - 1e-8, 1 + 1e-8)]
    for j, grp in enumerate(groups):
        r, az, el = ds.r[grp], ds.azimuth[grp], ds.elevation[grp]
        cb = o + r[:, None] * np.stack(
            [np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)], axis=1
        )
        balls.append((cb, ds.g[grp], np.full(grp.size, j)))
    p = np.concatenate([b[0] for b in balls])
    gg = np.concatenate([b[1] for b in balls])
    row = np.concatenate([b[2] for b in balls])
    order = np.argsort(row, kind="stable")
    p, gg, row = p[order], gg[order], row[order]
    left = []

    def counting(domain, p_, g_, row_, la, lb):
        left.append(row_.size)
        return exact_hits(domain, p_, g_, row_, la, lb)

    monkeypatch.setattr(limit3d_cones, "exact_hits", counting)
    got = limit3d_cones.key_hits(dom, p, gg, row, *lit)
    want = exact_hits(dom, p, gg, row, *lit)
    assert np.array_equal(got, want)
    assert 0.2 * row.size < want.sum() < 0.9 * row.size
    assert sum(left) < most_left * row.size


def _cone_interval(dom, c: np.ndarray, row: np.ndarray, lit) -> tuple[np.ndarray, np.ndarray]:
    """Per ball centre c (D, 3) of key ``row``: the largest cone distance of the key's lit
    facets and the smallest of its unlit ones, over every facet of both eyes (numpy)."""
    lo, hi = np.zeros(row.size), np.full(row.size, np.inf)
    for which, (ptr, ind) in zip("AB", lit, strict=True):
        pos, axes, acc = dom.eyes.facets(which)
        ax = axes / np.linalg.norm(axes, axis=1, keepdims=True)
        v = c[:, None, :] - pos[None]
        vn = np.linalg.norm(v, axis=2)
        theta = np.arccos(np.clip(np.einsum("dkj,kj->dk", v, ax) / vn, -1.0, 1.0))
        ex = theta - acc / 2
        dist = np.where(ex <= 0, 0.0, np.where(ex < np.pi / 2, vn * np.sin(ex), vn))
        is_lit = np.zeros((row.size, pos.shape[0]), bool)
        for d, k in enumerate(row):
            is_lit[d, ind[ptr[k] : ptr[k + 1]]] = True
        lo = np.maximum(lo, np.where(is_lit, dist, 0.0).max(axis=1))
        hi = np.minimum(hi, np.where(is_lit, np.inf, dist).min(axis=1))
    return lo, hi


def test_a_key_the_reference_search_misses_is_found_by_the_wider_search(monkeypatch):
    """Honeybee keys (fresh rows of the bench's seed) whose rays' triangulation lies 3-9
    facet spacings from their posterior: the first reference search ends at an infeasible
    centre (H < 0) and the box about it holds nothing; the wider search (``FAR``) finds a
    feasible reference and a box holding the ball that made the key."""
    from eyeviz.estimators import limit3d_measured as lm
    from eyeviz.files.eye_io import load_eyes, shipped_eye

    dom = Domain3D.for_eyes(load_eyes(shipped_eye("AM_60185-real.eye")))
    a = [[3167, 3168, 3177, 3179, 3180, 3184, 3185], [1970, 2066, 2087, 2159, 2254, 2277, 2340]]
    b = [[3181, 3183, 3186], [1774, 1775, 1776, 1873, 1874, 1875, 1907, 1970, 1971, 2001,
         2003, 2066, 2087, 2089, 2091, 2159, 2160, 2215, 2254, 2277, 2279, 2340, 2365]]  # fmt: skip
    balls = np.array([[-6.9989, 2.2332, -52.3497], [0.6343, 13.0075, 13.8416]])
    csr = [(np.array([0, len(s[0]), len(s[0]) + len(s[1])]), np.array(s[0] + s[1])) for s in (a, b)]
    prop = lm.MeasuredProposal(dom, "single", 64, 8)
    keys = _key_hash(*csr)
    for far, found in ((0.0, False), (lm.FAR, True)):
        monkeypatch.setattr(lm, "FAR", far)
        st = prop.setup(*csr, keys, 1.0)
        g_lo, g_hi = prop._h(st, st["ref"][:, None, :])
        assert np.all((g_hi > g_lo)[:, 0] == found)
        # the balls in (delta, beta): A's direction about u0, B's angle to the baseline
        v = balls - prop.fa.centre
        v /= np.linalg.norm(v, axis=1, keepdims=True)
        cu = np.einsum("nj,nj->n", v, st["u0"])
        x = np.stack([np.einsum("nj,nj->n", v, st[e]) / cu for e in ("e1", "e2")], 1)
        u = balls - prop.fb.centre
        beta = np.arccos(u @ -prop.bhat / np.linalg.norm(u, axis=1))
        x = np.concatenate([x, beta[:, None]], axis=1)
        inside = ((x >= st["box_lo"]) & (x <= st["box_hi"])).all(axis=1)
        assert np.all(inside == found)


def test_a_key_whose_first_batch_finds_nothing_goes_to_the_retry_at_once(far, monkeypatch):
    """The measured proposal's ``retry_empty`` (limit3d._tops_up): a key with nothing
    accepted in its first batch gets no top-ups (its later batches rarely find it) but the
    retry at once; only if the retry finds fewer than MIN_ESS draws does it get the
    top-ups too (the draws it had without ``retry_empty``), answered from whichever found
    more."""
    from eyeviz.estimators import limit3d_measured as lm

    dom, _, _, lit = far
    seen: dict = {}
    sample = lm.MeasuredProposal._sampled

    def counting(self, st, keys, streams, nst, rows):
        at, vals, width = sample(self, st, keys, streams, nst, rows)
        m = self.samples
        row, col = at // width, at % width
        for i, k in enumerate(keys):
            if rows is None or rows[i]:
                for j in range(int(nst[i])):
                    got = int(((row == i) & (col // m == j)).sum())
                    seen.setdefault((int(k), int(streams[i, j]) % 8), []).append(got)
        return at, vals, width

    monkeypatch.setattr(lm.MeasuredProposal, "_sampled", counting)
    runs = {}
    for empty in (True, False):
        monkeypatch.setattr(lm, "RETRY_EMPTY", empty)
        seen.clear()
        p = Limit3DEstimator(dom, samples=8).predict(*lit)
        runs[empty] = (p, {k: list(v) for k, v in seen.items()})
    (p, on), (q, off) = runs[True], runs[False]
    keys = _key_hash(*lit)
    missed = [n for n, k in enumerate(keys) if on[(int(k), 0)][0] == 0]
    retry = {n: sum(on.get((int(keys[n]), 2), [0])) for n in missed}
    found = [n for n in missed if retry[n] >= 4]
    weak = [n for n in missed if retry[n] < 4]
    assert found and weak
    for n in found:  # retried at once: one first-pass batch (up to 16 without the rule)
        assert len(on[(int(keys[n]), 0)]) == 1
    assert max(len(off[(int(keys[n]), 0)]) for n in found) > 1
    for n in weak:  # the retry found under 4 draws: the first pass's top-ups too
        tops = off[(int(keys[n]), 0)]
        assert on[(int(keys[n]), 0)][1:] == tops
        if sum(tops) > min(retry[n], 8):  # they found more: their answer
            assert p.r[n] == q.r[n] and p.flagged[n] == q.flagged[n]


@pytest.mark.parametrize("flag", ["BOX_KERNEL", "GRID_KERNEL", "SEARCH_KERNEL", "EDGES_KERNEL"])
def test_the_compiled_searches_give_the_numpy_loops_set_up(far, monkeypatch, flag):
    """MeasuredProposal._around's bisection, widening and pilot as one compiled call
    (``BOX_KERNEL``, kernels.measured_limit.box_kernel), limit3d_provable.dir_region's
    grids as one (``GRID_KERNEL``, kernels.limit3d_region.dir_grid_kernel) and the
    reference search's (``SEARCH_KERNEL``, kernels.measured_limit.search_kernel), and the
    constraining facets' (``EDGES_KERNEL``, kernels.limit3d_region.constraining_kernel),
    against their
    numpy loops with the compiled region and cell tests: every array of the set-up bit
    for bit (the boxes, the pilot's feasible points' box and number, the provable box,
    the mixture), on 48 fresh honeybee keys in chunks of 8, the two the first reference
    search misses (the wider search's chunk) and the far test pair's 30 keys."""
    from eyeviz.estimators import limit3d_cones as lc
    from eyeviz.estimators import limit3d_measured as lm
    from eyeviz.estimators import limit3d_provable as lp
    from eyeviz.files.eye_io import load_eyes, shipped_eye

    bee = Domain3D.for_eyes(load_eyes(shipped_eye("AM_60185-real.eye")))
    ds = generate3d(48, bee, seed=20261208)
    cases = []
    for s0 in range(0, 48, 8):
        rows = np.arange(s0, s0 + 8)
        cases.append((bee, take_rows(ds.indptr_a, ds.indices_a, rows),
                      take_rows(ds.indptr_b, ds.indices_b, rows)))  # fmt: skip
    a = [[3167, 3168, 3177, 3179, 3180, 3184, 3185], [1970, 2066, 2087, 2159, 2254, 2277, 2340]]
    b = [[3181, 3183, 3186], [1774, 1775, 1776, 1873, 1874, 1875, 1907, 1970, 1971, 2001,
         2003, 2066, 2087, 2089, 2091, 2159, 2160, 2215, 2254, 2277, 2279, 2340, 2365]]  # fmt: skip
    cases.append((bee, *[(np.array([0, len(s[0]), len(s[0]) + len(s[1])]),
                          np.array(s[0] + s[1])) for s in (a, b)]))  # fmt: skip
    cases.append((far[0], *far[3]))
    tight = 0
    for dom, la, lb in cases:
        prop = lm.MeasuredProposal(dom, "single", 64, 8)
        keys = _key_hash(la, lb)
        got = {}
        for compiled in (True, False):
            where = {"GRID_KERNEL": lp, "EDGES_KERNEL": lc}.get(flag, lm)
            monkeypatch.setattr(where, flag, compiled)
            got[compiled] = prop.setup(la, lb, keys, 1.0)
        assert got[True].keys() == got[False].keys()
        for k, v in got[False].items():
            if isinstance(v, np.ndarray):
                assert np.array_equal(got[True][k], v, equal_nan=True), k
        for eye in ("ea", "eb"):
            for name in ("pos", "ax", "half", "lit", "pad", "pa", "pp"):
                assert np.array_equal(getattr(got[True][eye], name), getattr(got[False][eye], name))
        tight += int(np.sum(got[True]["n_tight"] > 0))
    assert tight > 40


def test_one_key_s_draws_take_the_warmed_signature(far):
    """The draws' kernel gets its streams as a writable copy: one key's broadcast streams
    (read-only and contiguous) were a second signature, loaded from numba's cache at the
    first predict's retry of a single key (kernels.warm compiles the writable one)."""
    from eyeviz.core.kernels import measured_limit
    from eyeviz.estimators import limit3d_measured as lm

    dom, _, _, (la, lb) = far
    one = (take_rows(*la, np.array([0])), take_rows(*lb, np.array([0])))
    keys = _key_hash(*one)
    prop = lm.MeasuredProposal(dom, "single", 64, 8)
    prop.sample_sparse(prop.setup(*one, keys, 1.0), keys, 3)
    sigs = measured_limit.mixture_draws_kernel.signatures
    assert sigs and all(sig[1].mutable for sig in sigs)
