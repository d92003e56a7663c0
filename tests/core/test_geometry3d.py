"""EyePair3D: contract, the equatorial reduction (ties included), lit sets against a dense
sampling of the cap, the 3D BFV and overlap, and the exact fallback on constructed ties."""

from __future__ import annotations

import math
import re

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from eyeviz.core import healpix as hp
from eyeviz.core.bounds import MAX_M
from eyeviz.core.geometry import EyePair, intervals_to_bitmap
from eyeviz.core.geometry3d import EyePair3D
from eyeviz.reference import stability_cases as sc
from eyeviz.reference.digits80 import reference_interval

EVEN_NSIDE = [2, 4, 6, 8, 16, 180]


# --- the contract -------------------------------------------------------------------------
@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"h": 40, "l": 20, "nside": 7}, "nside must be an even integer"),
        ({"h": 40, "l": 20, "nside": 0}, "nside must be an even integer"),
        ({"h": 40, "l": 20, "nside": 2**21}, "nside must be an even integer"),
        ({"h": 40, "l": 20, "nside": 2.5}, "nside must be"),
        ({"h": 20, "l": 20, "nside": 4}, "h must be > l"),
        ({"h": 40, "l": -1, "nside": 4}, "l (eye radius) must be > 0"),
        ({"h": float("nan"), "l": 20, "nside": 4}, "h must be finite"),
    ],
)
def test_forbidden_parameters_are_refused(kwargs, message):
    with pytest.raises(ValueError, match=re.escape(message)):
        EyePair3D(**kwargs)


def test_attributes_and_shapes():
    e = EyePair3D(40, 20, 6)
    assert (e.npix, e.m, e.centers) == (432, 24, ((-40.0, 0.0, 0.0), (40.0, 0.0, 0.0)))
    assert e.design == {"h": 40.0, "l": 20.0, "nside": 6} and e.dims == 3
    la, lb = e.lit(0.0, 1000.0, 50.0, 200.0)
    assert la.dtype == np.int64 and np.all(np.diff(la) > 0) and lb.size > 0
    wa, wb = e.bitmaps(np.zeros((2, 3)), 1000.0, 0.0, 100.0)
    assert wa.shape == (2, 3, 432) and wa.dtype == bool
    (pa, ia), (pb, ib) = e.lit_csr(np.zeros(3), 1000.0, 0.0, [100.0, 200.0, 300.0])
    assert pa.shape == (4,) and pa[-1] == ia.size and np.all(np.diff(pa) > 0)
    assert np.array_equal(wa[0, 0], np.isin(np.arange(432), ia[pa[0] : pa[1]]))
    with pytest.raises(ValueError, match=r"g \(feature radius\) must be > 0"):
        e.lit_csr([1.0, 2.0], 0.0, 0.0, [1.0, -1.0])
    with pytest.raises(ValueError, match=r"g \(feature radius\) must be > 0: 1 value"):
        e.lit_csr([1.0, 2.0], 500.0, 0.0, [1.0, 0.0])  # a point is not a ball
    with pytest.raises(ValueError, match=r"z has 1 non-finite"):
        e.bitmaps(0.0, 1.0, np.nan, 1.0)
    with pytest.raises(ValueError, match="eye must be 'A' or 'B'"):
        e.facet(0, 1, 0, "C")
    with pytest.raises(ValueError, match="must be a scalar"):
        e.lit([0.0, 1.0], 1.0, 0.0, 1.0)


def test_facet_exact_on_boundaries():
    n = 4
    e = EyePair3D(40, 20, n)
    eq = 2 * n * (n - 1) + 4 * n * n
    # from B: +x is the equator vertex at phi = 0, +y at phi = pi/2, straight up the pole
    got = e.facet([50.0, 40.0, 40.0, 40.0, 30.0], [0.0, 5.0, 0.0, 0.0, 0.0], [0, 0, 3, -3, 0], "B")
    assert got.tolist() == [eq, eq + n, 0, 12 * n * n - 4, eq + 2 * n]
    rng = np.random.default_rng(3)
    p = rng.normal(size=(3, 2000)) * 100
    ref = hp.vec2pix_ring(n, p[0] + 40.0, p[1], p[2])
    assert np.array_equal(e.facet(p[0], p[1], p[2], "A"), ref)


def test_whole_eye_when_the_centre_is_in_the_closed_ball():
    e = EyePair3D(40, 20, 4)
    la, lb = e.lit(43.0, 4.0, 0.0, 5.0)  # |B - c| = 5 = g: on the sphere, closed ball
    assert lb.size == e.npix and la.size < e.npix
    la, lb = e.lit(43.0, 4.0, 0.0, np.nextafter(5.0, 0.0))
    assert lb.size < e.npix


# --- the equatorial reduction (docs/spherical.md) -----------------------------------------
def _equator_bits(e3: EyePair3D, ia, pa, i):
    n = e3.nside
    first = 2 * n * (n - 1) + 4 * n * n
    s = ia[pa[i] : pa[i + 1]]
    k = s[(s >= first) & (s < first + 4 * n)] - first
    bm = np.zeros(4 * n, bool)
    bm[k] = True
    return bm


def _planar_bitmaps(nside, x, y, g):
    m = 4 * nside
    if m <= MAX_M:
        return EyePair(40.0, 20.0, m).bitmaps(x, y, g)
    # beyond EyePair's bound (m = 4 * 2^20): the planar 80-digit reference of Eq. 11
    out = []
    for cx in (-40.0, 40.0):
        lr = np.array([reference_interval(*v, cx, m) for v in zip(x, y, g, strict=True)])
        out.append(intervals_to_bitmap(lr[:, 0], lr[:, 1], m))
    return out[0], out[1]


def _check_reduction(nside, x, y, g):
    e3 = EyePair3D(40.0, 20.0, nside)
    lits = e3.lit_csr(x, y, np.zeros_like(x), g)
    bms = _planar_bitmaps(nside, x, y, g)
    for (pa, ia), wa in zip(lits, bms, strict=True):
        for i in range(x.size):
            got = _equator_bits(e3, ia, pa, i)
            assert np.array_equal(got, wa[i]), (nside, x[i], y[i], g[i])


@settings(max_examples=40, deadline=None)
@given(
    nside=st.sampled_from(EVEN_NSIDE + [12, 2**10]),
    x=st.floats(-3000, 3000),
    y=st.floats(-3000, 3000),
    g=st.floats(1e-2, 800),
)
def test_equatorial_reduction_random(nside, x, y, g):
    _check_reduction(nside, np.array([x]), np.array([y]), np.array([g]))


def _planar_ties(case, nside, count):
    eyes2 = EyePair(40.0, 20.0, 4 * nside)
    maker = sc.resting_on_ground if case == "ground" else sc.touching_vertical
    return maker(count, np.random.default_rng(nside), eyes2)


@pytest.mark.parametrize("case", ["ground", "vertical"])
def test_equatorial_reduction_on_planar_ties(case):
    """Tangents exactly on sector boundaries: direction 0 / pi (resting on y = 0), pi/2
    (touching an eye's vertical line) and 30-degree multiples (nside 6: 12 | 4 nside)."""
    cs = _planar_ties(case, 6, 6)
    _check_reduction(6, cs.x, cs.y, cs.g)


@pytest.mark.slow
@pytest.mark.parametrize("nside", [2, 4, 8, 16, 180])
@pytest.mark.parametrize("case", ["ground", "vertical"])
def test_equatorial_reduction_on_planar_ties_many(nside, case):
    cs = _planar_ties(case, nside, 25)
    _check_reduction(nside, cs.x, cs.y, cs.g)


def test_equatorial_reduction_at_the_largest_nside():
    """nside = 2^20 (m = 4 * 2^20): small balls resting on y = 0, touching an eye's
    vertical line, and random ones; their caps span tens of facets."""
    rng = np.random.default_rng(5)
    g = np.round(10 ** rng.uniform(-4, -3, 6), 6)
    x = np.round(rng.uniform(-300, 300, 6), 2)
    x = np.concatenate([x, [40.0 + 1e-3, -40.0 - 2e-4, 123.25]])
    y = np.concatenate([g, [77.5, 1.0, 250.0]])
    g = np.concatenate([g, [1e-3, 2e-4, 3e-4]])
    _check_reduction(2**20, x, y, g)


def test_a_lit_set_too_large_to_hold_is_refused():
    with pytest.raises(ValueError, match="the lit sets would hold about"):
        EyePair3D(40.0, 20.0, 2**20).lit(0.0, 100.0, 0.0, 50.0)


# --- lit sets against a dense sampling of the closed cap ----------------------------------
def _sampled_cap_cells(n, d, g, rng, k=20000):
    dn = d / np.linalg.norm(d)
    a = math.asin(g / np.linalg.norm(d))
    u = np.concatenate([np.full(k // 2, math.cos(a)), rng.uniform(math.cos(a), 1, k // 2)])
    ph = rng.uniform(0, 2 * math.pi, k)
    t1 = np.cross(dn, [0.0, 0.0, 1.0] if abs(dn[2]) < 0.9 else [1.0, 0.0, 0.0])
    t1 /= np.linalg.norm(t1)
    t2 = np.cross(dn, t1)
    s = np.sqrt(1 - u * u)
    v = u[:, None] * dn + s[:, None] * (np.cos(ph)[:, None] * t1 + np.sin(ph)[:, None] * t2)
    return set(hp.vec2pix_ring(n, v[:, 0], v[:, 1], v[:, 2]).tolist())


@pytest.mark.parametrize("nside", [2, 4, 6, 8])
def test_lit_sets_contain_every_sampled_cell_and_no_far_cell(nside):
    rng = np.random.default_rng(nside)
    e = EyePair3D(40.0, 20.0, nside)
    cen = hp.centers(nside)
    for _ in range(15):
        p = rng.normal(size=3) * rng.uniform(30, 300)
        g = rng.uniform(1, 100)
        lit = set(e.lit(*p, g)[1].tolist())
        d = p - np.array([40.0, 0.0, 0.0])
        if np.linalg.norm(d) <= g:
            assert len(lit) == e.npix
            continue
        assert _sampled_cap_cells(nside, d, g, rng) <= lit
        # no lit cell lies further than the cap radius plus the largest pixel radius
        ang = np.arccos(np.clip(cen[sorted(lit)] @ (d / np.linalg.norm(d)), -1, 1))
        assert ang.max() <= math.asin(g / np.linalg.norm(d)) + 2.2 / nside


# --- the 3D BFV and the overlap -------------------------------------------------------------
def test_slices_z0_match_the_planar_model():
    rng = np.random.default_rng(11)
    e3, e2 = EyePair3D(40.0, 20.0, 8), EyePair(40.0, 20.0, 32)
    x, y = rng.uniform(-3000, 3000, 5000), rng.uniform(-500, 3000, 5000)
    g = 10 ** rng.uniform(-1, 3, 5000)
    z = np.zeros(5000)
    assert np.array_equal(e3.in_bfv(x, y, z, g), e2.in_bfv(x, y, g))
    assert np.array_equal(np.array(e3.overlaps_eye(x, y, z, g)), np.array(e2.overlaps_eye(x, y, g)))
    # the equatorial ring is the planar eye, and other rings only add facets
    v3, v2 = np.array(e3.visible(x, y, z, g)), np.array(e2.visible(x, y, g))
    assert np.all(v3 | ~v2) and (v3 & ~v2).any()


def test_in_bfv_exact_on_the_cone_and_in_front():
    # h = 5, l = 3 (w = 4): the ball at (0, 4, 3) * 10 has b = 50, 4 * 50 - 0 >= g * 5
    e = EyePair3D(5.0, 3.0, 2)
    assert e.in_bfv(0.0, 40.0, 30.0, 40.0)
    assert not e.in_bfv(0.0, 40.0, 30.0, np.nextafter(40.0, 41.0))
    # overhead, outside both cones but not in front of the eyes (y < g)
    assert not e.in_bfv(0.0, 1.0, 1000.0, 2.0)
    assert e.in_bfv(0.0, 2.0, 1000.0, 2.0)
    assert e.overlaps_eye(9.0, 0.0, 3.0, 2.0) == (False, True)  # |(4, 0, 3)| = 5 = g + l


def test_visible_counts_two_facets():
    e = EyePair3D(40.0, 20.0, 16)
    va, vb = e.visible([0.0, 0.0], [1000.0, 1e6], [0.0, 0.0], [100.0, 1.0])
    assert va.tolist() == [True, False] and vb.tolist() == [True, False]


def test_the_edge_curvature_bound_holds():
    """|P''| along every pixel edge (finite differences) stays under exact3d.edge_bound,
    which the fast path and the fallback use (with a factor 2.5) to clear edges."""
    from eyeviz.core.exact3d import edge_bound

    t = np.linspace(0.0, 1.0, 801)
    h = t[1] - t[0]
    worst = 0.0
    for n in (2, 4, 16):
        for face in range(12):
            for fixed_is_y in (True, False):
                for fixed in range(n + 1):
                    for lo in range(n):
                        fix = np.full_like(t, fixed)
                        px, py = (lo + t, fix) if fixed_is_y else (fix, lo + t)
                        p = hp.xyf2vec(n, px, py, np.full(t.shape, face))
                        d2 = np.linalg.norm(p[2:] - 2 * p[1:-1] + p[:-2], axis=1) / h**2
                        bound = edge_bound(n, face, fixed_is_y, float(fixed), float(lo))
                        worst = max(worst, float(d2.max()) / bound)
    assert 0.5 < worst < 1.0


@pytest.mark.parametrize(
    "g", [1e-3, 1e-6, 1e-9, 1e-12, pytest.param(1e-300, marks=pytest.mark.slow)]
)
@pytest.mark.parametrize("nside", [8, 180])
def test_a_tiny_cap_lights_the_cell_of_its_centre(g, nside):
    """A cap far smaller than the float direction's error still lights its own cell (the
    fast path once cleared every edge and lit nothing)."""
    eyes = EyePair3D(40.0, 20.0, nside)
    rng = np.random.default_rng(nside)
    for x, y, z in rng.uniform(-3000, 3000, (4, 3)):
        la, lb = eyes.lit(x, y, z, g)
        for got, cx in ((la, -40.0), (lb, 40.0)):
            centre = int(eyes.facet(x, y, z, "A" if cx < 0 else "B"))
            assert got.tolist() == [centre]


def test_far_tiny_ball_matches_the_reference():
    """Found by `eyeviz report stability` (extreme scales): r ~ 6e14, g ~ 5e5."""
    from eyeviz.reference.healpix_reference import reference_lit

    eyes = EyePair3D(40.0, 20.0, 8)
    ball = (556086480053557.3, 190659441615909.6, -56913132029480.01, 502579.43741302175)
    la, lb = eyes.lit(*ball)
    assert np.array_equal(la, reference_lit(8, *ball, -40.0))
    assert np.array_equal(lb, reference_lit(8, *ball, 40.0))


# --- the fast path's mechanisms -----------------------------------------------------------
@pytest.mark.parametrize("n", [2, 4, 6, 18, 64])
def test_vertex_lon_gives_every_cells_boundary_vertices(n):
    """The N, W, S, E vertices from the rings' (sin theta, z) and the longitudes L * unit
    are healpix.boundaries' vertices (from the face coordinates), for every pixel."""
    p = np.arange(hp.npix(n))
    ring, first, _, _ = hp.pix2ring(n, p)
    ln, un, lw, le, ui, ls, us = hp.vertex_lon(n, ring, p - first)
    got = []
    for k, lon, unit in ((ring - 1, ln, un), (ring, lw, ui), (ring + 1, ls, us), (ring, le, ui)):
        s, z = hp.ring_sz(n, k)
        ph = lon * unit
        got.append(np.stack([s * np.cos(ph), s * np.sin(ph), z], -1))
    want = hp.boundaries(n, p)
    np.testing.assert_allclose(np.stack(got, 1), want, rtol=0, atol=1e-14)
    # W and E lie on the cell's ring, at its edges: E of cell j is W of cell j + 1
    assert np.all(le[:-1][np.diff(ring) == 0] == lw[1:][np.diff(ring) == 0])


def test_edge_lower_bounds_every_function_of_bounded_curvature():
    """_edge_lower(fa, fb, M) <= min f on [0, 1] for f with |f''| <= M (the worst case is
    the parabola of curvature -M through the end values), and it is >= min - M / 8."""
    from eyeviz.core.healpix_fast import _edge_lower

    rng = np.random.default_rng(5)
    fa, fb = rng.uniform(0, 1, 4000), rng.uniform(0, 1, 4000)
    M = rng.uniform(1e-3, 3, 4000)
    t = np.linspace(0, 1, 2001)[:, None]
    lower = _edge_lower(fa, fb, M)
    for curv in (-1.0, -0.5, 0.0, 1.0):
        f = (1 - t) * fa + t * fb + curv * M * t * (1 - t) / 2
        assert np.all(lower <= f.min(axis=0) + 1e-12)
    worst = ((1 - t) * fa + t * fb - M * t * (1 - t) / 2).min(axis=0)
    assert np.all(lower >= worst - 1e-6)  # tight: the parabola attains it
    assert np.all(lower >= np.minimum(fa, fb) - M / 8 - 1e-15)


def test_lit_sets_do_not_depend_on_the_block_size(monkeypatch):
    """Blocks of balls are cut by _block(nside); the lit sets are the same for any cut."""
    import eyeviz.core.geometry3d as g3

    rng = np.random.default_rng(9)
    e = EyePair3D(40.0, 20.0, 16)
    x, y, z = rng.uniform(-3000, 3000, 700), rng.uniform(100, 3000, 700), rng.normal(0, 800, 700)
    g = rng.uniform(1, 400, 700)
    want = e.lit_csr(x, y, z, g)
    monkeypatch.setattr(g3, "_block", lambda n: 97)
    got = e.lit_csr(x, y, z, g)
    for (pa, ia), (pb, ib) in zip(want, got, strict=True):
        np.testing.assert_array_equal(pa, pb)
        np.testing.assert_array_equal(ia, ib)
