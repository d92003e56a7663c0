"""The responses layer's pure parts (eyeviz.model.responses3d): the shades, the owners'
values, and the bounds on what is computed (HEALPix: the selected ball's, at most
MAX_CELLS cells an eye)."""

from __future__ import annotations

import numpy as np

from eyeviz.core.geometry3d import EyePair3D
from eyeviz.model import responses3d as r3
from eyeviz.model.state3d import SceneState3D


def test_shades_follow_the_values_and_a_lit_facet_never_reads_unlit() -> None:
    v = np.array([0.0, 1e-9, 0.25, 0.5, 1.0, np.nan])
    k = r3.shade_levels(v)
    assert k[0] == 0 and k[1] >= 1 and k[-2] == k[-1] == r3.LEVELS - 1
    assert (np.diff(k[:-1]) >= 0).all() and k[2] < k[3] < k[4]
    ball, unlit = np.array([[200, 0, 0]], np.uint8), np.array([225, 225, 225])
    out = r3.shade(np.repeat(ball, v.size, axis=0), unlit, v)
    assert out.dtype == np.uint8 and (out[0] == unlit).all() and (out[-1] == ball[0]).all()
    assert out[2, 1] > out[3, 1] > out[4, 1]  # greener (greyer) for a smaller value
    idx, pal = r3.shaded_owners(np.array([0, 0]), v[[2, 4]], ball / 255.0, unlit / 255.0)
    np.testing.assert_allclose(pal[idx] * 255, out[[2, 4]], atol=0.51)


def test_owner_values_take_the_last_ball() -> None:
    csr = (np.array([0, 2, 4]), np.array([3, 5, 5, 7]))
    vals = np.array([0.1, 0.2, 0.3, 0.4])
    np.testing.assert_array_equal(r3.owner_values(csr, vals), [0.1, 0.3, 0.4])


def _state(pair, balls) -> SceneState3D:
    x, y, z, g = (np.array(c, float) for c in zip(*balls, strict=True))
    st = SceneState3D(pair, x, y, z, g, r=x, azimuth=x, elevation=x)
    st.lit_a, st.lit_b = pair.lit_csr(x, y, z, g)
    return st


def test_healpix_cells_only_for_the_selected_ball_within_the_cap() -> None:
    pair = EyePair3D(40.0, 20.0, nside=8)
    st = _state(pair, [(0.0, 200.0, 0.0, 8.0), (30.0, 300.0, 10.0, 9.0)])
    small = [(int(np.diff(c[0])[i]) for c in (st.lit_a, st.lit_b)) for i in range(2)]
    assert all(0 < n <= r3.MAX_CELLS for s in small for n in s)
    got = r3.lit_responses(st, 1, r3.ResponseCache())
    (_, _, va), (_, _, vb) = pair.responses(st.x, st.y, st.z, st.g)
    for eye, want, csr in (("A", va, st.lit_a), ("B", vb, st.lit_b)):
        lo, hi = csr[0][1], csr[0][2]
        assert np.isnan(got[eye][:lo]).all()  # ball 0: not selected
        np.testing.assert_allclose(got[eye][lo:hi], want[lo:hi], atol=1e-12)
    big = _state(pair, [(0.0, 60.0, 0.0, 20.0)])
    assert np.diff(big.lit_a[0])[0] > r3.MAX_CELLS
    assert np.isnan(r3.lit_responses(big, 0, r3.ResponseCache())["A"]).all()
    assert "not computed" in r3.response_text(float("nan"), "cell")
    assert r3.response_text(0.4242, "cell") == "response 0.424 (cell)"


def test_healpix_cells_wait_for_the_ball_to_stand_still() -> None:
    """A drag (a new position in each state) computes no cell; the release's state at the
    same position does; the painter and the dock asking in one state agree."""
    pair = EyePair3D(40.0, 20.0, nside=8)
    cache = r3.ResponseCache()
    s0 = _state(pair, [(0.0, 200.0, 0.0, 8.0)])
    assert np.isfinite(r3.lit_responses(s0, 0, cache)["A"]).all()  # new: at rest
    pair = EyePair3D(40.0, 20.0, nside=8)  # a state may build its pair anew
    s1 = _state(pair, [(5.0, 200.0, 0.0, 8.0)])  # a drag frame
    assert np.isnan(r3.lit_responses(s1, 0, cache)["A"]).all()
    assert np.isnan(r3.lit_responses(s1, 0, cache)["B"]).all()  # the same frame, again
    s2 = _state(pair, [(5.0, 200.0, 0.0, 8.0)])  # the release: same place, a new state
    assert np.isfinite(r3.lit_responses(s2, 0, cache)["A"]).all()
