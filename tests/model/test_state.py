"""compute_state against EyePair, element by element, and the layers-only rule."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from eyeviz.core.geometry import EyePair
from eyeviz.model.scene import Eyes, Feature, Scene
from eyeviz.model.state import compute_state, owners


def _scene(m=720, layers=("eyes", "bitmaps", "readout")):
    fs = [
        Feature("a", 0.0, 1500.0, 50.0),
        Feature("b", -1400.0, 3800.0, 250.0),
        Feature("c", 10.0, 1510.0, 60.0),  # overlaps a's ommatidia: c (later) wins
        Feature("d", -40.0, 5.0, 1.0),  # on eye A: A sees it with every ommatidium
        Feature("e", 5000.0, -10.0, 3.0),  # behind the BFV
    ]
    return Scene(Eyes(40.0, 20.0, m), fs, list(layers))


@pytest.mark.parametrize("m", [16, 720, 36000])
def test_state_matches_geometry(m):
    s = _scene(m)
    st = compute_state(s)
    pair = EyePair(40.0, 20.0, m)
    x, y, g = st.x, st.y, st.g
    for got, want in zip((st.LA, st.RA, st.LB, st.RB), pair.intervals(x, y, g), strict=True):
        np.testing.assert_array_equal(got, want)
    np.testing.assert_array_equal(st.in_bfv, pair.in_bfv(x, y, g))
    va, vb = pair.visible(x, y, g)
    np.testing.assert_array_equal(st.vis_a, va)
    np.testing.assert_array_equal(st.vis_b, vb)
    oa, ob = pair.overlaps_eye(x, y, g)
    np.testing.assert_array_equal(st.overlap_a, oa)
    np.testing.assert_array_equal(st.overlap_b, ob)
    np.testing.assert_allclose(st.r, np.hypot(x, y))
    np.testing.assert_allclose(st.rB, np.hypot(x - 40.0, y))
    wa, wb = pair.bitmaps(x, y, g)
    for i in range(st.n):
        ba, bb = st.bitmaps(i)
        np.testing.assert_array_equal(ba, wa[i])
        np.testing.assert_array_equal(bb, wb[i])
        np.testing.assert_array_equal(st.bitmaps(i, m // 2)[0], wa[i][: m // 2])
    for owner, bits in ((st.owner_a, wa), (st.owner_b, wb)):
        lit_by_any = bits.any(axis=0)
        np.testing.assert_array_equal(owner >= 0, lit_by_any)
        for k in np.flatnonzero(lit_by_any):
            assert owner[k] == np.flatnonzero(bits[:, k]).max()


def test_owner_wraps_around_zero():
    o = owners(np.array([6]), np.array([9]), 8)
    np.testing.assert_array_equal(o, [0, 0, -1, -1, -1, -1, 0, 0])


def test_only_needed_fields_are_computed():
    st = compute_state(_scene(layers=("bfv",)))
    assert st.LA is None and st.owner_a is None and st.in_bfv is None
    st = compute_state(_scene(layers=("bitmaps",)))
    assert st.LA is not None and st.owner_a is None and st.r is None


def test_a_state_without_the_arrays_says_so():
    """No layer needed the intervals or the BFV: one ValueError naming what is missing
    (before: a TypeError on None from deep inside)."""
    sc = Scene(Eyes(40.0, 20.0, 72), [Feature("a", 10.0, 500.0, 20.0)], ["features"])
    st = compute_state(sc)
    with pytest.raises(ValueError, match="no intervals"):
        st.intervals()
    with pytest.raises(ValueError, match="no intervals"):
        st.bitmaps(0)
    with pytest.raises(ValueError, match="no BFV or visibility"):
        st.in_domain()
    sc.layers.append("readout")
    st = compute_state(sc)
    LA, RA, LB, RB = st.intervals()
    assert st.in_domain().tolist() == [bool(st.in_bfv[0] and RA[0] > LA[0] and RB[0] > LB[0])]


def test_no_features():
    st = compute_state(Scene(features=[]))
    assert st.n == 0
    assert (st.owner_a == -1).all() and st.owner_a.shape == (720,)


def test_sectors_alone_get_the_eye_distances_they_draw_with():
    """The sectors layer reaches rE + 1.6 g: its state must carry rA/rB even when no other
    layer asks for them (a scene showing only sectors crashed the frame, issue 13 fuzz)."""
    from eyeviz.model import scene as S
    from eyeviz.model.frame import build_frame
    from eyeviz.model.state import compute_state

    sc = S.loads('[[features]]\nname = "a"\nx = 0.0\ny = 1500.0\ng = 50.0\n', "t.toml")
    sc.layers = ["sectors"]
    st = compute_state(sc)
    assert st.rA is not None and st.rB is not None
    fr = build_frame(sc, st, rect=(-100.0, 100.0, 0.0, 2000.0))
    assert len(fr.sectors) == 2


# --- update_state: a drag frame's rows against a whole new state -------------------------
def _assert_same_state(got, want):
    import dataclasses

    for f in dataclasses.fields(want):
        a, b = getattr(want, f.name), getattr(got, f.name)
        if isinstance(a, np.ndarray):
            assert isinstance(b, np.ndarray) and a.dtype == b.dtype, f.name
            np.testing.assert_array_equal(b, a, err_msg=f.name)
        else:
            assert a == b, f.name


ALL_LAYERS = ("eyes", "bitmaps", "readout", "features")


@pytest.mark.parametrize("name", ["paper", "ground", "vertical", "grazing", "extreme", "huge_m"])
def test_update_state_equals_compute_state_on_stability_cases(name):
    """Every moved row (ties, grazing, extreme scales included) gives the state that a
    whole vectorised pass gives, field by field and bit for bit."""
    from eyeviz.model.state import update_state
    from eyeviz.reference import stability_cases as sc

    cs = sc.make(name, 120, seed=4)
    eyes = Eyes(cs.eyes.h, cs.eyes.l, cs.eyes.m)
    fs = [Feature(f"f{i}", float(cs.x[i]), float(cs.y[i]), float(cs.g[i])) for i in range(6)]
    scene = Scene(eyes, fs, list(ALL_LAYERS))
    st = compute_state(scene)
    for j in range(6, cs.x.size):
        i = j % 6
        fs[i].x, fs[i].y, fs[i].g = float(cs.x[j]), float(cs.y[j]), float(cs.g[j])
        st = update_state(st, scene, {i})
        _assert_same_state(st, compute_state(scene))


def test_update_state_follows_a_drag_and_keeps_the_old_state():
    from eyeviz.model.state import update_state

    s = _scene(720, ALL_LAYERS)
    st0 = compute_state(s)
    before = st0.LA.copy()
    s.features[0].x, s.features[0].y = 2000.0, 40.0  # out of the BFV, a different interval
    st1 = update_state(st0, s, [0])
    _assert_same_state(st1, compute_state(s))
    np.testing.assert_array_equal(st0.LA, before)  # the old state is not written into
    assert st1.LA[0] != before[0]
    assert st1.owner_a is not st0.owner_a
    s.features[0].x += 1e-6  # the same lit cells: the owners are the same arrays
    st2 = update_state(st1, s, [0])
    _assert_same_state(st2, compute_state(s))
    assert st2.owner_a is st1.owner_a and st2.owner_b is st1.owner_b


def test_update_state_takes_the_whole_pass_when_it_must():
    from eyeviz.model.state import update_state

    s = _scene(720, ALL_LAYERS)
    st = compute_state(s)
    s.features.append(Feature("z", 0.0, 900.0, 9.0))  # another count
    _assert_same_state(update_state(st, s, [0]), compute_state(s))
    s2 = _scene(720, ("bfv",))  # other layers: other fields
    _assert_same_state(update_state(st, s2, [0]), compute_state(s2))
    s.features[0].g = -1.0  # refused with the core's own message
    with pytest.raises(ValueError, match="g \\(feature radius\\) must be > 0"):
        update_state(compute_state(_scene(720, ALL_LAYERS)), s, [0])


@settings(max_examples=150, deadline=None)
@given(
    st.integers(0, 4),
    st.floats(-1e5, 1e5),
    st.floats(-1e5, 1e5),
    st.floats(1e-2, 3e3),
    st.sampled_from([16, 720, 36000]),
)
def test_update_state_equals_compute_state_anywhere(i, x, y, g, m):
    from eyeviz.model.state import update_state

    s = _scene(m, ALL_LAYERS + ("labels",))
    st0 = compute_state(s)
    f = s.features[i]
    f.x, f.y, f.g = x, y, g
    _assert_same_state(update_state(st0, s, {i}), compute_state(s))


def test_update_state_with_several_moved_rows_reads_each_rows_own_feature():
    """Issue 20 item 7, mutant 2: several rows moved at once (a drag frame where the
    player moved another feature too) each read their own feature, in any order given."""
    from eyeviz.model.state import update_state

    s = _scene(720, ALL_LAYERS)
    st0 = compute_state(s)
    moves = {3: (-300.0, 2500.0, 80.0), 0: (900.0, 1200.0, 30.0), 2: (50.0, 4000.0, 400.0)}
    for i, (x, y, g) in moves.items():
        f = s.features[i]
        f.x, f.y, f.g = x, y, g
    for rows in ([3, 0, 2], {0, 2, 3}, (2, 3, 0, 3)):
        st = update_state(st0, s, rows)
        _assert_same_state(st, compute_state(s))
        assert [st.x[i] for i in sorted(moves)] == [moves[i][0] for i in sorted(moves)]


@settings(max_examples=60, deadline=None)
@given(
    st.lists(
        st.tuples(st.integers(0, 4), st.floats(-1e4, 1e4), st.floats(-1e4, 1e4), st.floats(1, 2e3)),
        min_size=2,
        max_size=5,
    ),
    st.sampled_from([16, 720]),
)
def test_update_state_equals_compute_state_for_several_rows(moves, m):
    from eyeviz.model.state import update_state

    s = _scene(m, ALL_LAYERS)
    st0 = compute_state(s)
    for i, x, y, g in moves:
        f = s.features[i]
        f.x, f.y, f.g = x, y, g
    _assert_same_state(update_state(st0, s, [i for i, *_ in moves]), compute_state(s))
