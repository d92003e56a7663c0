"""The HEALPix proposal's compiled set-up (eyeviz/core/kernels/limit3d_affine.py) against
its numpy reference (EYEVIZ_JIT=0): the same formulas, so the same values to a few ulps,
on the edge cells of real keys (nside 2-180, nside / 2 odd and even) and on random points."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from eyeviz.core.domain import Domain3D
from eyeviz.dataset.algorithm1_3d import generate3d
from eyeviz.estimators.base import take_rows
from eyeviz.estimators.limit3d_eye import STEP, _Eye

ks = pytest.importorskip("eyeviz.core.kernels.limit3d_affine")


def _eyes(nside: int, seed: int, n: int = 5) -> list[_Eye]:
    d = Domain3D(nside=nside)
    ds = generate3d(n, d, seed=seed)
    rows = np.arange(n)
    la = take_rows(ds.indptr_a, ds.indices_a, rows)
    lb = take_rows(ds.indptr_b, ds.indices_b, rows)
    return [_Eye(d, la, np.array([-d.h, 0, 0]), 0), _Eye(d, lb, np.array([d.h, 0, 0]), 1)]


def _kernel(e: _Eye, c: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    e.c = c / np.linalg.norm(c, axis=1, keepdims=True)
    from eyeviz.estimators.limit3d_eye import _frame

    e.e1, e.e2 = _frame(e.c)
    d, t = np.empty(e.pts.shape[:2]), np.empty((*e.pts.shape[:2], 2))
    ks.linearise_kernel(e.pts, e.lit, e.pad, e.c, e.e1, e.e2, e.step, d, t)
    return d, t


def _reference(e: _Eye, c: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    e.c = c / np.linalg.norm(c, axis=1, keepdims=True)
    from eyeviz.estimators.limit3d_eye import _frame

    e.e1, e.e2 = _frame(e.c)
    with np.errstate(all="ignore"):
        e._linearise_ref()
    return e.d.copy(), e.t.copy()


@pytest.mark.parametrize("nside,seed", [(2, 1), (6, 2), (10, 3), (16, 4), (18, 5), (180, 6)])
def test_linearise_kernel_is_the_reference_to_a_few_ulps(nside, seed):
    rng = np.random.default_rng(seed)
    for e in _eyes(nside, seed):
        live = ~e.pad
        assert live.sum() > 0
        for c in (e.u0, e.c, e.u0 + rng.normal(scale=0.01, size=e.u0.shape)):
            got_d, got_t = _kernel(e, c)
            want_d, want_t = _reference(e, c)
            assert np.allclose(got_d[live], want_d[live], rtol=1e-13, atol=1e-15)
            assert np.allclose(got_t[live], want_t[live], rtol=0, atol=1e-12)
            assert np.all(got_d[~live] == 0) and np.all(got_t[~live] == 0)
            # the lit cells' sample gap is taken off (and only theirs)
            assert np.any(e.lit & live) and np.any(~e.lit & live)


@settings(max_examples=30, deadline=None)
@given(seed=st.integers(0, 2**31), p=st.integers(1, 30), zero=st.booleans())
def test_linearise_kernel_on_random_points(seed, p, zero):
    """Random boundary samples (also the centre itself: tangent 0) and padding."""
    rng = np.random.default_rng(seed)
    n, k = 3, 7
    pts = rng.normal(size=(n, k, p, 3))
    pts /= np.linalg.norm(pts, axis=3, keepdims=True)
    c = rng.normal(size=(n, 3))
    c /= np.linalg.norm(c, axis=1, keepdims=True)
    if zero:
        pts[0, 1, :, :] = c[0]
    e = _Eye.__new__(_Eye)
    e.nside, e.pts = 16, pts
    e.lit = rng.random((n, k)) < 0.5
    e.pad = rng.random((n, k)) < 0.2
    got_d, got_t = _kernel(e, c)
    want_d, want_t = _reference(e, c)
    live = ~e.pad
    assert np.allclose(got_d[live], want_d[live], rtol=1e-13, atol=1e-15)
    # a sample at the centre itself: d 0 and its tangent that of the rounding errors, in
    # either path (the model's slope there is arbitrary and multiplies d = 0 in w)
    far = live.copy()
    far[0, 1] &= not zero
    assert np.allclose(got_t[far], want_t[far], rtol=0, atol=1e-12)
    assert np.all(np.hypot(*np.moveaxis(got_t[live], -1, 0)) <= 1 + 1e-12)


@settings(max_examples=30, deadline=None)
@given(seed=st.integers(0, 2**31), k=st.integers(1, 25), special=st.booleans())
def test_affine_kernel_is_the_reference_bit_for_bit(seed, k, special):
    """_Eye._affine compiled against numpy: the full forms and each kind's packed list
    (up to its count), bit for bit, also with inf and NaN distances."""
    from types import SimpleNamespace

    rng = np.random.default_rng(seed)
    n = 4
    d = rng.uniform(0.0, 0.05, (n, k))
    t = rng.normal(size=(n, k, 2))
    if special:
        d.ravel()[rng.integers(0, d.size, 3)] = rng.choice([np.inf, -np.inf, np.nan, -0.0], 3)
    lit = rng.random((n, k)) < 0.5
    pad = rng.random((n, k)) < 0.25
    got = SimpleNamespace(d=d, t=t, lit=lit, pad=pad)
    want = SimpleNamespace(d=d, t=t, lit=lit, pad=pad)
    _Eye._affine(got)  # type: ignore[arg-type]
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("EYEVIZ_JIT", "0")
        _Eye._affine(want)  # type: ignore[arg-type]
    for name in ("a_lit", "t_lit", "a_unl", "t_unl"):
        a, b = getattr(got, name), getattr(want, name)
        assert np.array_equal(a, b, equal_nan=True), name
    for j in (0, 3):  # each kind's list: values up to the row's count
        assert np.array_equal(got.lists[j + 2], want.lists[j + 2])
        for r in range(n):
            c = want.lists[j + 2][r]
            for i in (0, 1):
                x, y = got.lists[j + i][r, :c], want.lists[j + i][r, :c]
                assert np.array_equal(x, y, equal_nan=True), (j, i)


@pytest.mark.parametrize("nside", [1, 2, 6, 10, 16, 180])
def test_boundaries_kernel_is_healpix_boundaries_to_a_few_ulps(nside, monkeypatch):
    """Every cell of small nsides (both poles, the equator, faces' corners), random ones
    at nside 180, each written to its padded slot."""
    from eyeviz.core import healpix, kernels

    monkeypatch.setitem(kernels._STATE, "ready", True)  # small calls too take the kernel
    from eyeviz.estimators.limit3d_eye import _boundaries

    rng = np.random.default_rng(nside)
    npix = 12 * nside * nside
    pix = np.arange(npix) if npix < 5000 else rng.integers(0, npix, 3000)
    rows = rng.integers(0, 4, pix.size)
    order = np.argsort(rows, kind="stable")
    pix, rows = pix[order], rows[order]
    slot = np.arange(pix.size) - np.searchsorted(rows, rows)
    shape = (4, int(slot.max()) + 2)
    got = _boundaries(nside, pix, rows, slot, shape)
    want = np.zeros_like(got)
    want[rows, slot] = healpix.boundaries(nside, pix, STEP)
    assert np.allclose(got, want, rtol=0, atol=4e-16)
    filled = np.zeros(shape, bool)
    filled[rows, slot] = True
    assert np.all(got[~filled] == 0) and np.allclose(np.linalg.norm(got[filled], axis=-1), 1)


@pytest.mark.parametrize("nside,prior", [(16, "single"), (180, "single"), (32, "multi")])
def test_healpix_draws_kernel_agrees_with_the_reference(nside, prior, monkeypatch):
    """HealpixProposal's draws before the exact check, kernel against numpy on the same
    set-up and uniforms (two batches side by side, one key without draws): the same draws
    with a weight, their values to 1e-12 and weights to 1e-9 (a weight holds differences
    of nearly equal radii)."""
    from eyeviz.core import kernels
    from eyeviz.estimators import limit3d_healpix as lh

    monkeypatch.setitem(kernels._STATE, "ready", True)
    d = Domain3D(nside=nside)
    ds = generate3d(6, d, seed=nside + 1)
    rows = np.arange(6)
    la = take_rows(ds.indptr_a, ds.indices_a, rows)
    lb = take_rows(ds.indptr_b, ds.indices_b, rows)
    prop = lh.HealpixProposal(d, prior, 384, 8)
    keys = np.arange(6, dtype=np.uint64) * np.uint64(7919)
    st_ = prop.setup(la, lb, keys, 1.0)
    u = lh._batch_uniforms(keys, 384, 4, [0, 8])
    on = np.ones(6, bool)
    on[2] = False
    got, ca, alpha = prop._draws_kernel(st_, keys, [0, 8], on)  # its own uniforms: u's
    monkeypatch.setenv("EYEVIZ_JIT", "0")
    want, ca_r, alpha_r = prop._draws_ref(st_, u, on)
    kw = got["w"] > 0
    assert np.array_equal(kw, want["w"] > 0)
    assert kw.sum() >= 100 and not kw[2].any() and kw.sum(axis=1)[on].min() > 0
    assert np.all(got["w"][~kw] == 0)
    for k in ("x", "y", "z", "g", "r", "az", "el"):
        assert np.allclose(got[k][kw], want[k][kw], rtol=1e-12, atol=1e-15), k
    assert np.allclose(got["w"][kw], want["w"][kw], rtol=1e-9, atol=0)
    assert np.allclose(ca[kw], ca_r[kw], rtol=0, atol=1e-15)
    assert np.allclose(alpha[kw], alpha_r[kw], rtol=1e-12, atol=1e-15)


@pytest.mark.parametrize("multi", [False, True])
def test_healpix_prior_is_prior_density(multi):
    """The kernel's prior against limit3d_exact.prior_density on balls across and beyond
    the support (and on each bound of r, g and el exactly)."""
    from eyeviz.estimators.limit3d_exact import prior_density

    ka = pytest.importorskip("eyeviz.core.kernels.limit3d_draws")
    d = Domain3D(nside=16)
    rng = np.random.default_rng(3 + multi)
    k = 4000
    r = rng.uniform(d.r_min * 0.9, d.r_max * 1.1, k)
    g = rng.uniform(0.0, d.g_max * 1.1, k)
    el = rng.uniform(-1.2 * d.el_max, 1.2 * d.el_max, k)
    az = rng.uniform(-0.2, math.pi + 0.2, k)
    r[:3] = d.r_min, d.r_max, d.r_max
    g[3:6] = d.g_max, r[3] * math.sin(d.gamma / 2), r[5]
    el[6:8] = d.el_max, -d.el_max
    want = prior_density(d, "multi" if multi else "single", r, g, el, az)
    s = math.sin(d.gamma / 2)
    got = np.array([ka.healpix_prior(r[i], g[i], el[i], az[i], s, float(d.g_max),
                                     float(d.r_min), float(d.r_max), float(d.el_max),
                                     float(d.psi), multi) for i in range(k)])  # fmt: skip
    assert np.array_equal(got > 0, want > 0)
    assert 0.2 < (want > 0).mean() < 0.9
    assert np.allclose(got, want, rtol=1e-12, atol=0)


@settings(max_examples=30, deadline=None)
@given(seed=st.integers(0, 2**31), k=st.integers(1, 20), km=st.integers(1, 20))
def test_compact_kernel_is_the_stable_argsort_gather(seed, k, km):
    """_Eye.prune's compiled gather against numpy's stable argsort of ~keep."""
    rng = np.random.default_rng(seed)
    n, km = 4, min(km, k)
    keep = rng.random((n, k)) < 0.5
    pts = rng.normal(size=(n, k, 3, 3))
    lit = rng.random((n, k)) < 0.5
    d, t = rng.normal(size=(n, k)), rng.normal(size=(n, k, 2))
    o = (np.empty((n, km, 3, 3)), np.empty((n, km), bool), np.empty((n, km), bool),
         np.empty((n, km)), np.empty((n, km, 2)))  # fmt: skip
    ks.compact_kernel(keep, pts, lit, d, t, *o)
    order = np.argsort(~keep, axis=1, kind="stable")[:, :km]
    rows = np.arange(n)[:, None]
    want = (pts[rows, order], lit[rows, order], ~keep[rows, order], d[rows, order],
            t[rows, order])  # fmt: skip
    for a, b in zip(o, want, strict=True):
        assert np.array_equal(a, b)


def test_prune_with_the_kernel_is_the_reference_s(monkeypatch):
    """_Eye.prune on real keys (nside 180), compiled and in numpy: the same cells kept in
    the same slots, the same model."""
    import copy

    from eyeviz.core import kernels

    monkeypatch.setitem(kernels._STATE, "ready", True)
    for e in _eyes(180, 9):
        f = copy.deepcopy(e)
        k0 = e.pad.shape[1]
        reach = np.full(e.c.shape[0], 0.0015)
        e.prune(reach)
        with monkeypatch.context() as mp:
            mp.setenv("EYEVIZ_JIT", "0")
            f.prune(reach)
        assert e.pad.shape[1] < k0 and (~e.pad).sum() > 0  # it pruned, and kept some
        for name in ("pts", "lit", "pad", "d", "t", "a_lit", "t_lit", "a_unl", "t_unl"):
            assert np.array_equal(getattr(e, name), getattr(f, name)), name


@pytest.mark.parametrize("nside,seed", [(16, 11), (180, 12)])
def test_extent_with_the_kernel_is_the_reference_bit_for_bit(nside, seed, monkeypatch):
    """_extent's bisection compiled (extent_kernel) and in numpy, on real keys' models at
    their located centres, with a scalar slack and a per-key one: the same box."""
    from eyeviz.core import kernels
    from eyeviz.estimators.limit3d_proposal import _extent, _locate

    monkeypatch.setitem(kernels._STATE, "ready", True)
    fw = math.sqrt(4 * math.pi / (12 * nside**2))
    for e in _eyes(nside, seed):
        _locate(e, 0.25 * fw, 8, 4)
        n = e.c.shape[0]
        for slack in (0.002 * fw, np.linspace(1e-7, 0.01, n)[:, None] * fw):
            got = _extent(e, 0.5 * fw, slack)
            with monkeypatch.context() as mp:
                mp.setenv("EYEVIZ_JIT", "0")
                want = _extent(e, 0.5 * fw, slack)
            assert np.array_equal(got, want)
            assert (got > 1e-12).any() and (got < 0.5 * fw * 1.5).all()
        # an earlier box on the same model taken for the keys whose slack it had (the
        # others bisected again): the same as a fresh call, and each part is used
        first = _extent(e, 0.5 * fw, 0.002 * fw)
        slack = np.where(np.arange(n) % 2 == 0, 0.002, 0.0005)[:, None] * fw
        same = slack[:, 0] == 0.002 * fw
        got = _extent(e, 0.5 * fw, slack, known=(same, first))
        assert np.array_equal(got, _extent(e, 0.5 * fw, slack))
        assert not np.array_equal(got[~same], first[~same])
        assert np.array_equal(_extent(e, 0.5 * fw, 0.002 * fw, known=(np.ones(n, bool), first)),
                              first)  # fmt: skip


@pytest.mark.parametrize("nside,seed", [(16, 13), (180, 14)])
def test_locate_kernel_is_the_numpy_loop_bit_for_bit(nside, seed, monkeypatch):
    """_locate compiled (limit3d_locate.locate_kernel) and as its numpy loop of kernel
    calls (the grid's bounds, argmax, direction, linearise): the same centres, frames and
    model to the bit; and the numpy reference (EYEVIZ_JIT=0) to 1e-9."""
    import copy

    from eyeviz.core import kernels
    from eyeviz.estimators.limit3d_proposal import _grid, _locate

    monkeypatch.setitem(kernels._STATE, "ready", True)
    fw = math.sqrt(4 * math.pi / (12 * nside**2))
    for e in _eyes(nside, seed):
        e.prune(np.full(e.c.shape[0], 0.25 * fw))
        f, r = copy.deepcopy(e), copy.deepcopy(e)
        _locate(e, 0.25 * fw, 8, 4)
        half, g0 = 0.25 * fw, _grid(8)
        for _ in range(4):  # the loop the kernel replaces, each step compiled
            g = g0[None] * half
            lo, hi = f.bounds(np.broadcast_to(g, (f.c.shape[0], *g0.shape)))
            f.linearise(f.direction(g[0][np.argmax(hi - lo, axis=1)][:, None, :])[:, 0])
            half = half / 3.0
        assert not np.array_equal(e.c, r.c)  # it moved
        for name in ("c", "e1", "e2", "d", "t", "a_lit", "t_lit", "a_unl", "t_unl"):
            assert np.array_equal(getattr(e, name), getattr(f, name)), name
        for a, b in zip(e.lists, f.lists, strict=True):
            assert np.array_equal(a, b)
        with monkeypatch.context() as mp:
            mp.setenv("EYEVIZ_JIT", "0")
            _locate(r, 0.25 * fw, 8, 4)
        assert np.allclose(e.c, r.c, rtol=0, atol=1e-9)


def test_locate_kernel_takes_the_first_of_equal_points_as_argmax():
    """A key whose model has no cells (G = inf at every grid point): the centre moves to
    the grid's first point, as numpy's argmax picks (the kernel's ties)."""
    from eyeviz.core.kernels.limit3d_locate import locate_kernel
    from eyeviz.estimators.limit3d_eye import _frame
    from eyeviz.estimators.limit3d_proposal import _grid

    c = np.array([[0.0, 0.6, 0.8]])
    e1, e2 = _frame(c)
    g0 = _grid(4)
    pad = np.ones((1, 1), np.bool_)
    d, t = np.zeros((1, 1)), np.zeros((1, 1, 2))
    n0 = np.zeros(1, np.int64)
    lists = (d.copy(), t.copy(), n0, d.copy(), t.copy(), n0.copy())
    want = c + 0.1 * g0[0, 0] * e1 + 0.1 * g0[0, 1] * e2
    locate_kernel(np.ones((1, 1, 2, 3)), ~pad, pad, 0.01, g0, 0.1, 1, c, e1, e2, d, t,
                  d.copy(), t.copy(), d.copy(), t.copy(), lists, np.empty(g0.shape[0]))  # fmt: skip
    assert np.allclose(c, want / np.linalg.norm(want), atol=1e-15)


def _same_live(a: _Eye, b: _Eye) -> bool:
    """The two eyes' live cells are the same, key by key in slot order: their samples,
    lit, d and t bit for bit."""
    for n in range(a.pad.shape[0]):
        ka, kb = ~a.pad[n], ~b.pad[n]
        for x, y in ((a.pts, b.pts), (a.lit, b.lit), (a.d, b.d), (a.t, b.t)):
            if not np.array_equal(x[n][ka], y[n][kb]):
                return False
    return True


def test_the_first_prunes_candidates_keep_every_cell_it_keeps(monkeypatch):
    """_Eye with ``reach`` (boundary samples only for the cells the first prune may keep,
    _Eye._candidates) then prune gives the same live cells, samples, d and t bit for bit as
    every cell's samples then prune, and drops some cells before their samples: on Algorithm
    1 keys (nside 6, 16, 180) and on every stability class's keys (ties, poles, vertices,
    grazing, extreme scales; nside 16 and 180; the keys limit3d samples), at the set-up's
    reach, 2.5x it and 1e-12 rad."""
    from eyeviz.core import kernels
    from eyeviz.estimators.limit3d import max_lit
    from eyeviz.reference import stability_cases as sc

    # the kernels for calls of every size, as once warm (else a call of few cells takes
    # the reference, a few ulps away)
    monkeypatch.setitem(kernels._STATE, "ready", True)

    keysets = []
    for nside, seed in ((6, 1), (16, 2), (180, 3)):
        d = Domain3D(nside=nside)
        ds = generate3d(8, d, seed=seed)
        keysets.append((d, (ds.indptr_a, ds.indices_a), (ds.indptr_b, ds.indices_b)))
    for name in sorted(sc.CLASSES3D):
        cs = sc.make(name, 4, 7, "spherical")
        x, y, z, g = (np.asarray(v, np.float64).ravel() for v in (cs.x, cs.y, cs.z, cs.g))
        for nside in (180,) if name == "base_vertices" else (16, 180):  # (16: ties, 3 s)
            d = Domain3D(nside=nside)
            la, lb = d.eyes.lit_csr(x, y, z, g)
            na, nb = np.diff(la[0]), np.diff(lb[0])
            # keys limit3d samples (a key past max_lit gets no draws)
            ok = np.flatnonzero((na > 0) & (nb > 0) & (np.maximum(na, nb) <= max_lit(d)))
            if ok.size:
                keysets.append((d, take_rows(*la, ok), take_rows(*lb, ok)))
    dropped = 0
    for d, la, lb in keysets:
        fw = math.sqrt(4 * math.pi / d.npix)
        n = la[0].size - 1
        for eye, lit, cx in ((0, la, -d.h), (1, lb, d.h)):
            for f in (0.25, 0.625, 1e-12 / fw):
                reach = np.full(n, f * fw)
                full = _Eye(d, lit, np.array([cx, 0, 0]), eye)
                full.prune(reach)
                cand = _Eye(d, lit, np.array([cx, 0, 0]), eye, reach)
                dropped += len(full._band[1]) - int((~cand.pad).sum())
                cand.prune(reach)
                assert _same_live(cand, full), (d.nside, eye, f)
                for a, b in zip(cand.lists, full.lists, strict=True):
                    k = a.shape[1] if a.ndim > 1 else None
                    assert np.array_equal(a[:, :k] if k else a, b[:, :k] if k else b)
    assert dropped > 0


@pytest.mark.parametrize("nside,seed", [(16, 31), (180, 32)])
def test_candidates_kernel_gives_the_numpy_verdicts(nside, seed, monkeypatch):
    """_Eye._candidates' verdicts compiled (limit3d_affine.candidates_kernel) and in numpy
    (the sample gap, each key's largest lit L and smallest unlit U by ufunc.at, the
    margins) on real keys' band cells at several reaches: the same, cell by cell."""
    from eyeviz.core import kernels

    monkeypatch.setitem(kernels._STATE, "ready", True)
    fw = math.sqrt(4 * math.pi / (12 * nside**2))
    for e in _eyes(nside, seed):
        cnt = e._band[0]
        rows = np.repeat(np.arange(cnt.size), cnt)
        for f in (0.05, 0.25, 1.0):
            reach = np.full(cnt.size, f * fw) * np.linspace(0.5, 1.5, cnt.size)
            got = e._candidates(e.u0, rows, reach)
            with monkeypatch.context() as mp:
                mp.setenv("EYEVIZ_JIT", "0")
                want = e._candidates(e.u0, rows, reach)
            assert np.array_equal(got, want)
            if f == 0.05:
                assert got.any() and not got.all()


def test_band_cells_kernel_is_the_set_differences(monkeypatch):
    """_band_cells compiled (healpix_match.band_cells_kernel, a merge of sorted rows) and
    in numpy (set differences, a stable sort by key): the same codes, lit flags and rows,
    on random rows that overlap, miss each other, are empty or hold every cell, with some
    keys ``small`` (every lit cell an edge cell)."""
    from eyeviz.core import kernels
    from eyeviz.estimators.limit3d_eye import _band_cells

    monkeypatch.setitem(kernels._STATE, "ready", True)
    rng = np.random.default_rng(21)
    npix = 48

    def rows(n: int, p: float) -> tuple[np.ndarray, np.ndarray]:
        sel = [np.flatnonzero(rng.random(npix) < q) for q in rng.choice([0.0, p, 1.0], n)]
        ptr = np.concatenate([[0], np.cumsum([s.size for s in sel])]).astype(np.int64)
        return ptr, np.concatenate(sel).astype(np.int64)

    for _ in range(40):
        n = int(rng.integers(1, 7))
        key, inner, outer = rows(n, 0.5), rows(n, 0.3), rows(n, 0.7)
        small = rng.random(n) < 0.3
        got = _band_cells(key, inner, outer, small, npix)
        with monkeypatch.context() as mp:
            mp.setenv("EYEVIZ_JIT", "0")
            want = _band_cells(key, inner, outer, small, npix)
        for a, b in zip(got, want, strict=True):
            assert np.array_equal(a, b)


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 2**31), ties=st.booleans())
def test_band_order_kernel_is_the_lexsort(seed, ties):
    """_Eye.band's order (healpix_match.band_order_kernel) against numpy's stable lexsort
    of (where(lit, -near, far), ~lit, key): per key the lit cells by near from the
    largest, then the unlit ones by far from the smallest, ties (and NaN, last) in cell
    order; every array in that order and where each key's unlit cells start."""
    from eyeviz.core.kernels.healpix_match import band_order_kernel

    rng = np.random.default_rng(seed)
    cnt = rng.integers(0, 90, int(rng.integers(1, 6)))  # sorts past insertion sort's size
    bp = np.concatenate([[0], np.cumsum(cnt)]).astype(np.int64)
    t = int(bp[-1])
    lit = rng.random(t) < 0.5
    near, far = rng.random(t), rng.random(t)
    if ties:  # equal bounds, zeros of both signs and a NaN
        near, far = np.round(near, 1), np.round(far, 1)
        far[rng.random(t) < 0.2] = -0.0
        if t:
            near[rng.integers(0, t)] = np.nan
    pix, ring = rng.permutation(t).astype(np.int64), rng.integers(1, 9, t).astype(np.int64)
    verts = rng.normal(size=(t, 4, 3))
    got = band_order_kernel(bp, pix, ring, lit, near, far, verts)
    key = np.repeat(np.arange(cnt.size), cnt)
    order = np.lexsort((np.where(lit, -near, far), ~lit, key))
    want = (pix[order], ring[order], lit[order], near[order], far[order], verts[order],
            bp[:-1] + np.bincount(key[lit], minlength=cnt.size))  # fmt: skip
    for a, b in zip(got, want, strict=True):
        assert np.array_equal(a, b, equal_nan=True)


def _forms(rng, n: int, k: int) -> tuple[np.ndarray, ...]:
    """Packed lit and unlit forms (_Eye._affine's ``lists``) of n keys, k slots each, with
    the adversarial cases: exact duplicates (ties), near-ties at the domination margin,
    one form, none, and equal gradients."""
    out: list[np.ndarray] = []
    for _ in range(2):
        a = rng.uniform(0.1, 0.3, (n, k))
        t = rng.normal(size=(n, k, 2))
        t /= np.linalg.norm(t, axis=2, keepdims=True)
        cnt = np.full(n, k, np.int64)
        a[0, 1], t[0, 1] = a[0, 0], t[0, 0]  # a tie: neither dominates the other
        t[1, :] = t[1, 0]  # equal gradients: the largest (smallest) offset alone decides
        a[1, 1] = a[1, 0]
        cnt[2], cnt[3] = 1, 0
        out += [a, t, cnt]
    return tuple(out)


@pytest.mark.parametrize("seed", [0, 1])
def test_box_lists_kernel_is_the_reference_and_keeps_the_models_values(seed, monkeypatch):
    """_Eye.box_lists, kernel against numpy bit for bit, on random forms with ties and on
    real keys' boxes (nside 16 and 180); and the model (_affine_lists) from the kept
    forms is the whole model's bit for bit at the boxes' corners, edges and inside, and
    just outside by rounding, while dropping forms (a quarter or more kept)."""
    from eyeviz.core import kernels
    from eyeviz.core.kernels.limit3d_affine import _affine_lists, affine_bounds_kernel
    from eyeviz.estimators import limit3d_healpix as lh

    monkeypatch.setitem(kernels._STATE, "ready", True)
    rng = np.random.default_rng(seed)
    cases = []
    e = _eyes(16, seed)[0]
    e.lists = _forms(rng, 6, 9)
    cases.append((e, rng.uniform(0.0, 0.05, (6, 2)) * (np.arange(6) != 4)[:, None]))
    for nside in (16, 180):
        d = Domain3D(nside=nside)
        ds = generate3d(6, d, seed=seed + 5)
        la = take_rows(ds.indptr_a, ds.indices_a, np.arange(6))
        lb = take_rows(ds.indptr_b, ds.indices_b, np.arange(6))
        keys = np.arange(6, dtype=np.uint64)
        st_ = lh.HealpixProposal(d, "single", 64, 8).setup(la, lb, keys, 1.0)
        cases += [(st_["ea"], st_["ext"]), (st_["eb"], st_["ext_b"])]
    kept = total = 0
    for e, ext in cases:
        got = e.box_lists(ext)
        want = e._box_lists_ref(ext)
        for g_, w_ in zip(got, want, strict=True):
            assert np.array_equal(g_, w_)
        kept += int(got[2].sum() + got[5].sum())
        total += int(e.lists[2].sum() + e.lists[5].sum())
        s = np.array([-1.0, -0.5, 0.0, 0.3, 1.0, 1.0 + 2.0**-50])
        sx, sy = np.meshgrid(s, s[::-1], indexing="ij")
        pts = np.stack([sx.ravel(), sy.ravel()], -1)
        pts = np.concatenate([pts, rng.uniform(-1, 1, (40, 2))])[None] * ext[:, None, :]
        lo, hi = np.empty(pts.shape[:2]), np.empty(pts.shape[:2])
        lo2, hi2 = lo.copy(), hi.copy()
        f = (e.a_lit, e.t_lit, e.a_unl, e.t_unl)
        affine_bounds_kernel(*f, e.lists, pts, lo, hi)
        affine_bounds_kernel(*f, got, pts, lo2, hi2)
        assert np.array_equal(lo, lo2) and np.array_equal(hi, hi2)
        assert _affine_lists(*f, got, 0, 0.0, 0.0) == _affine_lists(*f, e.lists, 0, 0.0, 0.0)
    assert kept < 0.5 * total
