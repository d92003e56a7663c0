"""The responses layer's pure parts (eyeviz.model.responses3d): the shades, the owners'
values, and what is computed (every ball's, each once per position: a drag recomputes the
dragged ball's only)."""

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


def test_healpix_cells_for_every_ball_of_any_size() -> None:
    pair = EyePair3D(40.0, 20.0, nside=8)
    # a small ball, one lighting many cells, one holding eye A's centre
    st = _state(pair, [(0.0, 200.0, 0.0, 8.0), (0.0, 60.0, 0.0, 20.0), (-38.0, 0.0, 1.0, 5.0)])
    assert np.diff(st.lit_a[0])[1] > 24  # the old bound: no longer one
    got = r3.lit_responses(st, None, r3.ResponseCache())
    (_, _, va), (_, _, vb) = pair.responses(st.x, st.y, st.z, st.g)
    for eye, want in (("A", va), ("B", vb)):
        assert np.isfinite(got[eye]).all()
        np.testing.assert_allclose(got[eye], want, atol=1e-12)
    assert (got["A"][st.lit_a[0][2] :] == 1.0).all()
    assert "not computed" in r3.response_text(float("nan"), "cell")
    assert r3.response_text(0.4242, "cell") == "response 0.424 (cell)"


def test_a_drag_recomputes_the_dragged_ball_only() -> None:
    """Each frame of a drag (a new position of ball 0) computes ball 0's row anew; ball 1's
    is kept (the same array), also when a state builds its pair anew."""
    pair = EyePair3D(40.0, 20.0, nside=8)
    cache = r3.ResponseCache()
    s0 = _state(pair, [(0.0, 200.0, 0.0, 8.0), (30.0, 300.0, 10.0, 9.0)])
    r3.lit_responses(s0, 0, cache)
    kept = cache.rows[("A", 1)][2]
    pair = EyePair3D(40.0, 20.0, nside=8)
    s1 = _state(pair, [(5.0, 200.0, 0.0, 8.0), (30.0, 300.0, 10.0, 9.0)])  # a drag frame
    got = r3.lit_responses(s1, 0, cache)
    assert cache.rows[("A", 1)][2] is kept and cache.rows[("A", 0)][0][0] == 5.0
    (_, _, va), _ = pair.responses(s1.x, s1.y, s1.z, s1.g)
    np.testing.assert_allclose(got["A"], va, atol=1e-12)
