"""The information limit: weighted medians, symmetry, the shipped table, unseen keys."""

import numpy as np
import pytest

from eyeviz import dataset, estimators
from eyeviz.estimators import bayes, metrics


def test_group_medians_weighted_and_plain():
    key = np.array([5, 5, 5, 2, 2], np.int64)
    val = np.array([1.0, 2.0, 10.0, 3.0, 4.0])
    k, med, cnt = bayes._group_medians(key, val, 0.0, 16.0, weighted=False)
    np.testing.assert_array_equal(k, [2, 5])
    np.testing.assert_array_equal(cnt, [2, 3])
    assert med[1] == pytest.approx(2.0, abs=1e-5)
    # 1/x weights 1, 0.5, 0.1: half of 1.6 is reached by the first value
    _, wmed, _ = bayes._group_medians(key, val, 0.0, 16.0, weighted=True)
    assert wmed[1] == pytest.approx(1.0, abs=1e-5)


def test_small_table_beats_constant_and_round_trips(tmp_path):
    table = bayes.build_table(200_000, seed=5)
    est = bayes.BayesEstimator(table)
    ds = dataset.generate(5000, seed=6)
    p = est.predict(ds.omega_a, ds.omega_b)
    assert p.valid.all()
    const = metrics.mape(ds.r, np.full(len(ds), np.median(ds.r)))
    assert metrics.mape(ds.r, p.r) < 0.3 * const
    assert metrics.mape(ds.phi, p.phi) < 0.1
    path = tmp_path / "b.npz"
    bayes.save_table(table, path)
    est2 = estimators.load("bayes", path=path)
    p2 = est2.predict(ds.omega_a, ds.omega_b)
    np.testing.assert_allclose(p2.r, p.r, rtol=1e-3)
    np.testing.assert_allclose(p2.phi, p.phi, rtol=0, atol=1e-5)


def test_unseen_keys_fall_back_to_analytic():
    table = bayes.build_table(2000, seed=5)
    est = bayes.BayesEstimator(table)
    ds = dataset.generate(3000, seed=8)
    *ivs, valid = estimators.base.bitmaps_to_intervals(ds.omega_a, ds.omega_b)
    r, phi, seen = est.lookup(*ivs)
    assert (~seen).sum() > 100  # a tiny table misses many keys
    ana = estimators.load("analytic").predict_intervals(*ivs)
    np.testing.assert_array_equal(r[~seen], ana.r[~seen])
    assert np.isfinite(r).all()


def test_mirror_symmetry_of_the_table():
    table = bayes.build_table(100_000, seed=2)
    w = 360
    LA, RA, LB, RB = bayes._decode(table["key"], w)
    mirror = bayes._encode(w - 1 - RB, w - 1 - LB, w - 1 - RA, w - 1 - LA, w)
    i = np.searchsorted(table["key"], mirror)
    assert (table["key"][i] == mirror).all()
    np.testing.assert_allclose(table["r_mape"][i], table["r_mape"], rtol=1e-6)


def test_shipped_table_is_the_limit():
    est = estimators.load("bayes")
    assert est.metadata["sample_size"] >= 10**7
    ds = dataset.generate(20_000, seed=777_001)
    p = est.predict(ds.omega_a, ds.omega_b)
    comp = estimators.load("compact").predict(ds.omega_a, ds.omega_b)
    ana = estimators.load("analytic").predict(ds.omega_a, ds.omega_b)
    b_dd = metrics.mape(ds.r, p.r)
    assert 6.8 < b_dd < 7.5
    assert b_dd < metrics.mape(ds.r, comp.r) + 0.02
    assert b_dd < metrics.mape(ds.r, ana.r) - 1.5
    assert est.target == "mape"
    mae_est = estimators.load("bayes", target="mae")
    assert metrics.mae(ds.r, mae_est.predict(ds.omega_a, ds.omega_b).r) < metrics.mae(ds.r, p.r)


def test_a_table_of_one_key_saves_loads_and_answers(tmp_path):
    table = bayes.build_table(20_000, seed=5)
    n = table["meta"]["keys"]
    one = {
        k: v[:1] if isinstance(v, np.ndarray) and v.shape == (n,) else v for k, v in table.items()
    }
    one["meta"] = {**table["meta"], "keys": 1}
    bayes.save_table(one, tmp_path / "one.npz")
    est = estimators.load("bayes", path=tmp_path / "one.npz")
    p = est.predict_intervals(*bayes._decode(one["key"], est.domain.width))
    np.testing.assert_allclose(p.r, one["r_mape"], rtol=1e-3)  # float16 storage
    np.testing.assert_allclose(p.phi, one["phi_mape"], rtol=0, atol=1e-5)
