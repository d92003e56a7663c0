"""The app's Predictor: answers per feature, each row asked of an estimator once."""

import numpy as np

from eyeviz.model.predictor import Predictor
from eyeviz.model.scene import Eyes, Feature, Scene
from eyeviz.model.state import compute_state


def scene(x0=0.0):
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
    sc = scene()
    first = p.predict(sc, compute_state(sc))["analytic"]
    assert counting.rows == [6]
    for x0 in (50.0, 120.0, 400.0):  # f0 dragged: the other rows are known
        sc = scene(x0)
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
        sc = scene(float(x0))
        got = p.predict(sc, compute_state(sc))["analytic"]
        fresh = Predictor().predict(sc, compute_state(sc))["analytic"]
        np.testing.assert_array_equal(got[0], fresh[0])
        assert len(p._rows["analytic"]) <= 8
