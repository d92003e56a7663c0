"""The spherical scene's state against EyePair3D called directly (docs/spherical.md)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from eyeviz import EyevizError
from eyeviz.core.geometry3d import EyePair3D
from eyeviz.model.scene import Eyes, Feature, Scene, load
from eyeviz.model.state3d import compute_state3d

SCENES = Path(__file__).resolve().parents[2] / "assets" / "scenes"


@pytest.mark.parametrize("name", ["sphere_paper", "sphere_teaching", "sphere_equator"])
def test_state_matches_the_model(name):
    sc = load(SCENES / f"{name}.toml")
    st = compute_state3d(sc)
    e = EyePair3D(sc.eyes.h, sc.eyes.l, sc.eyes.nside)
    assert st.pair == e and st.n == len(sc.features)
    for i, f in enumerate(sc.features):
        la, lb = e.lit(f.x, f.y, f.z, f.g)
        np.testing.assert_array_equal(st.lit(i, "A"), la)
        np.testing.assert_array_equal(st.lit(i, "B"), lb)
        assert st.facets_a[i] == la.size and st.facets_b[i] == lb.size
        va, vb = e.visible(f.x, f.y, f.z, f.g)
        assert (st.vis_a[i], st.vis_b[i]) == (bool(va), bool(vb))
        assert st.in_bfv[i] == bool(e.in_bfv(f.x, f.y, f.z, f.g))
        oa, ob = e.overlaps_eye(f.x, f.y, f.z, f.g)
        assert (st.overlap_a[i], st.overlap_b[i]) == (bool(oa), bool(ob))
        assert st.r[i] == pytest.approx(math.sqrt(f.x**2 + f.y**2 + f.z**2))
        assert math.sin(st.elevation[i]) * st.r[i] == pytest.approx(f.z, abs=1e-9)
        assert 0.0 <= st.azimuth[i] < 2 * math.pi
        if f.x == 0.0 and f.y > 0:
            assert st.azimuth[i] == pytest.approx(math.pi / 2)  # forward is 90 degrees


def test_known_directions():
    sc = Scene(
        Eyes(40.0, 20.0, nside=8),
        [
            Feature("up", 0.0, 100.0, 1.0, "#000000", 100.0),
            Feature("left", -200.0, 0.0, 1.0, "#000000", 0.0),
            Feature("down behind", 0.0, -50.0, 1.0, "#000000", -50.0),
        ],
        layers=["readout"],
    )
    st = compute_state3d(sc)
    np.testing.assert_allclose(np.degrees(st.elevation), [45.0, 0.0, -45.0], atol=1e-12)
    np.testing.assert_allclose(np.degrees(st.azimuth), [90.0, 180.0, 270.0], atol=1e-12)
    assert st.in_bfv.tolist() == [True, False, False]


def test_only_what_the_layers_need():
    sc = load(SCENES / "sphere_teaching.toml")
    sc.layers = ["features"]
    st = compute_state3d(sc)
    assert st.lit_a is None and st.in_bfv is None and st.overlap_a is None
    with pytest.raises(EyevizError, match="not computed"):
        st.lit(0, "A")
    sc.layers = ["bfv"]
    st = compute_state3d(sc)
    assert st.in_bfv is not None and st.lit_a is None and st.overlap_a is None
    sc.layers = ["bitmaps"]
    st = compute_state3d(sc)
    assert st.lit_a is not None and st.in_bfv is None


def test_no_features_and_refusals():
    st = compute_state3d(Scene(Eyes(40.0, 20.0, nside=4), []))
    assert st.n == 0 and st.facets_a.size == 0
    with pytest.raises(EyevizError, match="spherical"):
        compute_state3d(Scene(Eyes(40.0, 20.0, 720), []))
    huge = Scene(Eyes(40.0, 20.0, nside=1 << 20), [Feature("f", 0.0, 100.0, 90.0)])
    with pytest.raises(EyevizError) as ei:
        compute_state3d(huge)
    assert "\n" not in str(ei.value) and "nside = 1048576" in str(ei.value)
    with pytest.raises(EyevizError, match="eye must be"):
        compute_state3d(Scene(Eyes(40.0, 20.0, nside=4), [Feature("f", 0, 90, 5)])).lit(0, "C")
