"""The spherical limit's exact check without lit sets (issue 31 item 3):
limit3d_exact._match_healpix (the lit-set kernel's rings compared with the key's as they
come, kernels.healpix_match.match_kernel) gives the same accept / reject as building both
eyes' lit sets with ``lit_csr`` and comparing them with ``same_rows``, draw by draw: on
every tie class of the spherical stability cases (poles, equator ties, vertices, grazing,
extreme scales) with keys that are the ball's own lit sets and near misses of them, and on
the HEALPix proposal's own candidate draws at nside 16 and 180."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import eyeviz.core.geometry3d as g3
from eyeviz.core import kernels
from eyeviz.core.domain import Domain3D
from eyeviz.dataset.algorithm1_3d import generate3d
from eyeviz.estimators import limit3d_exact, limit3d_healpix
from eyeviz.estimators.base import take_rows
from eyeviz.estimators.limit3d_eye import _Eye
from eyeviz.reference import stability_cases as sc

pytest.importorskip("eyeviz.core.kernels.healpix_match")

NSIDES = [2, 4, 6, 8, 10, 12, 16, 18, 64, 180]


def _csr(rows: list[np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    ptr = np.zeros(len(rows) + 1, np.int64)
    ptr[1:] = np.cumsum([r.size for r in rows])
    ind = np.concatenate(rows).astype(np.int64) if rows else np.zeros(0, np.int64)
    return ptr, ind


def _variants(s: np.ndarray, other: np.ndarray, npix: int) -> list[np.ndarray]:
    """A lit set and its near misses: itself, without its first / last / a middle cell,
    with the cell after its last or before its first, with a far cell, another ball's."""
    out = [s, s[1:], s[:-1], np.delete(s, s.size // 2) if s.size > 2 else s[:0], other]
    if s.size and s[-1] + 1 < npix:
        out.append(np.append(s, s[-1] + 1))
    if s.size and s[0] > 0:
        out.append(np.insert(s, 0, s[0] - 1))
    far = npix - 1 if not s.size or s[-1] < npix - 1 else 0
    out.append(np.union1d(s, [far]))
    return out


def _check(eyes, x, y, z, g) -> tuple[int, int]:
    """Both checks on every ball against every variant of its lit sets (eye A's and B's
    varied apart); returns (draws, matches)."""
    x, y, z, g = (np.ascontiguousarray(v, dtype=np.float64).ravel() for v in (x, y, z, g))
    (pa, ia), (pb, ib) = eyes.lit_csr(x, y, z, g)
    sa = [ia[pa[i] : pa[i + 1]] for i in range(x.size)]
    sb = [ib[pb[i] : pb[i + 1]] for i in range(x.size)]
    keys_a, keys_b, ball = [], [], []
    for i in range(x.size):
        j = (i + 1) % x.size
        va = _variants(sa[i], sa[j], eyes.npix)
        vb = _variants(sb[i], sb[j], eyes.npix)
        for ka, kb in [(a, sb[i]) for a in va] + [(sa[i], b) for b in vb[1:]]:
            keys_a.append(ka)
            keys_b.append(kb)
            ball.append(i)
    lit_a, lit_b = _csr(keys_a), _csr(keys_b)
    row = np.arange(len(ball), dtype=np.int64)
    b = np.array(ball)
    got = limit3d_exact._match_healpix(eyes, x[b], y[b], z[b], g[b], row, lit_a, lit_b)
    # lit_csr of the balls, compared with each key (same_rows: the check as it was)
    qa, ja = _csr([sa[i] for i in ball])
    qb, jb = _csr([sb[i] for i in ball])
    want = limit3d_exact.same_rows(qa, ja, lit_a, row) & limit3d_exact.same_rows(qb, jb, lit_b, row)
    bad = np.flatnonzero(got != want)
    assert not bad.size, [(x[b][i], y[b][i], z[b][i], g[b][i], want[i]) for i in bad[:3]]
    return row.size, int(want.sum())


# Every class on every run, two hypothesis draws of seed and nside each: an equator-ties
# example costs over a second (its balls go to the exact path), so the examples are
# counted per class, and the suite's time does not depend on which classes were drawn
@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(sc.CLASSES3D))
@settings(max_examples=2, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(seed=st.integers(0, 2**20), nside=st.sampled_from([None, *NSIDES]))
def test_match_equals_lit_sets_on_every_tie_class(name, seed, nside):
    cs = sc.make(name, 5, seed, "spherical")
    eyes = cs.eyes if nside is None else g3.EyePair3D(cs.eyes.h, cs.eyes.l, nside)
    n, hits = _check(eyes, cs.x, cs.y, cs.z, cs.g)
    assert 0 < hits < n


def test_match_decides_the_paper_regime_in_the_kernel():
    """The kernel itself answers nearly every paper-regime draw (2: the reference), so the
    comparison above compares the kernel, not lit_csr with itself."""
    from eyeviz.core.kernels.healpix_match import match_kernel, vertex_cache

    eyes = g3.EyePair3D(40.0, 20.0, 180)
    cs = sc.make("paper", 40, 3, "spherical")
    x, y, z, g = (np.ascontiguousarray(v, dtype=np.float64) for v in (cs.x, cs.y, cs.z, cs.g))
    pa, ia = eyes.lit_csr(x, y, z, g)[0]
    out = np.empty(x.size, np.int64)
    tabs = (*g3._ring_tables(180), *g3._ring_info_tables(180))
    match_kernel(180, x, y, z, g, -40.0, np.arange(x.size), pa, ia, *tabs, vertex_cache(), out)
    assert (out == 1).sum() >= x.size - 1
    out2 = np.empty(x.size, np.int64)
    match_kernel(180, x, y, z, g, -40.0, (np.arange(x.size) + 1) % x.size, pa, ia, *tabs,
                 vertex_cache(0), out2)  # fmt: skip
    assert (out2 == 0).sum() >= x.size - 1


def test_balls_holding_the_eye_and_on_its_sphere():
    """Whole-eye balls (every facet lit: the kernel's own branch) and balls whose sphere
    passes through the eye centre or graze it (handed to the reference)."""
    eyes = g3.EyePair3D(40.0, 20.0, 8)
    x = np.array([-40.0, -39.0, 40.0, 0.0, -40.0, 10.0])
    y = np.array([0.0, 1.0, 2.0, 500.0, 300.0, 60.0])
    z = np.array([0.0, 0.5, -1.0, 3.0, 0.0, 2.0])
    g = np.array([5.0, 3.0, 4.0, float(np.hypot(40.0, np.hypot(500.0, 3.0))), 300.0, 1e-9])
    _check(eyes, x, y, z, g)


@pytest.mark.parametrize("nside", [16, 180])
def test_match_equals_lit_sets_on_the_proposal_draws(nside, monkeypatch):
    """The proposal's candidate draws of a few keys (before the prefilter, so many are
    near misses): the same accept / reject draw by draw, by the rings alone and by the
    band cells first, and some of each; the proposal's draws the reference's (to 1e-9)."""
    d = Domain3D(nside=nside)
    ds = generate3d(4, d, seed=nside)
    rows = np.arange(4)
    la = take_rows(ds.indptr_a, ds.indices_a, rows)
    lb = take_rows(ds.indptr_b, ds.indices_b, rows)
    seen = []
    real = limit3d_healpix.band_pass

    def spy(eyes, p, g, row, bands):
        seen.append((p.copy(), g.copy(), row.copy(), bands))
        return real(eyes, p, g, row, bands)

    monkeypatch.setattr(limit3d_healpix, "band_pass", spy)
    prop = limit3d_healpix.HealpixProposal(d, "single", 512, 8)
    keys = np.arange(4, dtype=np.uint64) * np.uint64(7919)
    got_w = prop.sample(prop.setup(la, lb, keys, 1.0), keys, 0)["w"]
    assert seen
    p, g, row, bands = seen[0]
    assert kernels.use(row.size)
    (pa, ia), (pb, ib) = d.eyes.lit_csr(p[:, 0], p[:, 1], p[:, 2], g)
    want = limit3d_exact.same_rows(pa, ia, la, row) & limit3d_exact.same_rows(pb, ib, lb, row)
    x, y, z = p[:, 0], p[:, 1], p[:, 2]
    for b in (None, bands):  # the rings alone, and the band cells first
        assert np.array_equal(
            limit3d_exact._match_healpix(d.eyes, x, y, z, g, row, la, lb, b), want
        )
    sure = real(d.eyes, p, g, row, bands)
    assert np.array_equal(sure[sure != 2] == 1, want[sure != 2])
    assert 5 <= want.sum() < want.size - 5
    monkeypatch.setenv("EYEVIZ_JIT", "0")
    # the set-up's kernels are the reference's to a few ulps (kernels.limit3d_affine): the
    # same accepted draws, their weights to 1e-9
    want_w = prop.sample(prop.setup(la, lb, keys, 1.0), keys, 0)["w"]
    assert np.array_equal(got_w > 0, want_w > 0)
    assert np.allclose(got_w, want_w, rtol=1e-9, atol=0)


def test_exact_hits_take_the_lit_sets_with_eyeviz_jit_0(monkeypatch):
    """EYEVIZ_JIT=0: exact_hits builds the lit sets (the reference), never the kernel."""
    import eyeviz.core.kernels.healpix_match as hl

    def boom(*a):
        raise AssertionError("match kernel called with EYEVIZ_JIT=0")

    monkeypatch.setattr(hl, "match_kernel", boom)
    monkeypatch.setenv("EYEVIZ_JIT", "0")
    d = Domain3D(nside=8)
    ds = generate3d(3, d, seed=1)
    la, lb = (ds.indptr_a, ds.indices_a), (ds.indptr_b, ds.indices_b)
    p = np.stack([ds.x, ds.y, ds.z], axis=1)
    hit = limit3d_exact.exact_hits(d, p, ds.g, np.arange(3), la, lb)
    assert hit.all()


def _bands_check(d: Domain3D, x, y, z, g, keys_of, lit_a, lit_b) -> tuple[int, int, int]:
    """_match_healpix with the keys' band cells (limit3d_eye._Eye.band) against
    lit_csr + same_rows on balls (x, y, z, g) of the keys ``keys_of``; returns (balls,
    matches, balls the band check decided in eye A)."""
    from eyeviz.core.kernels.healpix_match import edge_match_kernel

    ea = _Eye(d, lit_a, np.array([-d.h, 0.0, 0.0]), 0)
    eb = _Eye(d, lit_b, np.array([d.h, 0.0, 0.0]), 1)
    bands = (ea.band(), eb.band())
    x, y, z, g = (np.ascontiguousarray(v, dtype=np.float64) for v in (x, y, z, g))
    row = np.asarray(keys_of, np.int64)
    got = limit3d_exact._match_healpix(d.eyes, x, y, z, g, row, lit_a, lit_b, bands)
    (pa, ia), (pb, ib) = d.eyes.lit_csr(x, y, z, g)
    want = limit3d_exact.same_rows(pa, ia, lit_a, row) & limit3d_exact.same_rows(pb, ib, lit_b, row)
    bad = np.flatnonzero(got != want)
    assert not bad.size, [(x[i], y[i], z[i], g[i], want[i]) for i in bad[:3]]
    out = np.full(x.size, 2, np.int64)
    tabs = (*g3._ring_tables(d.nside), *g3._ring_info_tables(d.nside))
    edge_match_kernel(d.nside, x, y, z, g, -d.h, row, *bands[0], *tabs[:4], tabs[5], out)
    return x.size, int(want.sum()), int((out != 2).sum())


# Every class on every run, as above (grazing balls at nside 180 cost seconds)
@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(sc.CLASSES3D))
@settings(max_examples=2, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    seed=st.integers(0, 2**20),
    nside=st.sampled_from([2, 4, 6, 8, 16, 18, 64, 180]),
    scale=st.sampled_from([0.0, 1e-13, 1e-9, 1e-6, 1e-4, 1e-2]),
)
def test_band_check_equals_lit_sets_on_every_tie_class(name, seed, nside, scale):
    """Keys: the lit sets of stability-case balls (ties, poles, vertices, grazing, extreme
    scales); balls: those balls (ties included) and copies moved by ``scale`` of their
    distance and radius, some matching and some not."""
    cs = sc.make(name, 4, seed, "spherical")
    d = Domain3D(nside=nside)
    x, y, z, g = (np.asarray(v, np.float64).ravel() for v in (cs.x, cs.y, cs.z, cs.g))
    (pa, ia), (pb, ib) = d.eyes.lit_csr(x, y, z, g)
    rng = np.random.default_rng(seed)
    k = np.repeat(np.arange(x.size), 6)
    r = np.hypot(np.hypot(x, y), z)[k]
    jit = rng.normal(size=(4, k.size)) * scale
    jit[:, ::6] = 0.0  # the ball itself
    bx, by, bz = x[k] + jit[0] * r, y[k] + jit[1] * r, z[k] + jit[2] * r
    bg = g[k] * (1.0 + jit[3])
    _bands_check(d, bx, by, bz, bg, k, (pa, ia), (pb, ib))


@pytest.mark.parametrize("nside", [16, 64, 180])
def test_band_check_decides_the_paper_regime(nside):
    """Keys of Algorithm 1 balls and balls about them: the band check itself decides
    most (so the comparison is of the band check, not of match_kernel), and some match."""
    d = Domain3D(nside=nside)
    ds = generate3d(12, d, seed=nside + 1)
    la, lb = (ds.indptr_a, ds.indices_a), (ds.indptr_b, ds.indices_b)
    rng = np.random.default_rng(nside)
    k = np.repeat(np.arange(12), 40)
    fw = np.sqrt(4 * np.pi / d.npix)
    step = rng.choice([0.0, 1e-4, 1e-3, 1e-2], k.size)[:, None] * fw * ds.r[k][:, None]
    p = np.stack([ds.x, ds.y, ds.z], axis=1)[k] + rng.normal(size=(k.size, 3)) * step
    gg = ds.g[k] * (1.0 + rng.normal(size=k.size) * step[:, 0] / ds.r[k])
    n, hits, decided = _bands_check(d, p[:, 0], p[:, 1], p[:, 2], gg, k, la, lb)
    assert hits >= n // 4 and hits < n
    assert decided >= 0.8 * n


def test_band_check_needs_the_draw_between_the_inner_and_outer_caps():
    """With the inner and the outer cap both the key's own ball (so no band cells), a draw
    is decided by the band check only if its cap lies between them: a larger or a smaller
    ball about the same centre is left open (2), never taken for the key."""
    from eyeviz.core.kernels.healpix_match import edge_match_kernel

    n, h = 16, 40.0
    tabs = (*g3._ring_tables(n), *g3._ring_info_tables(n))
    x, y, z, g0 = 30.0, 900.0, 50.0, 60.0
    v = np.array([x + h, y, z])
    dist = float(np.linalg.norm(v))
    u = (v / dist)[None, :]
    a = np.array([np.arcsin(g0 / dist)])
    empty = np.zeros(0, np.int64)
    band = (u, a, a.copy(), u.copy(), np.zeros(2, np.int64), np.zeros(1, np.int64), empty, empty,
            np.zeros(0, np.bool_), np.zeros(0), np.zeros(0), np.zeros((0, 4, 3)))  # fmt: skip
    g = np.array([g0 * 0.8, g0, g0 * 1.2])
    out = np.full(3, -1, np.int64)
    ones = np.ones(3)
    edge_match_kernel(n, x * ones, y * ones, z * ones, g, -h, np.zeros(3, np.int64), *band,
                      *tabs[:4], tabs[5], out)  # fmt: skip
    assert out.tolist() == [2, 2, 2]
    # the caps 1e-6 rad inside and outside the ball's: the ball itself is then decided
    band = (u, a - 1e-6, a + 1e-6, *band[3:])
    edge_match_kernel(n, x * ones, y * ones, z * ones, g, -h, np.zeros(3, np.int64), *band,
                      *tabs[:4], tabs[5], out)  # fmt: skip
    assert out.tolist() == [2, 1, 2]


def test_band_check_on_one_cell_keys_and_keys_with_a_hole():
    """Keys the band check must not be fooled by: a ball whose cap lies inside one cell
    (the key's centre is then in a band cell, lit however far its edges are), and a key
    with a hole in its middle (the inner cap lights a cell the key lacks: no band, those
    draws go to the rings)."""
    d = Domain3D(nside=16)
    fw = np.sqrt(4 * np.pi / d.npix)
    # cell centres seen from eye A at 600 units; caps of 0.15 facet widths
    from eyeviz.core import healpix

    v = np.asarray(healpix.centers(16, np.arange(0, d.npix, 97)), np.float64)
    v = v[v[:, 1] > 0.5][:4]
    p = np.array([-d.h, 0.0, 0.0]) + 600.0 * v
    g = 600.0 * np.sin(0.15 * fw) * np.ones(len(p))
    (pa, ia), (pb, ib) = d.eyes.lit_csr(p[:, 0], p[:, 1], p[:, 2], g)
    assert (np.diff(pa) == 1).any()  # some keys are one cell in eye A
    k = np.repeat(np.arange(len(p)), 5)
    jit = np.random.default_rng(3).normal(size=(k.size, 3)) * 1e-4 * fw * 600.0
    jit[::5] = 0.0
    q = p[k] + jit
    n, hits, _ = _bands_check(d, q[:, 0], q[:, 1], q[:, 2], g[k], k, (pa, ia), (pb, ib))
    assert hits >= n // 2
    # a hole: Algorithm 1 keys without a cell from the middle of eye A's set (nside 64:
    # keys large enough to have an inner cap)
    d = Domain3D(nside=64)
    ds = generate3d(6, d, seed=5)
    la, lb = (ds.indptr_a, ds.indices_a), (ds.indptr_b, ds.indices_b)
    rows = [np.delete(ds.indices_a[la[0][i] : la[0][i + 1]], (la[0][i + 1] - la[0][i]) // 2)
            for i in range(6)]  # fmt: skip
    holed = _csr(rows)
    x, y, z = ds.x, ds.y, ds.z
    n, hits, _ = _bands_check(d, x, y, z, ds.g, np.arange(6), holed, lb)
    assert hits == 0


def test_the_band_checks_cap_is_the_lit_set_kernels_ball():
    """healpix_match._cap (the band check's share of healpix_lit._ball) gives _ball's
    kind (3, a ball holding the eye centre, as 1), centre, alpha, pad, s2, ds2 and ed bit
    for bit, and _cap_pix its centre pixel, on every tie class's balls at several scales,
    at ordinary, grazing, tiny and enclosing radii."""
    from eyeviz.core.kernels.healpix_lit import _ball
    from eyeviz.core.kernels.healpix_match import _cap, _cap_pix

    kinds = set()
    for name in sorted(sc.CLASSES3D):
        cs = sc.make(name, 3, 5, "spherical")
        x, y, z, g = (np.asarray(v, np.float64).ravel() for v in (cs.x, cs.y, cs.z, cs.g))
        for i in range(x.size):
            r = float(np.sqrt(x[i] ** 2 + y[i] ** 2 + z[i] ** 2))
            for gg in (g[i], g[i] * (1 + 1e-15), r * 1e-12, r - 40.0, r + 40.0, r * 0.3):
                for n, cx in ((180, -40.0), (16, 40.0), (3, -40.0)):
                    want = _ball(n, x[i], y[i], z[i], gg, cx)
                    got = _cap(x[i], y[i], z[i], gg, cx)
                    kinds.add(want[0])
                    assert got[0] == (0 if want[0] == 0 else 1)
                    if want[0] != 0:
                        continue
                    par = want[1]
                    assert got[1] == par[0] and got[2:4] == want[4:6]
                    assert got[4:7] == (par[10], par[11], par[12])
                    assert _cap_pix(n, *got[7:]) == par[13]
    assert kinds == {0, 1, 3}


@pytest.mark.parametrize("n", [4, 5, 180])
def test_band_bounds_from_stored_vertices_are_the_cells_own_bit_for_bit(n):
    """band_bounds_kernel's vertices (_cell_vertices, written on a first call, read on a
    second: _Eye._candidates then band) are healpix_boundary._cell_fs's to the bit (the
    chord^2 of each of the four, _chord2), and a second call about other centres from
    the stored vertices gives the bounds a fresh call gives, bit for bit: on every cell
    of the polar caps' first and last rings, the rings beside the polar / equatorial
    seams and the equator (nside even and odd), about the poles, a cell's vertex (a tie
    of two cells), a point 1e-15 off it and random centres."""
    from eyeviz.core import healpix
    from eyeviz.core.kernels.healpix_boundary import _cell_fs
    from eyeviz.core.kernels.healpix_match import (
        _cell_vertices,
        _chord2,
        _polar,
        band_bounds_kernel,
    )

    sth, zr, unit = g3._ring_tables(n)
    first, _, shifted = g3._ring_info_tables(n)[:3]
    rings = sorted({i for i in (1, 2, n - 1, n, n + 1, 2 * n, 3 * n - 1, 3 * n, 3 * n + 1,
                                4 * n - 2, 4 * n - 1) if 1 <= i <= 4 * n - 1})  # fmt: skip
    pix = np.concatenate([np.arange(first[i], first[i + 1])[:: max(1, n // 8)] for i in rings])
    ring = np.concatenate([np.full(np.arange(first[i], first[i + 1])[:: max(1, n // 8)].size, i)
                           for i in rings]).astype(np.int64)  # fmt: skip
    vtx = healpix.boundaries(n, pix[3:4], 1)[0, 0]
    mids = healpix.boundaries(n, pix[[3, -2]], 2)[:, 1::2].reshape(-1, 3)  # edges' midpoints
    dense = healpix.boundaries(n, pix, 32)  # (T, 128, 3): the closures' distances, nearly
    rng = np.random.default_rng(n)
    rnd = rng.normal(size=(3, 3))
    cs = np.array([[0, 0, 1.0], [0, 0, -1.0], vtx, vtx + 1e-15, *rnd, *mids])
    cs /= np.linalg.norm(cs, axis=1, keepdims=True)
    none = (np.empty(0, np.int64), np.empty((0, 3)))
    key = np.zeros(pix.size, np.int64)
    verts = np.empty((pix.size, 4, 3))
    near0, far0 = np.empty(pix.size), np.empty(pix.size)
    band_bounds_kernel(n, pix, ring, key, cs[6:7], sth, zr, unit, first, shifted, verts, False,
                       near0, far0)  # fmt: skip
    for c in cs:
        for k in range(pix.size):
            i = ring[k]
            want = _cell_fs(n, i, pix[k] - first[i], shifted[i], c, sth, zr, unit, none)
            assert tuple(_chord2(verts, k, q, c) for q in range(4)) == want[:4]
            assert _cell_vertices(n, i, pix[k] - first[i], shifted[i], sth, zr, unit,
                                  np.empty((1, 4, 3)), 0) == want[4] == _polar(n, i)  # fmt: skip
        got = [np.empty(pix.size) for _ in range(4)]
        band_bounds_kernel(n, pix, ring, key, c[None], sth, zr, unit, first, shifted,
                           np.empty((pix.size, 4, 3)), False, got[0], got[1])  # fmt: skip
        band_bounds_kernel(n, pix, ring, key, c[None], sth, zr, unit, first, shifted, verts,
                           True, got[2], got[3])  # fmt: skip
        assert np.array_equal(got[0], got[2]) and np.array_equal(got[1], got[3])
        # bounds: far below the closure's distance (its boundary's, densely sampled, is
        # at most 1e-4 fw above it), near above it
        ang = np.arccos(np.clip(dense @ c, -1, 1)).min(axis=1)
        fw = np.sqrt(np.pi / 3) / n
        assert (got[1] <= ang + 1e-12).all() and (got[0] >= ang - 1e-4 * fw).all()
