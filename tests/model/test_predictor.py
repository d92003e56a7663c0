"""The Predictor answers for the scene's eyes (issue 10 item 4): analytic and limit are
loaded for the scene's (h, l, m), once per design; an estimator trained for the paper's
eyes says so instead of answering for the wrong eyes."""

from __future__ import annotations

import math

import numpy as np
import pytest

from eyeviz.core.domain import Domain
from eyeviz.core.geometry import intervals_to_bitmap
from eyeviz.model.frame import build_frame, trajectory_path
from eyeviz.model.predictor import Predictor, design_of
from eyeviz.model.scene import Eyes, Feature, Scene, Trajectory
from eyeviz.model.state import compute_state

NOTE = "cannot answer: trained for h = 40, l = 20, m = 720"


def scene(h=40.0, l=20.0, m=720, est=("analytic", "limit", "compact", "bayes")):  # noqa: E741
    return Scene(
        Eyes(h, l, m),
        [Feature("target", 300.0, 3000.0, 60.0, "#D55E00"), Feature("far", -800, 2200, 150)],
        ["eyes", "features", "readout", "predictions"],
        estimators=list(est),
    )


def _rel(res, st):
    r_hat, phi_hat = res
    return np.abs(r_hat - st.r) / st.r, np.abs(phi_hat - st.phi)


@pytest.mark.parametrize("eyes", [(80.0, 20.0, 720), (40.0, 20.0, 1440), (40.0, 10.0, 720)])
def test_any_design_estimators_answer_for_the_scenes_eyes(eyes):
    sc = scene(*eyes)
    st = compute_state(sc)
    assert st.in_domain().all()
    out = Predictor().predict(sc, st)
    for name in ("analytic", "limit"):
        dr, dphi = _rel(out[name], st)
        # the paper's eyes would give -50 % at h = 80 and no answer at m = 1440
        assert dr.max() < 0.2 and dphi.max() < 0.01, (name, dr, dphi)
    for name in ("compact", "bayes"):
        assert out[name] == NOTE


def test_the_papers_design_still_answers_with_every_estimator():
    sc = scene()
    st = compute_state(sc)
    out = Predictor().predict(sc, st)
    for name in ("analytic", "limit", "compact", "bayes"):
        dr, _ = _rel(out[name], st)
        assert dr.max() < 0.2, name


def test_estimators_are_cached_per_design():
    p = Predictor()
    a1 = p.estimator("limit", (80.0, 20.0, 720))
    a2 = p.estimator("limit", Eyes(80.0, 20.0, 720).pair())
    base = p.estimator("limit")
    assert a1 is a2 and a1 is not base
    assert design_of(a1.domain) == (80.0, 20.0, 720) and design_of(base.domain) == (40, 20, 720)
    assert a1.domain.r_max == base.domain.r_max and a1.prior == base.prior
    assert p.estimator("limit", Domain()) is base  # the paper's design: the first one
    c = p.estimator("compact", (80.0, 20.0, 720))
    assert c is p.estimator("compact")  # one trained estimator, whatever the design asked
    assert p.design_note("compact", (80.0, 20.0, 720)) == NOTE.removeprefix("cannot answer: ")
    assert p.design_note("compact", (40.0, 20.0, 720)) is None
    assert p.design_note("analytic", (80.0, 20.0, 720)) is None


def test_predict_bitmaps_for_another_m():
    sc = scene(40.0, 20.0, 1440)
    st = compute_state(sc)
    pair = sc.eyes.pair()
    oa = intervals_to_bitmap(st.LA, st.RA, 1440, 720)
    ob = intervals_to_bitmap(st.LB, st.RB, 1440, 720)
    p = Predictor()
    r_hat, _ = p.predict_bitmaps("analytic", oa, ob, pair)
    assert np.all(np.abs(r_hat - st.r) / st.r < 0.2)
    assert p.predict_bitmaps("compact", oa, ob, pair) == NOTE
    # without a design: the estimator's own (m = 720) refuses 720-wide rows, in one line
    msg = p.predict_bitmaps("analytic", oa, ob)
    assert isinstance(msg, str) and msg.startswith("cannot answer:") and "\n" not in msg


def test_no_features_still_reports_other_eyes():
    sc = scene(80.0)
    sc.features = []
    out = Predictor().predict(sc, compute_state(sc))
    assert out["compact"] == NOTE and isinstance(out["analytic"], tuple)


def test_frame_and_trajectory_use_the_scenes_eyes():
    sc = scene(80.0)
    fr = build_frame(sc)
    pf = fr.predictions["analytic"]
    assert np.all(np.abs(pf.dr_pct) < 20)
    assert fr.predictions["compact"] == NOTE
    path = trajectory_path(
        sc.eyes.pair(), Trajectory("horizontal", 3000.0, 50.0), ["analytic", "compact"], Predictor()
    )
    ad, dd = path.accuracy["analytic"]
    assert np.nanmedian(dd) > 80 and math.isfinite(np.nanmedian(ad))
    assert path.accuracy["compact"] == NOTE


def test_peek_never_loads():
    p = Predictor()
    assert p.peek("analytic") is None
    est = p.estimator("analytic")
    assert p.peek("analytic") is est
    assert p.peek("nonesuch") is None
    assert isinstance(p.estimator("nonesuch"), str) and p.peek("nonesuch").startswith("unavail")


# --- the row cache of a drag (issue 12 item 4) ---


def drag_scene(x0=0.0):
    fs = [Feature(f"f{i}", -900.0 + 300.0 * i, 1500.0 + 200.0 * i, 40.0) for i in range(6)]
    fs[0].x = x0
    return Scene(Eyes(40.0, 20.0, 720), fs, ["predictions"], estimators=["analytic"])


class Counting:
    """An estimator that records how many rows it is asked for."""

    def __init__(self, est):
        self.est, self.rows = est, []

    def predict(self, oa, ob):
        self.rows.append(len(oa))
        return self.est.predict(oa, ob)


def test_a_drag_frame_asks_only_for_the_moved_feature_and_answers_as_a_fresh_predictor():
    p = Predictor()
    counting = Counting(p.estimator("analytic"))
    p._loaded["analytic"] = counting
    sc = drag_scene()
    first = p.predict(sc, compute_state(sc))["analytic"]
    assert counting.rows == [6]
    for x0 in (50.0, 120.0, 400.0):  # f0 dragged: the other rows are known
        sc = drag_scene(x0)
        got = p.predict(sc, compute_state(sc))["analytic"]
        assert counting.rows[-1] == 1, counting.rows
        fresh = Predictor().predict(sc, compute_state(sc))["analytic"]
        np.testing.assert_array_equal(got[0], fresh[0])
        np.testing.assert_array_equal(got[1], fresh[1])
    np.testing.assert_array_equal(first[0][1:], got[0][1:])
    assert len(counting.rows) == 4


def test_the_row_cache_is_bounded_and_stays_right():
    p = Predictor()
    p.ROW_CACHE_MAX = 8
    for x0 in np.linspace(-300.0, 300.0, 12):
        sc = drag_scene(float(x0))
        got = p.predict(sc, compute_state(sc))["analytic"]
        fresh = Predictor().predict(sc, compute_state(sc))["analytic"]
        np.testing.assert_array_equal(got[0], fresh[0])
        assert max(len(c) for c in p._rows.values()) <= 8


def test_a_drag_frame_makes_bitmaps_only_for_rows_the_cache_lacks(monkeypatch):
    """The m/2-wide bitmaps cost ~2 ms a frame for 50 features at m = 36,000: a drag frame
    makes them for the moved feature only, and none for an estimator made for other eyes."""
    import eyeviz.model.predictor as predictor_module

    made: list[int] = []
    real = predictor_module.intervals_to_bitmap

    def counting(L, R, m, width):
        made.append(len(L))
        return real(L, R, m, width)

    monkeypatch.setattr(predictor_module, "intervals_to_bitmap", counting)
    p = Predictor()
    sc = drag_scene()
    p.predict(sc, compute_state(sc))
    assert made == [6, 6]  # eye A's rows, eye B's rows
    for x0 in (50.0, 120.0):
        made.clear()
        sc = drag_scene(x0)
        got = p.predict(sc, compute_state(sc))["analytic"]
        assert made == [1, 1]
        fresh = Predictor().predict(sc, compute_state(sc))["analytic"]
        np.testing.assert_array_equal(got[0], fresh[0])
    # compact (trained for m = 720) at m = 1440: its one line, and no bitmap made
    sc = drag_scene()
    sc.eyes = Eyes(40.0, 20.0, 1440)
    sc.estimators = ["compact"]
    made.clear()
    assert p.predict(sc, compute_state(sc)) == {"compact": NOTE}
    assert made == []
