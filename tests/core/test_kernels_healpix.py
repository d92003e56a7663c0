"""The compiled lit-set kernel against the numpy reference, element by element (issue 31).

Every ball the kernel decides itself (status 0) must give the reference's lit set; the
balls it hands back (status 1) are few and go through the reference in geometry3d.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import eyeviz.core.geometry3d as g3
from eyeviz.core import kernels
from eyeviz.core.kernels.healpix_lit import lit_runs_kernel
from eyeviz.reference import stability_cases as sc

NSIDES = [2, 4, 6, 8, 10, 12, 16, 18, 64, 180]  # nside / 2 odd and even, small and large


def _kernel(n, x, y, z, g, cx):
    sth, zr, unit = g3._ring_tables(n)
    first, nr, shifted, delta, o = g3._ring_info_tables(n)
    return lit_runs_kernel(n, x, y, z, g, cx, sth, zr, unit, first, nr, shifted, delta, o)


def _sets(per, st, ln):
    indptr, idx = g3._runs_to_csr(per, st, ln)
    return [idx[indptr[i] : indptr[i + 1]].tolist() for i in range(per.size)]


def _compare(n, x, y, z, g):
    """(balls the kernel decided, balls compared); asserts equality on every one."""
    decided = 0
    for cx in (-40.0, 40.0):
        status, per, st_, ln, bl = _kernel(n, x, y, z, g, cx)
        want = _sets(*g3._lit_runs_ref(n, x, y, z, g, cx))
        got = _sets(per, st_, ln)
        assert np.all(np.diff(bl) >= 0), "runs not sorted by ball"
        for i in np.flatnonzero(status == 0):
            assert got[i] == want[i], (n, cx, x[i], y[i], z[i], g[i])
        decided += int((status == 0).sum())
        both = _sets(*g3._lit_runs_jit(n, x, y, z, g, cx))
        assert both == want
    return decided


@pytest.mark.slow
@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    name=st.sampled_from(sorted(sc.CLASSES3D)),
    seed=st.integers(0, 2**20),
    nside=st.sampled_from([None] + NSIDES),
)
def test_kernel_equals_the_reference_on_every_tie_class(name, seed, nside):
    cs = sc.make(name, 12, seed, "spherical")
    n = cs.eyes.nside if nside is None else nside
    x, y, z, g = (np.ascontiguousarray(v, dtype=np.float64) for v in (cs.x, cs.y, cs.z, cs.g))
    _compare(n, x, y, z, g)


@pytest.mark.parametrize("n", [16, 64, 180])
def test_kernel_decides_the_paper_regime_itself(n):
    """Nearly every paper-regime ball is decided in the kernel (not handed back), so the
    comparison above is a comparison of the kernel, not of the reference with itself."""
    cs = sc.make("paper", 60, n, "spherical")
    x, y, z, g = (np.ascontiguousarray(v, dtype=np.float64) for v in (cs.x, cs.y, cs.z, cs.g))
    assert _compare(n, x, y, z, g) >= 2 * 60 - 2


@settings(max_examples=40, deadline=None)
@given(
    nside=st.sampled_from(NSIDES),
    p=st.tuples(*[st.floats(-3000, 3000)] * 3),
    q=st.floats(1e-3, 1.5),
)
def test_kernel_equals_the_reference_on_random_balls(nside, p, q):
    r = float(np.linalg.norm(np.subtract(p, (40.0, 0.0, 0.0)))) + 1e-9
    x, y, z, g = (np.array([v], np.float64) for v in (*p, q * r))
    _compare(nside, x, y, z, g)


@pytest.mark.parametrize("n", [2, 4, 6, 18, 64])
def test_kernel_equals_the_reference_on_caps_of_a_cell_about_its_corners(n):
    """Caps of 0.1 to 1.5 cells centred near a cell's vertices and edges (every ring,
    the first and last cells of rings, polar and equatorial): the boundary cells on both
    sides of the centre's cell, whose vertices the ring loop shares between neighbours,
    are the ones decided one by one."""
    from eyeviz.core import healpix

    rng = np.random.default_rng(n)
    npix = 12 * n * n
    first, nr, _ = healpix.ring_info(n, np.arange(1, 4 * n))
    pix = np.concatenate([first, first + nr - 1, rng.integers(0, npix, 60)])
    pts = healpix.boundaries(n, pix, step=4)[:, rng.integers(0, 16, pix.size) % 16]
    u = pts[np.arange(pix.size), np.arange(pix.size)] + rng.normal(0, 1e-3 / n, (pix.size, 3))
    u /= np.linalg.norm(u, axis=1)[:, None]
    alpha = rng.uniform(0.1, 1.5, pix.size) * math.sqrt(4 * math.pi / npix)
    d = rng.uniform(500, 3000, pix.size)
    x, y, z = (np.ascontiguousarray(v) for v in (40.0 + d * u[:, 0], d * u[:, 1], d * u[:, 2]))
    g = d * np.sin(alpha)
    assert _compare(n, x, y, z, g) >= 2 * pix.size - 4


def test_eyeviz_jit_0_runs_the_reference(monkeypatch):
    """EYEVIZ_JIT=0: geometry3d never calls the kernel."""
    import eyeviz.core.kernels.healpix_lit as hl

    monkeypatch.setitem(kernels._STATE, "ready", True)
    monkeypatch.setenv("EYEVIZ_JIT", "0")
    assert not kernels.use()

    def boom(*a):
        raise AssertionError("kernel called with EYEVIZ_JIT=0")

    monkeypatch.setattr(hl, "lit_runs_kernel", boom)
    monkeypatch.setattr(hl, "csr_kernel", boom)
    la, lb = g3.EyePair3D(40.0, 20.0, 16).lit(10.0, 500.0, 20.0, 60.0)
    assert la.size > 10 and lb.size > 10
    monkeypatch.setenv("EYEVIZ_JIT", "1")
    with pytest.raises(AssertionError, match="kernel called"):
        g3.EyePair3D(40.0, 20.0, 16).lit(10.0, 500.0, 20.0, 60.0)


def test_deferred_kernels_wait_for_the_warm_up(monkeypatch):
    """An app defers the kernels until warm: the reference answers meanwhile; a warm-up
    on a background thread makes them ready."""
    monkeypatch.setitem(kernels._STATE, "ready", False)
    monkeypatch.setitem(kernels._STATE, "defer", False)
    assert kernels.use(kernels.COLD_WORK) and not kernels.use(1)  # small calls wait
    thread = kernels.warm_in_background()
    assert thread is not None
    assert not kernels.use(10**6) or kernels._STATE["ready"]  # deferred until warm
    thread.join(120)
    assert kernels.use(1)


def test_the_warm_up_list_names_every_kernel_module_and_refuses_others():
    """scripts/setup.sh warms the modules of KERNELS (the healpix_* ones in one process,
    the others in another): a new kernel module must join the list, and an unknown one
    is named."""
    import pkgutil

    modules = {m.name for m in pkgutil.iter_modules(kernels.__path__)}
    assert sorted(kernels.KERNELS) == sorted(modules)
    with pytest.raises(ValueError, match="no kernel module 'nope'; known: healpix_lit"):
        kernels.warm(("nope",))


def test_lit_csr_through_the_kernel_equals_the_reference(monkeypatch):
    """EyePair3D.lit_csr and lit, kernel (both eyes and the indices in compiled code)
    against EYEVIZ_JIT=0, on a batch mixing ordinary, tiny, grazing and whole-eye balls
    (the last three handed back to the reference and merged), and one-ball calls of
    Python and numpy scalars; and one eye's alone (lit_csr_eye, kernel) the same."""
    rng = np.random.default_rng(4)
    p = rng.uniform(-500, 500, (40, 3))
    g = rng.uniform(1, 300, 40)
    g[::7] = 1e-200  # tiny
    p[3] = (40.0, 0.0, 0.0)  # whole eye B
    g[5] = float(np.linalg.norm(p[5] - (40.0, 0.0, 0.0))) * (1 - 2.0**-30)  # grazing
    eyes = g3.EyePair3D(40.0, 20.0, 18)
    monkeypatch.setitem(kernels._STATE, "ready", True)
    got = eyes.lit_csr(p[:, 0], p[:, 1], p[:, 2], g)
    got += tuple(g3.lit_csr_eye(eyes, e, p[:, 0], p[:, 1], p[:, 2], g) for e in (0, 1))
    ones = [eyes.lit(float(p[i, 0]), p[i, 1], p[i, 2], g[i]) for i in range(40)]
    monkeypatch.setenv("EYEVIZ_JIT", "0")
    want = eyes.lit_csr(p[:, 0], p[:, 1], p[:, 2], g)
    for (a, b), (c, d) in zip(got, want + want, strict=True):
        np.testing.assert_array_equal(a, c)
        np.testing.assert_array_equal(b, d)
    for i, one in enumerate(ones):
        for o, (ptr, idx) in zip(one, want, strict=True):
            np.testing.assert_array_equal(o, idx[ptr[i] : ptr[i + 1]])
    monkeypatch.setenv("EYEVIZ_JIT", "1")
    with pytest.raises(ValueError, match="x has 1 non-finite"):
        eyes.lit(float("nan"), 1.0, 2.0, 3.0)
    with pytest.raises(ValueError, match="g .feature radius. must be > 0"):
        eyes.lit(0.0, 1.0, 2.0, 0)
    with pytest.raises(ValueError, match="would hold about"):
        g3.EyePair3D(40.0, 20.0, 1 << 20).lit(0.0, 100.0, 0.0, 50.0)


@pytest.mark.parametrize("huge_up_to", [0, 1 << 40])
def test_lit_csr_indices_from_either_allocator(monkeypatch, huge_up_to):
    """The CSR indices go into numpy's array (huge pages) or numba's (past
    HUGE_PAGES_UP_TO): the same sets either way."""
    import eyeviz.core.kernels.healpix_lit as hl

    rng = np.random.default_rng(7)
    p = rng.uniform(-800, 800, (30, 3))
    g = rng.uniform(5, 400, 30)
    eyes = g3.EyePair3D(40.0, 20.0, 64)
    monkeypatch.setitem(kernels._STATE, "ready", True)
    monkeypatch.setattr(hl, "HUGE_PAGES_UP_TO", huge_up_to)
    got = eyes.lit_csr(p[:, 0], p[:, 1], p[:, 2], g)
    monkeypatch.setenv("EYEVIZ_JIT", "0")
    want = eyes.lit_csr(p[:, 0], p[:, 1], p[:, 2], g)
    for (a, b), (c, d) in zip(got, want, strict=True):
        np.testing.assert_array_equal(a, c)
        np.testing.assert_array_equal(b, d)


def test_one_ball_estimate_equals_the_arrays():
    """The one-ball path's size estimate (Python floats) is lit_csr's on arrays."""
    for x, y, z, g in [(0.0, 100.0, 5.0, 30.0), (40.0, 0.0, 0.0, 1.0), (1e308, 1e308, 0, 1.0)]:
        est = g3._estimate_one(x, y, z, g, 40.0, 12)
        want = 0.0
        with np.errstate(all="ignore"):
            for cx in (-40.0, 40.0):
                q = np.float64(g) / np.hypot(np.hypot(x - cx, y), z)
                want += (1.0 if q >= 1 else 0.5 * q * q) * 12
        assert est == want
