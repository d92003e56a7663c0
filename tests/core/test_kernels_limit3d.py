"""The spherical limit's compiled proposal kernels against their numpy references, element
by element (issue 31 item 3, issue 33): the HEALPix model and ray search bit for bit, the
measured cone distances to 1e-12, the early-exit interval kernel keeping exactly the draws
the reference keeps, the row comparison exactly; and limit3d's answers with the kernels
equal to the reference's (EYEVIZ_JIT=0): to 1e-9 with the same accepted draws (the
set-up's compiled linearisation is the reference's to a few ulps)."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from eyeviz.core.domain import Domain3D
from eyeviz.core.measured import MeasuredEye, MeasuredEyePair
from eyeviz.dataset.algorithm1_3d import generate3d
from eyeviz.estimators import limit3d_exact, limit3d_healpix
from eyeviz.estimators.base import take_rows
from eyeviz.estimators.limit3d import Limit3DEstimator
from eyeviz.estimators.limit3d_eye import _Eye
from eyeviz.estimators.limit3d_measured import MeasuredProposal, _Edges

kr = pytest.importorskip("eyeviz.core.kernels.limit3d_region")
ka = pytest.importorskip("eyeviz.core.kernels.limit3d_affine")
kd = pytest.importorskip("eyeviz.core.kernels.limit3d_draws")

SPECIAL = [np.inf, -np.inf, np.nan, 0.0, -0.0, 1e300, -1e300, 1e-300]


def _same_bits(a: np.ndarray, b: np.ndarray) -> bool:
    """Equal element by element, NaN where NaN (the sign of a zero aside)."""
    return bool(np.all((a == b) | (np.isnan(a) & np.isnan(b))))


def _affine_eye(rng: np.random.Generator, n: int, k: int) -> SimpleNamespace:
    """An _Eye's affine model: random distances and slopes, some cells padding."""
    lit = rng.random((n, k)) < 0.5
    pad = rng.random((n, k)) < 0.2
    d = rng.uniform(0.0, 0.05, (n, k))
    t = rng.normal(size=(n, k, 2))
    t /= np.linalg.norm(t, axis=2, keepdims=True)
    e = SimpleNamespace(lit=lit, pad=pad, d=d, t=t)
    _Eye._affine(e)  # type: ignore[arg-type]
    return e


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 2**31), k=st.integers(1, 40), special=st.booleans())
def test_affine_bounds_kernel_is_the_reference_bit_for_bit(seed, k, special):
    rng = np.random.default_rng(seed)
    e = _affine_eye(rng, 3, k)
    delta = rng.normal(scale=0.03, size=(3, 17, 2))
    if special:  # inf, NaN, huge and tiny offsets: numpy's NaN rules must hold
        delta.ravel()[rng.integers(0, delta.size, 6)] = rng.choice(SPECIAL, 6)
    lo, hi = np.empty((3, 17)), np.empty((3, 17))
    ka.affine_bounds_kernel(e.a_lit, e.t_lit, e.a_unl, e.t_unl, e.lists, delta, lo, hi)
    with np.errstate(all="ignore"):
        want_lo, want_hi = _Eye._bounds_ref(e, delta)  # type: ignore[arg-type]
    assert _same_bits(lo, want_lo) and _same_bits(hi, want_hi)


@pytest.fixture(scope="module")
def healpix_chunk():
    """A chunk of 6 nside-16 keys set up by the HEALPix proposal."""
    d = Domain3D(nside=16)
    ds = generate3d(6, d, seed=11)
    rows = np.arange(6)
    la = take_rows(ds.indptr_a, ds.indices_a, rows)
    lb = take_rows(ds.indptr_b, ds.indices_b, rows)
    prop = limit3d_healpix.HealpixProposal(d, "single", 64, 8)
    keys = np.arange(6, dtype=np.uint64) * np.uint64(7919)
    return prop, prop.setup(la, lb, keys, 1.0), keys


@pytest.mark.parametrize("wide", [False, True])
def test_ray_region_kernel_is_the_reference_bit_for_bit(healpix_chunk, monkeypatch, wide):
    """The draws' kernel's search along A's rays for where the g test can pass (its points
    chosen one by one, _aim_next) against the numpy reference (_ray_bracket on every
    point), on rays through B's region, A's sin radii about B's so that rays with no point
    inside, short runs and the whole ray all occur."""
    prop, stt, _ = healpix_chunk
    eb, d = stt["eb"], prop.domain
    rng = np.random.default_rng(5)
    n = eb.c.shape[0]
    rho_b = rng.uniform(d.r_min, d.r_max, (n, 50, 1))
    v = eb.c[:, None, :] + rng.normal(size=(n, 50, 3)) * (0.02 if wide else 0.005)
    ca = stt["B"] + rho_b * v / np.linalg.norm(v, axis=2, keepdims=True) - stt["A"]
    rho = np.linalg.norm(ca, axis=2)
    ca /= rho[..., None]
    lo, hi = rng.uniform(0.7, 1.0, (n, 50)) / rho, rng.uniform(1.0, 1.3, (n, 50)) / rho
    good = rng.random((n, 50)) < 0.8
    b_lo, b_hi = eb.bounds(np.zeros((n, 1, 2)))
    k = rho_b[..., 0] / rho  # rho_B / rho: A's sin radius of B's cap
    s_lo = np.sin(b_lo) * k * rng.uniform(0.6, 1.1, (n, 50))
    s_hi = np.maximum(np.sin(b_hi) * k * rng.uniform(0.9, 1.6, (n, 50)), s_lo)
    args = (eb, ca, lo, hi, good, stt["slack"], 0.01, (s_lo, s_hi))
    got = limit3d_healpix._ray_region_draws(*args)
    monkeypatch.setenv("EYEVIZ_JIT", "0")
    want = limit3d_healpix._ray_region_draws(*args)
    assert _same_bits(got[0], want[0]) and _same_bits(got[1], want[1])
    # brackets of every width occur: short runs (or none inside) to the whole ray
    step = (hi - lo) / (limit3d_healpix.RAY_GRID - 1)
    width = np.round(((got[1] - got[0]) / step)[good]).astype(int)
    assert set(width) == set(range(1, limit3d_healpix.RAY_GRID))


@pytest.mark.parametrize("rounds", [1, 2, 3])
def test_the_draws_lanes_search_each_ray_as_its_own_search(healpix_chunk, rounds):
    """The draws' kernel's searches side by side (_ray_searches: four lanes, the gap and B's
    model written out in its loop) against the search of one ray at a time
    (ray_region_kernel: _ray_search of _gap_g), bit for bit, on 0-50 rays of every key
    (counts that do not fill the lanes, rays that finish on different steps), with rays
    whose gap is NaN or 0 wide."""
    prop, stt, _ = healpix_chunk
    eb, d = stt["eb"], prop.domain
    rng = np.random.default_rng(17 + rounds)
    n, m = eb.c.shape[0], 50
    v = eb.c[:, None, :] + rng.normal(size=(n, m, 3)) * 0.01
    rho_b = rng.uniform(d.r_min, d.r_max, (n, m, 1))
    ca = stt["B"] + rho_b * v / np.linalg.norm(v, axis=2, keepdims=True) - stt["A"]
    rho = np.linalg.norm(ca, axis=2)
    ca /= rho[..., None]
    lo, hi = rng.uniform(0.7, 1.0, (n, m)) / rho, rng.uniform(1.0, 1.3, (n, m)) / rho
    hi[:, 7] = lo[:, 7]  # no width
    b_lo, b_hi = eb.bounds(np.zeros((n, 1, 2)))
    k = rho_b[..., 0] / rho  # rho_B / rho: A's sin radius of B's cap, so either side decides
    s_lo = np.sin(b_lo) * k * rng.uniform(0.6, 1.1, (n, m))
    s_hi = np.maximum(np.sin(b_hi) * k * rng.uniform(0.9, 1.6, (n, m)), s_lo)
    s_hi[:, 11] = np.nan
    slack = np.ascontiguousarray(np.broadcast_to(stt["slack"], (n, 1))[:, 0], np.float64)
    t = np.linspace(0.0, 1.0, limit3d_healpix.RAY_GRID)
    a = np.ascontiguousarray(eb.a, np.float64)
    want_lo, want_hi = lo.copy(), hi.copy()
    kd.ray_region_kernel(eb.a_lit, eb.t_lit, eb.a_unl, eb.t_unl, eb.lists, eb.c, eb.e1, eb.e2,
                         a, ca, want_lo, want_hi, slack, t, rounds, np.ones((n, m), np.bool_),
                         s_lo, s_hi)  # fmt: skip
    moved = 0
    for key in range(n):
        nq = [0, 1, 3, 4, 5, 13, 50][key % 7]
        qv = np.empty((m, 8))
        qv[:, :3], qv[:, 3] = ca[key], 1.0
        qv[:, 4], qv[:, 5], qv[:, 6], qv[:, 7] = lo[key], hi[key], s_lo[key], s_hi[key]
        out = np.full((m, 2), -7.0)
        kd._ray_searches(eb.a_lit, eb.t_lit, eb.a_unl, eb.t_unl, *eb.lists, eb.c, eb.e1, eb.e2,
                         a, key, qv, nq, slack[key], t, rounds, out)  # fmt: skip
        assert _same_bits(out[:nq, 0], want_lo[key, :nq]), (key, nq)
        assert _same_bits(out[:nq, 1], want_hi[key, :nq]), (key, nq)
        assert np.all(out[nq:] == -7.0)
        moved += int(np.sum((out[:nq, 0] != lo[key, :nq]) | (out[:nq, 1] != hi[key, :nq])))
    assert moved > 8  # the searches did narrow the rays


def test_the_ray_search_picks_the_reference_s_bracket():
    """The draws' kernel's search along the ray (_aim_next, replayed point by point) against
    its numpy reference (_ray_bracket, every point known) on gap profiles of 2-10 points
    with ties, plateaus, NaN and several peaks; on unimodal profiles it is the full scan's
    bracket (the first and last point inside, else the first maximum)."""
    from eyeviz.estimators.limit3d_proposal import _ray_bracket

    rng = np.random.default_rng(3)
    for _ in range(600):
        grid = int(rng.integers(2, 11))
        g = rng.choice([-2.0, -1.0, 0.0, 0.5, 1.0, np.nan], grid)
        if rng.random() < 0.5:  # unimodal: up then down
            g = -np.abs(np.arange(grid) - rng.uniform(-1, grid)) + rng.uniform(-3, 3)
            if rng.random() < 0.3:
                g = np.round(g)  # plateaus and exact zeros
        seen, evals = 0, 0
        while True:
            j, first, last = kd._aim_next(g, seen, grid)
            if j < 0:
                break
            assert not (seen >> j) & 1
            seen |= 1 << j
            evals += 1
        want = _ray_bracket(g[None, :])
        assert (first, last) == (int(want[0][0]), int(want[1][0])), g
        if np.all(np.diff(np.sign(np.diff(g))) <= 0) and not np.isnan(g).any():
            ins = np.flatnonzero(g > 0)
            full = (ins[0], ins[-1]) if ins.size else (int(np.argmax(g)),) * 2
            assert (first, last) == full, g


def test_healpix_draws_are_the_reference_s(healpix_chunk, monkeypatch):
    """The whole sample (draws, exact check), compiled against EYEVIZ_JIT=0: the same
    accepted draws, their values to 1e-12 and weights to 1e-9 (the draws' kernel rounds
    as math does, not as numpy: kernels.limit3d_draws)."""
    prop, stt, keys = healpix_chunk
    got = prop.sample(stt, keys, [3, 11])
    monkeypatch.setenv("EYEVIZ_JIT", "0")
    want = prop.sample(stt, keys, [3, 11])
    kept = want["w"] > 0
    assert kept.sum() >= 10
    assert np.array_equal(got["w"] > 0, kept)
    for k in want:
        tol = 1e-9 if k == "w" else 1e-12
        assert np.allclose(got[k][kept], want[k][kept], rtol=tol, atol=1e-15), k


def small_pair() -> MeasuredEyePair:
    """As tests/estimators/test_limit3d_measured.py: 40 facets an eye on spheres of radius
    0.5 about (-/+2, 0, 0), acceptance angles 0.3-0.5 rad per facet."""
    rng = np.random.default_rng(0)
    k = np.arange(90) + 0.5
    z = 1 - 2 * k / 90
    phi = np.pi * (1 + 5**0.5) * k
    d = np.stack([np.sqrt(1 - z * z) * np.cos(phi), np.sqrt(1 - z * z) * np.sin(phi), z], 1)
    d = d[d[:, 1] > 0.1]
    eyes = [
        MeasuredEye(np.array([sx, 0.0, 0.0]) + 0.5 * d, d, rng.uniform(0.3, 0.5, len(d)), name=nm)
        for sx, nm in ((-2.0, "A"), (2.0, "B"))
    ]
    return MeasuredEyePair(eyes[0], eyes[1], name="small")


@pytest.fixture(scope="module")
def bee_small():
    """The small measured pair (tests/estimators/test_limit3d_measured.py), a chunk of 6
    keys set up by the measured proposal."""
    dom = Domain3D.for_eyes(small_pair(), r_min=4.0, r_max=12.0, g_max=1.5, el_max=0.6)
    ds = generate3d(6, dom, seed=4)
    rows = np.arange(6)
    la = take_rows(ds.indptr_a, ds.indices_a, rows)
    lb = take_rows(ds.indptr_b, ds.indices_b, rows)
    prop = MeasuredProposal(dom, "single", 128, 8)
    keys = np.arange(6, dtype=np.uint64) * np.uint64(104729)
    return dom, prop, prop.setup(la, lb, keys, 1.0), keys, (la, lb)


def _centres(rng: np.random.Generator, e: _Edges, m: int, spread: float) -> np.ndarray:
    """Centres about each key's lit facets: in their cones, near their edges, behind
    their lenses (the apex case) and far off."""
    n = e.pos.shape[0]
    k = rng.integers(0, e.pos.shape[1], (n, m))
    rows = np.arange(n)[:, None]
    p, a = e.pos[rows, k], e.ax[rows, k]
    dist = rng.choice([-0.5, 0.3, 3.0, 8.0], (n, m))[..., None]
    return p + dist * a + rng.normal(scale=spread, size=(n, m, 3))


@pytest.mark.parametrize("spread", [0.01, 0.3, 3.0])
def test_cone_bounds_kernel_agrees_with_the_reference(bee_small, spread):
    ea = bee_small[2]["ea"]
    c = _centres(np.random.default_rng(int(spread * 100)), ea, 200, spread)
    lo, hi = np.empty(c.shape[:2]), np.empty(c.shape[:2])
    kr.cone_bounds_kernel(*ea.columns(), c, lo, hi)
    want_lo, want_hi = ea._bounds_ref(c)
    scale = np.linalg.norm(c, axis=2) + 1.0
    assert np.all(np.abs(lo - want_lo) <= 1e-12 * scale)
    assert np.all(np.abs(hi - want_hi) <= 1e-12 * scale)
    assert (want_lo == 0).any() and (want_lo > 0).any()  # inside and outside cones


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 2**31))
def test_same_rows_kernel_is_the_reference(seed):
    rng = np.random.default_rng(seed)
    kc = rng.integers(0, 4, 5)
    kp = np.concatenate([[0], np.cumsum(kc)])
    ki = np.concatenate([np.sort(rng.choice(9, c, replace=False)) for c in kc]).astype(np.int64)
    row = rng.integers(0, 5, 12)
    # candidate rows: the key's own rows, some changed in one index or in length
    sets = [ki[kp[r] : kp[r + 1]].copy() for r in row]
    for s in sets:
        if s.size and rng.random() < 0.4:
            s[rng.integers(0, s.size)] += 1
        elif rng.random() < 0.2:
            s.resize(s.size + 1, refcheck=False)
    ptr = np.concatenate([[0], np.cumsum([s.size for s in sets])]).astype(np.int64)
    ind = np.concatenate(sets).astype(np.int64)
    got = np.empty(row.size, np.bool_)
    kr.same_rows_kernel(ptr, ind, kp, ki, row, got)
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("EYEVIZ_JIT", "0")
        want = limit3d_exact.same_rows(ptr, ind, (kp, ki), row)
    assert np.array_equal(got, want)


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 2**31), m=st.integers(1, 40), special=st.booleans())
def test_compact_draws_kernel_is_the_reference(seed, m, special):
    """limit3d_rows._compact compiled (limit3d_region.compact_draws_kernel) and in numpy: the
    same arrays bit for bit, over all columns and over a range of them with some rows
    weighing 0 (the top-ups' batches), with weights 0, negative or NaN, values inf or NaN
    (the padding: the row's largest accepted value, 1 where that is not finite or there
    is none), rows with nothing accepted and a strided view of the draws."""
    from eyeviz.core import kernels
    from eyeviz.estimators import limit3d_rows

    rng = np.random.default_rng(seed)
    n = int(rng.integers(1, 6))
    names = ("x", "y", "z", "g", "r", "az", "el", "w")
    big = {k: rng.normal(size=(n, 2 * m)) for k in names}
    big["w"] = np.where(rng.random((n, 2 * m)) < 0.4, rng.exponential(size=(n, 2 * m)), 0.0)
    big["w"][0] = 0.0  # a row with nothing accepted
    if special:
        for k in names:
            big[k].ravel()[rng.integers(0, 2 * n * m, 3)] = rng.choice(SPECIAL, 3)
    s = {k: v[:, ::2] for k, v in big.items()}  # strided views
    rows = rng.random(n) < 0.7
    lo = int(rng.integers(0, m))
    with pytest.MonkeyPatch.context() as mp:
        mp.setitem(kernels._STATE, "ready", True)
        got = [limit3d_rows._compact(s), limit3d_rows._compact(big, lo, 2 * m - lo // 2, rows)]
    want = [limit3d_rows._compact_ref(s), limit3d_rows._compact_ref(big, lo, 2 * m - lo // 2, rows)]
    for g, w in zip(got, want, strict=True):
        assert list(g) == list(w)
        for k in names:
            assert g[k].shape == w[k].shape and np.array_equal(g[k], w[k], equal_nan=True), k


def test_limit3d_answers_with_the_kernels_are_the_reference_s_healpix(monkeypatch):
    d = Domain3D(nside=8)
    ds = generate3d(6, d, seed=21)
    rows = np.arange(6)
    la = take_rows(ds.indptr_a, ds.indices_a, rows)
    lb = take_rows(ds.indptr_b, ds.indices_b, rows)
    got = Limit3DEstimator(d, samples=64, max_batches=3).predict(la, lb)
    monkeypatch.setenv("EYEVIZ_JIT", "0")
    want = Limit3DEstimator(d, samples=64, max_batches=3).predict(la, lb)
    # the set-up's linearisation is compiled to a few ulps of the reference's
    # (kernels.limit3d_affine), so the draws move by as little: the same accepted draws
    assert got.n_accepted.sum() > 20
    assert np.array_equal(got.n_accepted, want.n_accepted)
    assert np.array_equal(got.flagged, want.flagged)
    for k in ("r", "azimuth", "elevation", "mc_error"):
        assert np.allclose(getattr(got, k), getattr(want, k), rtol=1e-9, atol=1e-12), k


def test_limit3d_answers_with_the_kernels_are_the_reference_s_measured(bee_small, monkeypatch):
    dom, _, _, _, (la, lb) = bee_small
    got = Limit3DEstimator(dom, samples=128, max_batches=4).predict(la, lb)
    monkeypatch.setenv("EYEVIZ_JIT", "0")
    want = Limit3DEstimator(dom, samples=128, max_batches=4).predict(la, lb)
    assert np.array_equal(got.n_accepted, want.n_accepted) and got.n_accepted.sum() > 50
    assert np.array_equal(got.flagged, want.flagged)
    for k in ("r", "azimuth", "elevation"):
        assert np.allclose(getattr(got, k), getattr(want, k), rtol=1e-10, atol=1e-12)


def test_prefilter_kernel_keeps_what_the_reference_keeps(healpix_chunk):
    """The early-exit prefilter against the numpy one, on caps about each key's centre
    (some exact, some a little off in direction or radius)."""
    from eyeviz.estimators.limit3d_proposal import _prefilter_ref

    _, stt, _ = healpix_chunk
    ea = stt["ea"]
    rng = np.random.default_rng(2)
    n = ea.c.shape[0]
    row = np.repeat(np.arange(n), 300)
    c = ea.c[row] + rng.normal(scale=2e-3, size=(row.size, 3))
    c /= np.linalg.norm(c, axis=1, keepdims=True)
    alpha = ea.alpha0[row] + rng.normal(scale=3e-3, size=row.size)
    got = np.empty(row.size, np.bool_)
    kr.prefilter_kernel(ea.pts, ea.lit, ea.pad, row, c, alpha, ea.step, got)
    want = _prefilter_ref(ea, row, c, alpha)
    assert np.array_equal(got, want)
    assert 0 < want.sum() < want.size


def test_region_test_with_early_exit_keeps_the_reference_s_verdicts(bee_small, monkeypatch):
    """The box search's test H >= -slack (MeasuredProposal._hb), compiled with its early
    exit, against numpy, about each key's box."""
    _, prop, stt, _, _ = bee_small
    rng = np.random.default_rng(3)
    lo, hi = stt["box_lo"], stt["box_hi"]
    span = hi - lo
    x = lo[:, None] - span[:, None] + 3 * span[:, None] * rng.random((lo.shape[0], 500, 3))
    got = prop._hb(stt, x) >= -stt["slack"]
    monkeypatch.setenv("EYEVIZ_JIT", "0")
    want = prop._hb(stt, x) >= -stt["slack"]
    assert np.array_equal(got, want)
    assert 0 < want.sum() < want.size


@pytest.mark.parametrize("grow", [0.0, 1.0, 4.0])
@pytest.mark.parametrize("multi", [False, True])
def test_measured_draws_kernel_agrees_with_the_reference(bee_small, monkeypatch, grow, multi):
    """MeasuredProposal's draws before the exact check, compiled draw by draw, against
    numpy: the same draws weighted (> 0), their values and weights to 1e-12. The box grown
    ``grow`` spans on each side sends draws behind the eyes (beta <= 0, no triangle),
    outside the prior's r, elevation and azimuth ranges and out of every facet's reach;
    ``rows`` leaves a key out."""
    from eyeviz.estimators.limit3d_proposal import _batch_uniforms

    dom, prop, stt, keys, _ = bee_small
    prop = MeasuredProposal(dom, "multi" if multi else "single", 128, 8)
    span = stt["box_hi"] - stt["box_lo"]
    stt = dict(stt, box_lo=stt["box_lo"] - grow * span, box_hi=stt["box_hi"] + grow * span)
    u = _batch_uniforms(keys, 1024, 4, [1, 9])
    rows = np.ones(keys.size, bool)
    rows[2] = False
    got = prop._draws_kernel(stt, u, rows)
    monkeypatch.setenv("EYEVIZ_JIT", "0")
    want = prop._draws_ref(stt, u, rows)
    kept = want["w"] > 0
    assert np.array_equal(got["w"] > 0, kept)
    assert (10 if grow < 2 else 1) <= kept.sum() < kept.size and not kept[2].any()
    for k in want:
        # the weight holds the g interval's length, a difference of two cone distances
        # (each to ~1e-15 of g): relative to the length, g / length x 1e-15, a few 1e-12
        # mostly; the tight box's draws lie where the interval may be 1e-6 of g
        tol = 1e-8 if k == "w" else 1e-13
        assert np.allclose(got[k][kept], want[k][kept], rtol=tol, atol=0), k


def test_measured_draws_kernel_tries_the_facets_that_rule_draws_out_first(bee_small):
    """The walk's order: a draw is dropped at its first facet that empties its interval,
    and that facet moves to the front of the key's order (the kept draws' intervals do
    not depend on the order: max and min are exact). Calling the kernel on the draws in
    reverse order keeps the same draws with the same values."""
    from eyeviz.estimators.limit3d_proposal import _batch_uniforms

    _, prop, stt, keys, _ = bee_small
    stt = dict(stt, n_tight=0 * stt["n_tight"])  # one box: a draw's box not its position's
    u = _batch_uniforms(keys, 512, 4, 3)
    a = prop._draws_kernel(stt, u, None)
    b = prop._draws_kernel(stt, np.ascontiguousarray(u[:, ::-1]), None)
    for k in a:
        assert _same_bits(a[k][a["w"] > 0], b[k][:, ::-1][b["w"][:, ::-1] > 0]), k


def _ties(lo: float, hi: float) -> list[float]:
    """The bounds lo and hi, one ulp in and one out of each, and a value between."""
    up, down = np.inf, -np.inf
    return [lo, hi, np.nextafter(lo, down), np.nextafter(lo, up), np.nextafter(hi, down),
            np.nextafter(hi, up), 0.5 * (lo + hi)]  # fmt: skip


@pytest.mark.parametrize("wide", [False, True])
def test_measured_prior_is_the_reference_s(bee_small, wide):
    """The compiled measured prior (one ball) against limit3d_exact.prior_density, on
    every bound of its support, each exactly, one ulp in and one out: r at r_min and
    r_max, g at r sin(gamma / 2), g_max and r, the elevation at +-el_max, the azimuth at 0
    and pi. ``wide``: a domain where g <= r binds (g_max above r_min) and a ball at r = 0
    (the density's 1 / r^2 infinite: 0 in both)."""
    dom = bee_small[0]
    if wide:
        dom = SimpleNamespace(kind="measured", gamma=dom.gamma, psi=0.0, r_min=0.0,
                              r_max=30.0, g_max=20.0, el_max=1.2)  # fmt: skip
    s = np.sin(dom.gamma / 2)
    rs = _ties(dom.r_min, dom.r_max) + ([0.0, 15.0] if wide else [])
    cases = []
    for r in rs:
        for g in _ties(r * s, dom.g_max) + [r, np.nextafter(r, np.inf), np.nextafter(r, 0)]:
            for el in _ties(-dom.el_max, dom.el_max):
                for az in _ties(0.0, np.pi) + [-0.0]:
                    cases.append((r, g, el, az))
    r, g, el, az = np.array(cases).T
    for multi in (False, True):
        with np.errstate(all="ignore"):
            want = limit3d_exact.prior_density(dom, "multi" if multi else "single", r, g, el, az)
        got = np.array([kr.measured_prior(*c, s, dom.g_max, dom.r_min, dom.r_max, dom.el_max,
                                          multi) for c in cases])  # fmt: skip
        assert np.array_equal(got == 0, want == 0)
        assert np.allclose(got, want, rtol=1e-14, atol=0)
        assert 0.05 < (want > 0).mean() < 0.5


def test_bcentre_is_the_reference_s(bee_small):
    """The compiled centre of one draw against MeasuredProposal._bcentres, on offsets and
    angles about each key's box and beyond it: beta <= 0 and a + beta >= pi give NaN."""
    _, prop, stt, _, _ = bee_small
    rng = np.random.default_rng(8)
    n = stt["u0"].shape[0]
    delta = rng.normal(scale=0.5, size=(n, 300, 2))
    beta = rng.uniform(-0.5, np.pi + 0.5, (n, 300))
    beta[:, :3] = [0.0, -0.0, np.pi]
    c, rho, drho = prop._bcentres(stt, delta, beta)
    for i in range(n):
        for j in range(300):
            frame = (stt["u0"][i], stt["e1"][i], stt["e2"][i])
            d0, d1 = delta[i, j]
            got = kr.bcentre(*frame, d0, d1, beta[i, j], prop.fa.centre, prop.bhat, prop.blen)
            want = (*c[i, j], rho[i, j], drho[i, j])
            assert np.isnan(got[3]) == np.isnan(want[3])
            assert np.allclose(got, want, rtol=1e-12, atol=1e-12, equal_nan=True), (i, j)
    assert np.isnan(rho).any() and np.isfinite(rho).any()


@pytest.mark.parametrize("share", [0.0, 0.3, 1.0])
def test_measured_draws_kernel_mixture_agrees_with_the_reference(bee_small, monkeypatch, share):
    """The defensive mixture (issue 33): the first ``n_def`` draws of each batch from a
    second box (here the box grown by two spans on each side), every weight over the two
    boxes' mixture density; compiled against numpy, the same draws weighted, values and
    weights to 1e-12 (one key gets none from the second box, one all)."""
    from eyeviz.estimators.limit3d_proposal import _batch_uniforms

    dom, _, stt, keys, _ = bee_small
    stt = dict(stt, n_tight=0 * stt["n_tight"])  # the two boxes alone (the tight box: below)
    prop = MeasuredProposal(dom, "single", 512, 8)
    span = stt["box_hi"] - stt["box_lo"]
    n_def = np.full(keys.size, int(share * 512), np.int64)
    n_def[0], n_def[-1] = 0, 512
    u = _batch_uniforms(keys, 512, 4, [2, 10])
    if 0 < share < 1:
        # key 2's split just before a draw the box alone keeps: the split's boundary shows
        alone = prop._draws_ref(dict(stt, n_def=0 * n_def, def_lo=stt["box_lo"],
                                     def_hi=stt["box_hi"]), u, None)  # fmt: skip
        n_def[2] = np.flatnonzero(alone["w"][2, 1:512] > 0)[0] + 1
    stt = dict(stt, def_lo=stt["box_lo"] - 2 * span, def_hi=stt["box_hi"] + 2 * span,
               n_def=n_def)  # fmt: skip
    got = prop._draws_kernel(stt, u, None)
    monkeypatch.setenv("EYEVIZ_JIT", "0")
    want = prop._draws_ref(stt, u, None)
    kept = want["w"] > 0
    assert np.array_equal(got["w"] > 0, kept)
    assert 10 <= kept.sum() < kept.size
    for k in want:
        tol = 1e-10 if k == "w" else 1e-13
        assert np.allclose(got[k][kept], want[k][kept], rtol=tol, atol=0), k
    # the mixture's density is below the box's alone (the grown box takes a share), so a
    # draw of the box (batch position >= n_def) weighs more than with every draw there
    if 0 < share < 1:
        alone = prop._draws_ref(dict(stt, n_def=np.zeros_like(n_def)), u, None)
        assert kept[2, n_def[2] :].any()
        both = kept[1] & (alone["w"][1] > 0) & (np.arange(1024) % 512 >= n_def[1])
        assert both.any() and np.all(want["w"][1][both] > alone["w"][1][both])


def test_direction_keep_kernel_agrees_with_the_reference(bee_small, monkeypatch):
    """The provable box's cell test (limit3d_provable.keep_cells), compiled with its
    early exit, against numpy: the same cells kept, away from the 1e-7 margin's edge;
    some kept, some dropped by F, some by L."""
    ea = bee_small[2]["ea"]
    rng = np.random.default_rng(5)
    n = ea.pos.shape[0]
    lit = ea.lit & ~ea.pad
    mean = np.where(lit[..., None], ea.ax, 0.0).sum(axis=1)
    spread = np.repeat([0.05, 0.5], 200)[None, :, None]  # about the lit facets, and wide
    v = mean[:, None] + spread * rng.normal(size=(n, 400, 3))
    v /= np.linalg.norm(v, axis=2, keepdims=True)
    t = rng.uniform(0.0, 0.05, n)
    s = rng.uniform(0.1, 0.6, n)
    h = rng.uniform(0.0, 0.01, n)
    from eyeviz.estimators.limit3d_provable import _angles, keep_cells

    got = keep_cells(ea, v, t, s, h)
    monkeypatch.setenv("EYEVIZ_JIT", "0")
    want = keep_cells(ea, v, t, s, h)

    f, top = _angles(ea, v)
    margin = np.minimum(np.abs(f - (t + 2 * h + 1e-7)[:, None]),
                        np.abs(top - (s + h + 1e-7)[:, None]))  # fmt: skip
    sure = margin > 1e-12
    assert np.array_equal(got[sure], want[sure])
    assert want.any() and (~want).any()
    assert ((f > (t + 2 * h)[:, None]) & (top <= s[:, None])).any()  # dropped by F alone
    assert (top > (s + h + 1e-7)[:, None]).any()


@pytest.mark.parametrize("streams", [0, 7, [1, 9, 17], [2**31 - 1]])
def test_uniforms_kernel_is_the_reference_bit_for_bit(streams, monkeypatch):
    """The measured proposal's uniforms compiled (limit3d_measured._uniforms) against
    limit3d_proposal._batch_uniforms: the same floats bit for bit, keys with high bits
    set, several streams side by side."""
    from eyeviz.estimators import limit3d_measured as lm
    from eyeviz.estimators.limit3d_proposal import _batch_uniforms

    keys = np.array([0, 1, 2**63 + 5, 2**64 - 1, 0x1234_5678_9ABC_DEF0], np.uint64)
    for k in (3, 4):
        got = lm._uniforms(keys, 96, k, streams)
        want = _batch_uniforms(keys, 96, k, streams)
        assert got.shape == want.shape and np.array_equal(got, want)
        assert 0 < got.min() and got.max() < 1
    monkeypatch.setenv("EYEVIZ_JIT", "0")
    assert np.array_equal(lm._uniforms(keys, 96, 4, streams), want)


def test_direction_kernel_agrees_with_the_reference(monkeypatch):
    """Each eye's best direction at infinity (limit3d_cones._direction), compiled with its
    early exit, against numpy on 60 keys of the small pair and 60 honeybee keys: the same
    direction to 1e-6 rad (arccos near 1 rounds to ~1e-8 either way, so a near tie may
    pick the neighbouring point of the last, finest grid)."""
    from eyeviz.estimators.limit3d_cones import _direction, _facets
    from eyeviz.files.eye_io import load_eyes, shipped_eye

    small = Domain3D.for_eyes(small_pair(), r_min=4.0, r_max=12.0, g_max=1.5, el_max=0.6)
    bee = Domain3D.for_eyes(load_eyes(shipped_eye("AM_60185-real.eye")))
    for dom in (small, bee):
        ds = generate3d(60, dom, seed=12)
        rows = np.arange(60)
        for which, (ptr, ind) in (("A", (ds.indptr_a, ds.indices_a)),
                                  ("B", (ds.indptr_b, ds.indices_b))):  # fmt: skip
            e = _Edges(_facets(dom.eyes, which), take_rows(ptr, ind, rows))
            monkeypatch.setenv("EYEVIZ_JIT", "1")
            got = _direction(e, 8)
            monkeypatch.setenv("EYEVIZ_JIT", "0")
            want = _direction(e, 8)
            ang = np.arccos(np.clip((got * want).sum(axis=1), -1.0, 1.0))
            assert np.all(ang < 1e-6), (which, ang.max())
            assert np.allclose(np.linalg.norm(got, axis=1), 1.0)


def test_locate_kernel_picks_the_reference_s_point(bee_small, monkeypatch):
    """The reference search's step (MeasuredProposal._locate: the first grid point of
    largest H x w), compiled with its early exit, against numpy: the same point on every
    key, on grids about each key's reference and on grids far off (where H < 0 all over),
    with the best point again at the grid's end (a tie: the first is the answer)."""
    _, prop, stt, _, _ = bee_small
    rng = np.random.default_rng(5)
    n = stt["u0"].shape[0]
    for spread in (0.02, 0.3, 3.0):
        delta = rng.normal(scale=spread * prop.domain.gamma, size=(n, 125, 2))
        ww = rng.uniform(prop.w_min, prop.w_max, size=(n, 125))
        c = prop._centres(stt, delta, ww)
        monkeypatch.setenv("EYEVIZ_JIT", "0")
        first = prop._locate(stt, c, ww)
        # the best point again at the grid's end: still the first one
        c[:, -1], ww[:, -1] = c[np.arange(n), first], ww[np.arange(n), first]
        for jit in ("1", "0"):
            monkeypatch.setenv("EYEVIZ_JIT", jit)
            assert np.array_equal(prop._locate(stt, c, ww), first), (spread, jit)


@pytest.mark.parametrize("grow", [0.0, 2.0])
def test_measured_draws_kernel_draws_the_reference_s_uniforms(bee_small, grow):
    """The measured draws' kernel drawing its uniforms inside (limit3d_measured.
    MeasuredProposal._draws_sparse without u: each drawn when first read) against the
    same kernel given limit3d_proposal._batch_uniforms of the same keys and streams: the
    same draws, bit for bit, over two streams side by side, keys with high bits, a key
    left out and (``grow``) a box where most draws are given up before their g."""
    from eyeviz.estimators.limit3d_proposal import _batch_uniforms

    _, prop, stt, _, _ = bee_small
    span = stt["box_hi"] - stt["box_lo"]
    stt = dict(stt, box_lo=stt["box_lo"] - grow * span, box_hi=stt["box_hi"] + grow * span)
    keys = np.arange(6, dtype=np.uint64) * np.uint64(0x9E3779B97F4A7C15) + np.uint64(7)
    rows = np.ones(keys.size, bool)
    rows[3] = False
    streams = np.tile(np.array([2, 10], np.int64), (keys.size, 1))
    nst = np.full(keys.size, 2, np.int64)
    u = _batch_uniforms(keys, prop.samples, 4, [2, 10])
    at, got = prop._draws_sparse(stt, keys, streams, nst, None, rows)
    at_u, want = prop._draws_sparse(stt, keys, streams, nst, u, rows)
    assert np.array_equal(at, at_u) and 10 <= at.size
    assert not ((at // u.shape[1]) == 3).any()
    for k in want:
        assert _same_bits(got[k], want[k]), k
