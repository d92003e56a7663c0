"""Eq. 33-35 with the standard R^2 (docs/conventions.md)."""

import numpy as np
import pytest

from eyeviz.estimators import metrics


def test_known_values():
    t = np.array([1.0, 2.0, 4.0])
    p = np.array([1.5, 2.0, 3.0])
    assert metrics.mae(t, p) == pytest.approx(0.5)
    assert metrics.mape(t, p) == pytest.approx(100 * (0.5 + 0 + 0.25) / 3)
    ss_res = 0.25 + 0 + 1
    ss_tot = np.sum((t - t.mean()) ** 2)
    assert metrics.r2(t, p) == pytest.approx(1 - ss_res / ss_tot)


def test_r2_uses_spread_of_true_values():
    # a constant prediction at the true mean scores 0, whatever the paper's Eq. 36 would say
    t = np.array([1.0, 2.0, 3.0, 6.0])
    assert metrics.r2(t, np.full(4, t.mean())) == pytest.approx(0.0)
    assert metrics.r2(t, t) == 1.0


def test_summary_keys_and_bad_input():
    s = metrics.summary([1.0, 2.0], [1.0, 2.2])
    assert set(s) == {"mape", "mae", "r2"}
    with pytest.raises(ValueError, match="differ in length"):
        metrics.mae([1.0], [1.0, 2.0])
    with pytest.raises(ValueError, match="finite"):
        metrics.mape([1.0, 2.0], [np.nan, 2.0])
    with pytest.raises(ValueError, match="true value is 0"):
        metrics.mape([0.0, 2.0], [1.0, 2.0])


def test_running_summary_equals_summary_on_blocks():
    import numpy as np

    from eyeviz.estimators.metrics import RunningSummary, summary

    rng = np.random.default_rng(3)
    t = rng.uniform(1000, 5000, 10_001)
    p = t * rng.normal(1, 0.05, t.size)
    run = RunningSummary()
    for s in range(0, t.size, 777):
        run.update(t[s : s + 777], p[s : s + 777])
    run.update(t[:0], p[:0])
    got, want = run.result(), summary(t, p)
    for k in want:
        assert abs(got[k] - want[k]) <= 1e-9 * max(1.0, abs(want[k])), k
