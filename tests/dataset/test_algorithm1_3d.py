"""Algorithm 1 in 3D: every row in the field and visible to both eyes with exactly the
geometry's lit sets, the ranges and densities of single and multi-pass, same seed same
bytes, and refusals of impossible parameters."""

from __future__ import annotations

import math

import numpy as np
import pytest

from eyeviz import EyevizError
from eyeviz.core.domain import Domain3D
from eyeviz.dataset import algorithm1_3d as A
from eyeviz.dataset import sparse3d
from eyeviz.dataset.records import spherical_to_xyz

DOM = Domain3D(h=30, l=10, nside=8, r_min=100, r_max=400, g_max=60, el_max=0.4)


@pytest.fixture(scope="module", params=["single", "multi"])
def made(request):
    return request.param, A.generate3d(300, DOM, mode=request.param, seed=7)


def test_every_row_is_in_the_field_visible_to_both_with_the_geometrys_lit_sets(made):
    _, ds = made
    eyes = DOM.eyes
    x, y, z, g = ds.x, ds.y, ds.z, ds.g
    assert len(ds) == 300
    assert eyes.in_bfv(x, y, z, g).all()
    vis_a, vis_b = eyes.visible(x, y, z, g)
    assert vis_a.all() and vis_b.all()
    for i in range(len(ds)):
        la, lb = eyes.lit(float(x[i]), float(y[i]), float(z[i]), float(g[i]))
        got_a, got_b = ds.lit(i)
        assert np.array_equal(got_a, la) and np.array_equal(got_b, lb), i
        assert got_a.size >= 2 and got_b.size >= 2
    # the centre the lit sets were computed at is the row's (r, azimuth, elevation)
    want = spherical_to_xyz(ds.r, ds.azimuth, ds.elevation)
    for have, w in zip((x, y, z), want, strict=True):
        assert np.allclose(have, w, rtol=0, atol=1e-12 * DOM.r_max)


def test_rows_keep_the_steps_ranges(made):
    _, ds = made
    s = math.sin(DOM.gamma / 2)
    assert ((ds.r >= DOM.r_min) & (ds.r <= DOM.r_max)).all()
    assert (np.abs(ds.elevation) <= DOM.el_max).all()
    assert ((ds.azimuth > 0) & (ds.azimuth < math.pi)).all()
    assert ((ds.g >= ds.r * s * (1 - 1e-12)) & (ds.g <= DOM.g_max) & (ds.g <= ds.r)).all()
    assert ds.indices_a.dtype == np.int32 and ds.indptr_a.dtype == np.int64
    lens = np.diff(ds.indptr_a)
    assert lens.max() <= A.max_lit(DOM)  # the chunk bound's estimate is an upper bound


def test_same_seed_same_rows_and_bytes_other_seed_other_rows(tmp_path):
    a = A.generate3d(120, DOM, seed=3)
    b = A.generate3d(120, DOM, seed=3)
    c = A.generate3d(120, DOM, seed=4)
    for k in ("r", "azimuth", "elevation", "g", "indices_a", "indptr_b"):
        assert np.array_equal(getattr(a, k), getattr(b, k))
    assert not np.array_equal(a.r, c.r)
    for name in ("x.npz", "y.npz"):
        sparse3d.write3d(tmp_path / name, 120, DOM, mode="multi", seed=3)
    assert (tmp_path / "x.npz").read_bytes() == (tmp_path / "y.npz").read_bytes()
    back = sparse3d.load3d(tmp_path / "x.npz")
    m = A.generate3d(120, DOM, mode="multi", seed=3)
    for k in ("r", "g", "x", "indices_b", "indptr_a"):
        assert np.array_equal(getattr(back, k), getattr(m, k))
    assert back.params == {"mode": "multi", "seed": 3, "segments": None}


def test_multi_pass_r_histogram_is_the_volume_plan():
    p = A.make_params3d(DOM, "multi", seed=1)
    n = 600
    edges, counts = A.segment_plan3d(n, p)
    assert counts.sum() == n and len(edges) == 61  # segments of length 5 over [100, 400]
    vol = edges[1:] ** 3 - edges[:-1] ** 3
    assert np.all(np.abs(counts - n * vol / vol.sum()) < 1)
    ds = A.generate3d(n, DOM, mode="multi", seed=1)
    got, _ = np.histogram(ds.r, [100, 200, 300, 400])
    want = [counts[(edges[:-1] >= a) & (edges[:-1] < b)].sum() for a, b in ((100, 200),
            (200, 300), (300, 400))]  # fmt: skip
    assert got.tolist() == [int(w) for w in want]


def test_elevation_uniform_in_single_and_uniform_over_the_fields_solid_angle_in_multi():
    """Small balls (g/r <= 0.01) in a tall band: single-pass elevations are uniform;
    multi-pass centres are uniform over the field's solid angle, so the elevation has
    density cos(el) times the field's azimuth width at el, pi - 2 acos(min(1, cos psi /
    cos el)) (the width widens above |el| = psi)."""
    dom = Domain3D(h=30, l=10, nside=128, r_min=1000, r_max=4000, g_max=10, el_max=1.2)
    single = A.generate3d(1500, dom, mode="single", seed=2).elevation
    multi = A.generate3d(1500, dom, mode="multi", seed=2).elevation
    share = float(np.mean(np.abs(single) > 0.8))
    assert abs(share - 1 / 3) < 0.04, share
    el = np.linspace(0, 1.2, 4001)
    dens = np.cos(el) * (math.pi - 2 * np.arccos(np.minimum(1, math.cos(dom.psi) / np.cos(el))))
    want = float(np.sum(dens[el > 0.8]) / np.sum(dens))
    share = float(np.mean(np.abs(multi) > 0.8))
    assert abs(share - want) < 0.04, (share, want)
    assert abs(want - 1 / 3) > 2 * 0.04  # the two modes differ measurably here


def test_chunks_are_bounded_by_the_lit_budget():
    for dom in (Domain3D(), DOM, Domain3D(nside=2048), Domain3D(r_min=41, nside=64)):
        rows = A.chunk_rows(dom)
        assert 1 <= rows <= A.CHUNK3D
        assert rows == 1 or rows * A.max_lit(dom) <= A.LIT_BUDGET
    assert A.max_lit(Domain3D(r_min=41, nside=64)) == 12 * 64**2  # r_min - h <= g_max


@pytest.mark.parametrize(
    "kw, message",
    [
        (dict(mode="triple"), "mode must be one of 'single', 'multi', got 'triple'"),
        (dict(seed=-1), "seed must be an integer >= 0, got -1"),
        (dict(segments=0), "segments must be an integer >= 1"),
        (dict(domain=Domain3D(nside=8, g_max=1.0)), "no feature can be visible"),
        (dict(domain=Domain3D(h=30, l=29.9, nside=2)), "no visible feature fits"),
        (dict(domain="paper"), "domain must be a Domain3D, got str"),
    ],
)
def test_bad_parameters_refused_in_one_line(kw, message):
    with pytest.raises(EyevizError) as info:
        A.make_params3d(**kw)
    assert str(info.value).startswith(message) and "\n" not in str(info.value)


def test_bad_n_refused():
    for n in (0, -3, 1.5, 10**12):
        with pytest.raises(EyevizError, match="n must be an integer"):
            A.generate3d(n, DOM)


def test_interrupted_generation_leaves_no_file(tmp_path):
    def stop(k):
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        sparse3d.write3d(tmp_path / "d.npz", 50, DOM, progress=stop)
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize(
    "dom", [DOM, Domain3D(nside=16), Domain3D(nside=64, el_max=1.0)], ids=["small", "16", "64"]
)
def test_the_free_space_estimate_covers_the_spools_and_the_file(tmp_path, dom):
    out = tmp_path / "d.npz"
    sparse3d.write3d(out, 300, dom, seed=1)
    need = 2 * out.stat().st_size  # spools and zip side by side
    assert need <= sparse3d.estimated_bytes3d(300, dom) <= 4 * need


@pytest.mark.parametrize("mode", ["single", "multi"])
def test_r_and_g_are_drawn_from_independent_uniforms(mode):
    """Joint statistics, not marginals (issue 37): each row's r, as the uniform it was drawn
    from (its position in its segment: linear in single pass, by volume in multi), and its
    g, as the uniform of step 10 (its position in [r sin(gamma/2), g_max]), are
    uncorrelated. Drawn from one uniform they correlate fully."""
    p = A.make_params3d(DOM, mode, seed=5)
    ds = A.generate3d(1500, DOM, mode=mode, seed=5)
    if mode == "single":
        u_r = (ds.r - DOM.r_min) / (DOM.r_max - DOM.r_min)
    else:
        edges, _ = A.segment_plan3d(1500, p)
        k = np.clip(np.searchsorted(edges, ds.r, side="right") - 1, 0, len(edges) - 2)
        lo, hi = edges[k], edges[k + 1]
        u_r = (ds.r**3 - lo**3) / (hi**3 - lo**3)
    g_min = ds.r * math.sin(DOM.gamma / 2)
    u_g = (ds.g - g_min) / (DOM.g_max - g_min)
    assert abs(np.corrcoef(u_r, u_g)[0, 1]) < 0.15
    assert abs(np.corrcoef(u_r, np.cos(ds.azimuth))[0, 1]) < 0.15


def test_sight_clear_is_the_segments_distance_from_the_other_eye():
    """_sight_clear against a brute-force distance: 4,001 points along each segment from
    the eye centre to the ball centre; cases within 1e-3 of the radius are left out."""
    rng = np.random.default_rng(11)
    x, y, z = rng.uniform(-80, 80, 400), rng.uniform(-15, 40, 400), rng.uniform(-15, 15, 400)
    t = np.linspace(0, 1, 4001)[:, None]
    for from_x, other_x in ((-30.0, 30.0), (30.0, -30.0)):
        px, py, pz = from_x + t * (x - from_x), t * y, t * z
        dist = np.sqrt(((px - other_x) ** 2 + py**2 + pz**2).min(axis=0))
        got = A._sight_clear(x, y, z, from_x, other_x, 10.0)
        sure = np.abs(dist - 10.0) > 1e-3
        assert 20 < (~got[sure]).sum() < sure.sum() - 20  # both answers occur
        assert np.array_equal(got[sure], dist[sure] > 10.0)


def test_both_eyes_field_reaches_outside_the_wedge_and_measured_rows_are_about_the_origin(
    toy_pair,
):
    """HEALPix eyes' both-eyes field is not the wedge (some of its rows lie outside it);
    a measured pair's rows give (r, azimuth, elevation) about the domain's origin."""
    ds = A.generate3d(60, DOM, seed=5, field="both-eyes")
    assert (~DOM.eyes.in_bfv(ds.x, ds.y, ds.z, ds.g)).sum() >= 5
    dom = Domain3D.for_eyes(toy_pair)
    assert abs(dom.origin[1]) > 0.1  # the toy's lens centroids lie in front of x = 0
    ds = A.generate3d(20, dom, seed=5)
    want = spherical_to_xyz(ds.r, ds.azimuth, ds.elevation)
    for have, w, o in zip((ds.x, ds.y, ds.z), want, dom.origin, strict=True):
        assert np.allclose(have, w + o, rtol=0, atol=1e-12 * dom.r_max)
    assert toy_pair.in_bfv(ds.x, ds.y, ds.z, ds.g).all()


def test_a_rare_field_is_filled_the_generator_gives_up_only_after_many_draws():
    """Step 9 keeps about 1 r in 1,000 here: the last slots wait hundreds of rounds of a
    few draws each. The generator stops only after _MAX_IDLE_DRAWS idle draws *and*
    _MAX_IDLE_ROUNDS idle rounds, so the rows come."""
    s = math.sin(math.pi / 32)  # gamma / 2 at nside 8
    dom = Domain3D(h=30, l=10, nside=8, r_min=100, r_max=500, g_max=100 * s * 1.004, el_max=0.4)
    ds = A.generate3d(3, dom, seed=2)
    assert len(ds) == 3 and (ds.r <= 100.4 * (1 + 1e-9)).all()


def test_a_design_exactly_at_gamma_half_plus_psi_equal_to_pi_half_is_refused():
    """l = h cos(gamma / 2) puts gamma/2 + psi at pi/2 to the last bit (nside 2, h = 1):
    no ball fits between the cones (the boundary counts as refused)."""
    l_ = 0.9238795325112867
    assert math.pi / 8 + math.asin(l_) == math.pi / 2
    dom = Domain3D(h=1.0, l=l_, nside=2, r_min=100, r_max=400, g_max=60, el_max=0.4)
    with pytest.raises(EyevizError, match="gamma/2 \\+ psi >= pi/2"):
        A.generate3d(1, dom, seed=1)
