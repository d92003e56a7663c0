"""The 3D predictions layer's model (eyeviz.model.predictions3d, issue 23 item 4): the
ghosts are the estimators' answers converted to centres, the errors are against the true
ball, the limit's result is shown only for the key wanted now, the readout's rows."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from eyeviz import EyevizError
from eyeviz.core.domain import Domain3D
from eyeviz.estimators import registry
from eyeviz.model import predictions3d as p3
from eyeviz.model import scene as scene_mod
from eyeviz.model.scene import Eyes, Feature, Scene, load
from eyeviz.model.state3d import compute_state3d

SCENES = Path(__file__).resolve().parents[2] / "assets" / "scenes"
LAYERS = ["eyes", "features", "readout", "predictions"]


def _scene(nside=16, balls=((0.0, 1500.0, 0.0, 80.0),), estimators=None) -> Scene:
    feats = [Feature(f"b{i}", x, y, g, "#D55E00", z) for i, (x, y, z, g) in enumerate(balls)]
    s = Scene(Eyes(40.0, 20.0, None, nside), feats, list(LAYERS))
    if estimators is not None:
        s.estimators = list(estimators)
    return s


def _direct(name, st, i, domain):
    """The estimator's own answer for ball i, loaded here (not through the layer)."""
    est = registry.load(name, domain=domain)
    la, lb = st.lit(i, "A"), st.lit(i, "B")
    p = est.predict((np.array([0, la.size]), la), (np.array([0, lb.size]), lb))
    return float(p[0][0]), float(p[1][0]), float(p[2][0]), p


def test_ghosts_are_the_estimators_answers_converted():
    sc = _scene(balls=((-300.0, 1800.0, 250.0, 90.0), (200.0, 1200.0, -150.0, 60.0)))
    st = compute_state3d(sc)
    pred = p3.Predictor3D()
    dom = Domain3D(h=40.0, l=20.0, nside=16)
    for i in range(2):
        out = p3.scene_predictions3d(sc, st, i, pred, names=["analytic3d", "limit3d"])
        assert out is not None and out.ball == i and out.g == st.g[i]
        assert out.truth == (st.x[i], st.y[i], st.z[i])
        for name in ("analytic3d", "limit3d"):
            a = out.answers[name]
            assert isinstance(a, p3.Answer3D) and a.valid
            r, az, el, _ = _direct(name, st, i, dom)
            assert (a.r, a.azimuth, a.elevation) == pytest.approx((r, az, el), rel=1e-12)
            # x right, y forward, z up (docs/spherical.md), written out here
            want = (
                r * math.cos(el) * math.cos(az),
                r * math.cos(el) * math.sin(az),
                r * math.sin(el),
            )
            assert (a.x, a.y, a.z) == pytest.approx(want, rel=1e-12, abs=1e-9)
            assert a.dr_pct == pytest.approx(100.0 * (r - st.r[i]) / st.r[i])
            assert a.del_ == pytest.approx(math.degrees(el - st.elevation[i]))
        assert [g.name for g in out.ghosts()] == ["analytic3d", "limit3d"]
        assert out.cloud is not None and len(out.cloud.points) > 0
        # the cloud is the limit's own posterior for this key (its draws are a hash of
        # the key: the same samples again), the heaviest sample opaque
        from eyeviz.estimators.limit3d import posterior_samples3d

        est = registry.load("limit3d", domain=dom)
        s = posterior_samples3d(est, st.lit(i, "A"), st.lit(i, "B"))
        assert 0 < s["weight"].size <= p3.MAX_CLOUD  # under the cap: every sample drawn
        assert np.allclose(out.cloud.points, np.column_stack([s[k] for k in "xyz"]))
        assert out.cloud.alpha.max() == pytest.approx(1.0)


def test_errors_wrap_the_azimuth_and_are_relative_for_r():
    dr, daz, de = p3.errors3d((2000.0, math.radians(1.0), 0.1), (2100.0, math.radians(359.0), 0.0))
    assert dr == pytest.approx(5.0)
    assert daz == pytest.approx(-2.0)
    assert de == pytest.approx(-math.degrees(0.1))


def test_answers_for_one_ball_only_and_in_the_domain():
    behind = _scene(balls=((0.0, -1500.0, 0.0, 80.0), (0.0, 1500.0, 0.0, 80.0)))
    st = compute_state3d(behind)
    pred = p3.Predictor3D()
    out = p3.scene_predictions3d(behind, st, 0, pred, names=["analytic3d"])
    assert out is not None and out.ghosts() == []
    assert out.answers["analytic3d"] == "not in the 3D binocular field"  # says which
    assert p3.scene_predictions3d(behind, st, None, pred) is None
    assert p3.scene_predictions3d(behind, st, 5, pred) is None
    # in the field but outside Table 4's ranges: answered, with the note
    near = _scene(balls=((0.0, 400.0, 0.0, 50.0),))
    out = p3.scene_predictions3d(near, compute_state3d(near), 0, pred, names=["analytic3d"])
    assert out is not None and out.note is not None and "r outside [1000, 5000]" in out.note


def test_learned3d_says_in_one_line_it_is_for_another_design():
    sc = _scene(nside=16)
    out = p3.scene_predictions3d(sc, compute_state3d(sc), 0, p3.Predictor3D(), names=["learned3d"])
    assert out is not None
    msg = out.answers["learned3d"]
    assert isinstance(msg, str) and msg.startswith("unavailable") and "nside=180" in msg
    assert "\n" not in msg


def test_the_limit_waits_in_a_drag_and_comes_from_the_cache():
    sc = _scene()
    st = compute_state3d(sc)
    pred = p3.Predictor3D()
    names = ["analytic3d", "limit3d"]
    drag = p3.scene_predictions3d(sc, st, 0, pred, limit="drag", names=names)
    idle = p3.scene_predictions3d(sc, st, 0, pred, limit="cached", names=names)
    assert drag is not None and idle is not None
    assert drag.answers["limit3d"] == "after the drag"
    assert idle.answers["limit3d"] == "computing…" and idle.cloud is None
    assert isinstance(idle.answers["analytic3d"], p3.Answer3D)  # fast: every frame
    job = pred.limit_job(p3.domain_of(sc), st, 0)
    assert callable(job)
    pred.store_limit(p3.ball_key(st, 0), job())
    again = p3.scene_predictions3d(sc, st, 0, pred, limit="cached", names=names)
    assert again is not None and isinstance(again.answers["limit3d"], p3.Answer3D)
    assert again.cloud is not None


def test_ball_key_is_the_lit_sets():
    sc = _scene(balls=((0.0, 1500.0, 0.0, 80.0), (0.0, 1500.0, 0.0, 80.0), (5.0, 1500, 0, 80)))
    st = compute_state3d(sc)
    assert p3.ball_key(st, 0) == p3.ball_key(st, 1)  # same lit sets, same answers
    same = np.array_equal(st.lit(0, "A"), st.lit(2, "A")) and np.array_equal(
        st.lit(0, "B"), st.lit(2, "B")
    )
    assert (p3.ball_key(st, 0) == p3.ball_key(st, 2)) == same


def test_staleness_only_the_newest_key_is_shown():
    lo = p3.LatestOnly()
    assert lo.want(b"k1")  # nothing runs: start
    assert not lo.want(b"k2")  # the ball moved on while k1 runs: wait
    assert not lo.want(b"k3")  # and on again
    assert not lo.finish(b"k1")  # k1's result is stale: not shown
    assert lo.start_pending() == b"k3"  # only the newest is computed next (k2 never)
    assert lo.start_pending() is None  # one job at a time
    assert lo.finish(b"k3")  # still wanted: shown
    assert lo.start_pending() is None
    assert lo.want(b"k4")  # nothing runs: a new key starts at once
    lo.want(None)  # the layer is off: nothing wanted, a late result is not shown
    assert not lo.finish(b"k4")
    assert lo.start_pending() is None


def test_cloud_is_capped_to_the_heaviest_with_alpha_by_weight():
    rng = np.random.default_rng(1)
    n = 50
    w = rng.random(n)
    w /= w.sum()
    samples = {k: rng.normal(size=n) for k in "xyz"} | {"weight": w}
    c = p3.cloud_of(samples, cap=10)
    assert c.n_samples == n and len(c.points) == 10
    top = np.argsort(-w)[:10]
    assert np.allclose(c.points, np.column_stack([samples[k][top] for k in "xyz"]))
    assert c.alpha.max() == pytest.approx(1.0)
    assert np.all(np.diff(c.alpha) <= 0) and c.alpha.min() >= 0.15
    empty = p3.cloud_of({k: np.zeros(0) for k in ("x", "y", "z", "weight")})
    assert len(empty.points) == 0


def test_rows_flag_and_monte_carlo_error():
    a = p3.Answer3D("limit3d", 2010.0, 1.5, 0.1, 1.0, 2.0, 3.0, True, True, 0.0021, 14,
                    0.5, 0.01, -0.002)  # fmt: skip
    one = p3.Answer3D("limit3d", 2010.0, 1.5, 0.1, 1.0, 2.0, 3.0, True, False, 0.0, 1)
    solo = p3.Predictions3D(0, 50.0, (0.0, 0.0, 0.0), {"limit3d": one})
    assert p3.prediction_rows(solo)[0][-1] == "1 draw: MC n/a"  # not "MC ±0 %"
    b = p3.Answer3D("analytic3d", *([math.nan] * 6), False, False)
    pr = p3.Predictions3D(0, 50.0, (0.0, 0.0, 0.0), {"limit3d": a, "analytic3d": b})
    pr.answers["learned3d"] = "unavailable: weights for nside 180"
    rows = {r[0]: r for r in p3.prediction_rows(pr)}
    assert rows["limit3d"][1:3] == ("2010", "+0.50")
    assert "MC ±0.21 %" in rows["limit3d"][-1] and "flagged" in rows["limit3d"][-1]
    assert rows["analytic3d"][1] == "" and "no answer" in rows["analytic3d"][-1]
    assert rows["learned3d"][-1].startswith("unavailable")
    assert p3.prediction_rows(None) == []


def test_the_scene_names_the_estimators_with_the_planar_key():
    known = ["analytic3d", "learned3d", "limit3d"]
    sc = _scene()
    assert sc.estimators == ["compact"]  # a scene file's default (planar)
    assert p3.estimators3d(sc, known) == list(p3.DEFAULT_ESTIMATORS3D)
    sc.estimators = ["limit3d", "compact", "analytic3d"]
    assert p3.estimators3d(sc, known) == ["limit3d", "analytic3d"]
    assert p3.estimator_color3d("analytic3d") != p3.estimator_color3d("limit3d")
    shipped = load(SCENES / "sphere_predictions.toml")
    assert shipped.shows("predictions") and p3.estimators3d(shipped, known) == known


def test_outside_the_domain_says_which_eye_and_a_40_char_cut_keeps_it():
    # a small ball at nside 2: in the field, one facet lit per eye (Definition 1: two)
    tiny = _scene(nside=2, balls=((0.0, 1500.0, 0.0, 0.5),))
    st = compute_state3d(tiny)
    assert st.in_bfv[0] and int(st.facets_a[0]) == 1
    out = p3.scene_predictions3d(tiny, st, 0, p3.Predictor3D(), names=["analytic3d"])
    assert out is not None and out.ghosts() == []
    assert out.answers["analytic3d"] == "eye A: 1 facet lit (needs 2); eye B: 1 facet lit (needs 2)"
    behind = _scene(balls=((0.0, -1500.0, 0.0, 80.0),))
    why = p3.outside_reason(compute_state3d(behind), 0)
    assert len(why) <= 40  # the exported figure's table cuts a cell at 40 characters


def test_an_unavailable_reason_names_no_local_path():
    # learned3d's weights are for nside 180: its reason names their folder, which the
    # readout and the exported figure must not show (a path under the user's home)
    why = p3.Predictor3D().estimator("learned3d", Domain3D(h=40.0, l=20.0, nside=16))
    assert isinstance(why, str) and why.startswith("unavailable: ") and "nside=180" in why
    assert "/" not in why and "\\" not in why
    assert str(Path(registry.__file__).resolve().parents[1]) not in why


def test_a_name_no_estimator_has_is_refused_in_one_line():
    sc = _scene(estimators=["nonsense"])
    st = compute_state3d(sc)
    with pytest.raises(
        EyevizError,
        match=r"^predictions.estimators: unknown estimator 'nonsense'; available: .*limit3d",
    ):
        p3.scene_predictions3d(sc, st, 0, p3.Predictor3D())
    # a planar name is refused too (issue 36: "compact" silently drew the spherical three)
    for planar in ("compact", "analytic"):
        sc.estimators = ["limit3d", planar]
        with pytest.raises(
            EyevizError,
            match=rf"^predictions.estimators: '{planar}' is an estimator of the planar eyes; "
            r"a spherical scene's are analytic3d, learned3d, limit3d$",
        ):
            p3.check_estimators(sc)
    sc.layers.remove("predictions")  # a scene not showing the layer is not checked
    sc.estimators = ["nonsense"]
    p3.check_estimators(sc)


def test_a_name_given_twice_is_one_estimator():
    sc = _scene(estimators=["limit3d", "analytic3d", "limit3d"])
    assert p3.estimators3d(sc, ["analytic3d", "learned3d", "limit3d"]) == ["limit3d", "analytic3d"]


def test_a_spherical_scene_file_naming_no_estimator_shows_the_spherical_three():
    text = '[eyes]\nh = 40.0\nl = 20.0\nnside = 8\n[layers]\nshow = ["eyes", "predictions"]\n'
    sc = scene_mod.loads(text)
    assert sc.estimators == ["analytic3d", "learned3d", "limit3d"]
    p3.check_estimators(sc)
    planar = scene_mod.loads(text.replace("nside = 8", "m = 720"))
    assert planar.estimators == ["compact"]  # the planar default is unchanged
