"""compute_state against EyePair, element by element, and the layers-only rule."""

import numpy as np
import pytest

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
