"""The Frame against the geometry, computed here from first principles (never with the
helpers the Frame itself uses): tangent directions, sector rays, runs, readout, wedge."""

import math

import numpy as np
import pytest

from eyeviz.core.geometry import EyePair
from eyeviz.model import scene as scene_mod
from eyeviz.model.frame import build_frame, clip_wedge
from eyeviz.model.palette import (
    ESTIMATOR_COLORS,
    FALLBACK_ESTIMATOR,
    FEATURE_COLORS,
    MIN_DELTA_E,
    delta_e,
    estimator_colors,
)
from eyeviz.resources import scenes_dir

H, L = 40.0, 20.0


def _scene(m=720, layers=("eyes", "bfv", "features", "tangents", "sectors", "readout")):
    return scene_mod.Scene(
        eyes=scene_mod.Eyes(H, L, m),
        features=[
            scene_mod.Feature("a", 120.0, 60.0, 20.0, "#D55E00"),
            scene_mod.Feature("b", -300.0, 900.0, 45.0, "#0072B2"),
            scene_mod.Feature("c", 35.0, 3000.0, 400.0, "#009E73"),
        ],
        layers=list(layers),
    )


def test_tangents_from_first_principles():
    sc = _scene()
    fr = build_frame(sc)
    centres = {"A": (-H, 0.0), "B": (H, 0.0)}
    seen = set()
    for t in fr.tangents:
        f = sc.features[t.feature]
        ex, ey = centres[t.eye]
        d = math.hypot(f.x - ex, f.y - ey)
        want = math.asin(f.g / d)
        assert t.alpha == pytest.approx(want, rel=1e-12)
        centre_dir = math.atan2(f.y - ey, f.x - ex)
        for px, py in t.ends:
            # each end is on the circle and the ray from E is perpendicular to the radius
            assert math.hypot(px - f.x, py - f.y) == pytest.approx(f.g, rel=1e-9)
            dot = (px - ex) * (px - f.x) + (py - ey) * (py - f.y)
            assert abs(dot) <= 1e-9 * d * d
            ang = math.atan2(py - ey, px - ex)
            off = abs(math.remainder(ang - centre_dir, 2 * math.pi))
            assert off == pytest.approx(want, rel=1e-9)
        seen.add((t.feature, t.eye))
    assert seen == {(i, e) for i in range(3) for e in "AB"}


def test_no_tangent_from_an_eye_inside_a_disc():
    sc = _scene()
    sc.features = [scene_mod.Feature("cover", -H, 5.0, 30.0)]
    fr = build_frame(sc)
    assert {t.eye for t in fr.tangents} == {"B"}


def _intervals(sc, i):
    f = sc.features[i]
    pair = EyePair(H, L, sc.eyes.m)
    LA, RA, LB, RB = pair.intervals(np.array([f.x]), np.array([f.y]), np.array([f.g]))
    return {"A": (int(LA[0]), int(RA[0])), "B": (int(LB[0]), int(RB[0]))}


def test_sector_rays_at_k_gamma_bound_the_lit_interval():
    sc = _scene(m=720)
    fr = build_frame(sc)
    gamma = 2 * math.pi / 720
    got = {(s.feature, s.eye): s for s in fr.sectors}
    for i in range(3):
        for eye, (lo, hi) in _intervals(sc, i).items():
            s = got[(i, eye)]
            assert (s.L, s.R) == (lo, hi)
            if hi - lo < 24:
                assert s.rays == list(range(lo, hi + 2))
            else:
                assert s.rays == [lo, hi + 1]
            # the first and last rays bound the lit cells: the feature's centre direction
            # lies between them
            ex = -H if eye == "A" else H
            f = sc.features[i]
            c = math.atan2(f.y, f.x - ex) % (2 * math.pi)
            a0, a1 = s.rays[0] * gamma, s.rays[-1] * gamma
            assert a0 - 1e-12 <= c <= a1 + 1e-12 or a0 <= c + 2 * math.pi <= a1


def test_runs_equal_the_intervals():
    sc = _scene(m=720)
    fr = build_frame(sc)
    m = 720
    for eye in fr.eyes:
        want = np.zeros(m, int)
        for i in range(3):
            lo, hi = _intervals(sc, i)[eye.name]
            if hi > lo:
                for k in range(lo, hi + 1):
                    want[k % m] = 1 + i  # three distinct colours
        starts, stops, cidx = eye.runs
        got = np.zeros(m, int)
        for s, e, c in zip(starts, stops, cidx, strict=True):
            assert e > s
            got[s:e] = c
        assert (got == want).all()
        # maximal: neighbouring runs differ
        assert (cidx[1:] != cidx[:-1]).all()
        assert starts[0] == 0 and stops[-1] == m and (starts[1:] == stops[:-1]).all()


def test_readout_is_distance_from_each_centre():
    sc = _scene()
    fr = build_frame(sc)
    for i, f in enumerate(sc.features):
        assert fr.r[i] == pytest.approx(math.hypot(f.x, f.y))
        assert fr.rA[i] == pytest.approx(math.hypot(f.x + H, f.y))
        assert fr.rB[i] == pytest.approx(math.hypot(f.x - H, f.y))
        assert math.degrees(fr.phiA[i]) == pytest.approx(
            math.degrees(math.atan2(f.y, f.x + H)) % 360
        )


def test_bfv_wedge_covers_a_far_view():
    """Issue 12 item 5: at x = y = 1e7 the wedge must still cover the feature."""
    sc = _scene(layers=("bfv", "features", "readout"))
    sc.features = [scene_mod.Feature("far", 1e7, 1e7, 5e4)]
    sc.view = scene_mod.View((1e7, 1e7), 4e5)
    fr = build_frame(sc)
    assert fr.in_bfv[0]
    from matplotlib.path import Path

    assert Path(fr.bfv.polygon).contains_point((1e7, 1e7))
    x0, x1, y0, y1 = fr.rect
    # the wedge's vertices are on the view's border or inside it
    assert (fr.bfv.polygon[:, 0] >= x0 - 1e-6 * 1e7).all()
    assert (fr.bfv.polygon[:, 1] <= y1 + 1e-6 * 1e7).all()


def test_clip_wedge_membership_matches_angles():
    psi = math.asin(L / H)
    rect = (-500.0, 700.0, -100.0, 900.0)
    poly = clip_wedge(psi, rect)
    from matplotlib.path import Path

    path = Path(poly)
    rng = np.random.default_rng(1)
    pts = rng.uniform((-500, -100), (700, 900), size=(2000, 2))
    ang = np.arctan2(pts[:, 1], pts[:, 0])
    inside = (ang > psi + 1e-3) & (ang < math.pi - psi - 1e-3)
    outside = (ang < psi - 1e-3) | (ang > math.pi - psi + 1e-3)
    got = path.contains_points(pts)
    assert got[inside].all() and not got[outside].any()


def test_only_needed_layers_are_computed():
    sc = _scene(layers=("features",))
    fr = build_frame(sc)
    assert fr.bfv is None and not fr.tangents and not fr.sectors and not fr.eyes
    assert not fr.predictions and not fr.ambiguity and fr.trajectory is None


def test_predictions_errors_from_the_truth():
    sc = _scene(layers=("features", "predictions", "readout"))
    sc.estimators = ["analytic"]
    fr0 = build_frame(sc, predictions={"analytic": (np.zeros(3), np.zeros(3))})
    r_hat = fr0.r * 1.1
    phi_hat = fr0.phi + math.radians(2.0)
    fr = build_frame(sc, predictions={"analytic": (r_hat, phi_hat)})
    p = fr.predictions["analytic"]
    assert p.dr_pct == pytest.approx(np.full(3, 10.0))
    assert p.dphi_deg == pytest.approx(np.full(3, 2.0))
    assert p.x_hat == pytest.approx(r_hat * np.cos(phi_hat))


def test_ambiguity_and_trajectory_in_the_frame():
    sc = scene_mod.load(scenes_dir() / "default.toml")
    sc.layers = ["features", "ambiguity", "trajectory"]
    sc.trajectory = scene_mod.Trajectory("horizontal", 3000.0, 50.0)
    fr = build_frame(sc)
    assert set(fr.ambiguity) == {0, 1, 2}
    for i, reg in fr.ambiguity.items():
        lo, hi = reg["r_range"]
        assert lo <= fr.r[i] * (1 + 1e-9) and fr.r[i] <= hi * (1 + 1e-9)
    t = fr.trajectory
    assert t.n > 10 and np.allclose(t.y, 3000.0)


def test_each_layers_part_depends_on_its_inputs_only():
    """A vertical trajectory ends at the view's top, with or without the ambiguity layer
    (before the layer table, the ambiguity code widened the box the trajectory then read)."""
    sc = scene_mod.load(scenes_dir() / "default.toml")
    sc.trajectory = scene_mod.Trajectory("vertical", 1000.0, 50.0)
    rect = (-500.0, 500.0, 0.0, 7000.0)
    sc.layers = ["features", "trajectory"]
    alone = build_frame(sc, rect=rect).trajectory
    sc.layers = ["features", "ambiguity", "trajectory"]
    both = build_frame(sc, rect=rect).trajectory
    assert alone is not None and both is not None
    np.testing.assert_array_equal(alone.y, both.y)
    assert alone.y.max() <= 7000.0


def test_estimator_colours_fixed_and_far_from_feature_colours():
    assert set(ESTIMATOR_COLORS) == {"analytic", "limit", "bayes", "compact", "paper"}
    assert estimator_colors(["compact", "bayes"]) == estimator_colors(["bayes", "compact"])
    est = [*ESTIMATOR_COLORS.values(), FALLBACK_ESTIMATOR]
    assert min(delta_e(a, b) for a in est for b in FEATURE_COLORS) >= MIN_DELTA_E
    assert min(delta_e(a, b) for a in est for b in est if a != b) >= MIN_DELTA_E
    assert set(FEATURE_COLORS) == set(scene_mod.OKABE_ITO)
    assert delta_e("#000000", "#FFFFFF") == pytest.approx(100.0, abs=0.1)


def test_errors_wrap_phi_across_zero():
    from eyeviz.model.frame_parts import errors

    assert errors(100.0, 0.0, 110.0, math.radians(359.0)) == pytest.approx((10.0, 10.0, -1.0))


def test_view_rect_is_the_views_width_about_its_centre():
    from eyeviz.model.frame_parts import view_rect

    sc = _scene()
    sc.view = scene_mod.View(center=(120.0, 2600.0), width=4000.0)
    assert view_rect(sc, aspect=0.5) == (-1880.0, 2120.0, 1600.0, 3600.0)
    assert view_rect(sc) == pytest.approx((-1880.0, 2120.0, 880.0, 4320.0))


def test_an_eyes_rim_and_owners_default_to_every_ommatidium():
    """``rim()`` and ``pooled_owner()`` without a level of detail: one cell per
    ommatidium, the rim at j * gamma for j = 0..m (Figure 2, Eq. 6)."""
    fr = build_frame(_scene(m=360))
    for eye, cx in zip(fr.eyes, (-H, H), strict=True):
        rim = eye.rim()
        t = np.arange(361) * (2 * math.pi / 360)
        np.testing.assert_allclose(rim, np.column_stack([cx + L * np.cos(t), L * np.sin(t)]))
        np.testing.assert_array_equal(eye.pooled_owner(), eye.owner)
        assert eye.owner.shape == (360,) and (eye.owner >= 0).any()


def test_sector_rays_reach_past_the_far_side_of_the_disc():
    sc = _scene()
    fr = build_frame(sc)
    centres = {"A": (-H, 0.0), "B": (H, 0.0)}
    assert fr.sectors
    for s in fr.sectors:
        f = sc.features[s.feature]
        r_e = math.hypot(f.x - centres[s.eye][0], f.y - centres[s.eye][1])
        assert s.reach > r_e + f.g, (s.feature, s.eye)
        assert np.hypot(*(s.ends - np.array(centres[s.eye])).T) == pytest.approx(s.reach)


def test_eye_labels_sit_under_the_eyes():
    fr = build_frame(_scene(layers=("eyes", "features", "labels")))
    eyes = {lab.text: lab for lab in fr.labels if lab.kind == "eye"}
    assert set(eyes) == {"A", "B", "O"}
    assert [eyes[k].x for k in "AOB"] == [-H, 0.0, H]
    assert all(lab.y < -L for lab in eyes.values())  # below the eye discs (radius l)
