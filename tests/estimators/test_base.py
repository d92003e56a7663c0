"""The shared protocol: validation, interval extraction, NaN rows and masks."""

import numpy as np
import pytest

from eyeviz import estimators
from eyeviz.core.geometry import EyePair, intervals_to_bitmap
from eyeviz.estimators.base import PAPER_DOMAIN, Domain, bitmaps_to_intervals, in_domain

W = PAPER_DOMAIN.width


def _features(n, seed=0):
    rng = np.random.default_rng(seed)
    r = rng.uniform(1000, 5000, n)
    phi = rng.uniform(np.pi / 6 + 0.12, 5 * np.pi / 6 - 0.12, n)
    g = rng.uniform(30, 300, n)
    return r * np.cos(phi), r * np.sin(phi), g


def _bitmaps(n, seed=0):
    LA, RA, LB, RB = EyePair().intervals(*_features(n, seed))
    a = intervals_to_bitmap(LA, RA, 720, W)
    return a, intervals_to_bitmap(LB, RB, 720, W), (LA, RA, LB, RB)


def test_intervals_round_trip_from_bitmaps():
    a, b, ivs = _bitmaps(3000)
    *got, valid = bitmaps_to_intervals(a, b)
    assert valid.all()
    for g, want in zip(got, ivs, strict=True):
        np.testing.assert_array_equal(g, want)


def test_runs_at_the_bitmap_ends_and_odd_widths():
    for width in (W, 13):
        a = np.zeros((4, width), bool)
        a[0, 0] = True
        a[1, width - 1] = True
        a[2, :] = True
        a[3, 2 : width - 3] = True
        LA, RA, LB, RB, valid = bitmaps_to_intervals(a, a)
        assert valid.all()
        np.testing.assert_array_equal(LA, [0, width - 1, 0, 2])
        np.testing.assert_array_equal(RA, [0, width - 1, width - 1, width - 4])


def test_predict_accepts_ints_floats_bools_and_single_rows():
    a, b, _ = _bitmaps(50)
    est = estimators.load("analytic")
    r0, p0 = est.predict(a, b)
    for conv in (lambda x: x.astype(np.uint8), lambda x: x.astype(float), lambda x: x.astype(int)):
        r, p = est.predict(conv(a), conv(b))
        np.testing.assert_array_equal(r, r0)
        np.testing.assert_array_equal(p, p0)
    one = est.predict(list(a[7].astype(int)), b[7])
    assert np.ndim(one.r) == 0 and one.r == r0[7] and one.phi == p0[7]
    assert bool(one.valid) and bool(one.in_domain)


def test_wrong_length_non_binary_and_mismatch_raise():
    est = estimators.load("analytic")
    a, b, _ = _bitmaps(5)
    with pytest.raises(ValueError, match="length m/2 = 360"):
        est.predict(a[:, :-1], b[:, :-1])
    bad = a.astype(int)
    bad[2, 5] = 2
    with pytest.raises(ValueError, match="binary.*row 2, column 5"):
        est.predict(bad, b)
    with pytest.raises(ValueError, match="different row counts"):
        est.predict(a[:3], b)
    with pytest.raises(ValueError, match="shape"):
        est.predict(a[None], b[None])
    with pytest.raises(ValueError, match="0/1 numbers"):
        est.predict(np.array(["x"] * W), np.array(["x"] * W))


def test_empty_eye_and_two_runs_give_nan_and_mask():
    a, b, _ = _bitmaps(6)
    a[1] = False  # nothing lit in eye A
    b[3, :] = False
    b[3, [10, 11, 20]] = True  # two lit runs in eye B
    p = estimators.load("analytic").predict(a, b)
    np.testing.assert_array_equal(p.valid, [True, False, True, False, True, True])
    assert np.isnan(p.r[[1, 3]]).all() and np.isnan(p.phi[[1, 3]]).all()
    assert np.isfinite(p.r[p.valid]).all()
    assert not p.in_domain[[1, 3]].any()
    zero = estimators.load("analytic").predict(np.zeros(W), np.zeros(W))
    assert np.isnan(zero.r) and not zero.valid


def test_empty_input():
    p = estimators.load("analytic").predict(np.zeros((0, W)), np.zeros((0, W)))
    assert p.r.shape == (0,) and p.valid.shape == (0,)


def test_out_of_domain_flag():
    eyes = EyePair()
    # inside: r = 3000 straight ahead, g = 50
    ivs_in = eyes.intervals(0.0, 3000.0, 50.0)
    # too near (r = 200), too far (r = 60000, a 1-2 sector disparity can't be below r_max)
    ivs_near = eyes.intervals(0.0, 200.0, 20.0)
    ivs_far = eyes.intervals(0.0, 60000.0, 300.0)
    ivs_big = eyes.intervals(0.0, 1500.0, 1400.0)  # g far above g_max
    got = [bool(in_domain(*v, PAPER_DOMAIN)) for v in (ivs_in, ivs_near, ivs_far, ivs_big)]
    assert got == [True, False, False, False]
    wide = Domain(r_min=100.0, r_max=100000.0, g_max=2000.0)
    assert bool(in_domain(*ivs_near, wide)) and bool(in_domain(*ivs_far, wide))


def test_predict_intervals_matches_predict():
    a, b, ivs = _bitmaps(200, seed=3)
    est = estimators.load("analytic")
    p1 = est.predict(a, b)
    p2 = est.predict_intervals(*ivs)
    np.testing.assert_array_equal(p1.r, p2.r)
    p3 = est.predict_intervals(0, 5, 400, 410)  # RB beyond the half bitmap
    assert not p3.valid and np.isnan(p3.r)


def test_domain_validation():
    with pytest.raises(ValueError, match="r_min"):
        Domain(r_min=10.0, r_max=5.0)
    with pytest.raises(ValueError, match="m must be an even integer"):
        Domain(m=7)


def test_predict_intervals_takes_runs_inside_the_half_bitmap_only():
    """Issue 20 item 7, mutant 3: a run ends at m/2 - 1 at most (R = m/2 is past the half
    bitmap) and starts at 0 at least, in either eye; a one-ommatidium run (L = R) is a run."""
    est = estimators.load("analytic")
    ok = [(100, 110, 300, W - 1), (100, W - 1, 300, 310), (0, 110, 300, 310), (100, 110, 0, 310)]
    ok += [(100, 100, 300, 310), (100, 110, 300, 300)]
    bad = [(100, 110, 300, W), (100, W, 300, 310), (-1, 110, 300, 310), (100, 110, -1, 310)]
    bad += [(111, 110, 300, 310), (100, 110, 311, 310)]
    p = est.predict_intervals(*np.array(ok + bad).T)
    assert p.valid.tolist() == [True] * len(ok) + [False] * len(bad)
    assert np.isfinite(p.r[: len(ok)]).all() and np.isnan(p.r[len(ok) :]).all()
    assert np.isnan(p.phi[len(ok) :]).all() and not p.in_domain[len(ok) :].any()
    for iv in bad:  # one row at a time (no neighbour to share a mask with)
        q = est.predict_intervals(*iv)
        assert not q.valid and np.isnan(q.r) and np.isnan(q.phi), iv


def test_in_domain_refuses_a_run_touching_either_end_of_either_eye():
    """Issue 20 item 7, mutant 4: a run that touches an end of the half bitmap (index 0 or
    m/2 - 1) may go on past it, so it is out of the domain in eye A and in eye B alike;
    one ommatidium in from the end it is in (a domain wide enough for the rest)."""
    wide = Domain(r_min=1.0, r_max=1e9, g_max=1e9)
    inner = (100, 110, 300, 310)
    assert bool(in_domain(*inner, wide))
    for k, (end, one_in) in enumerate(((0, 1), (W - 1, W - 2), (0, 1), (W - 1, W - 2))):
        touching, inside = list(inner), list(inner)
        touching[k], inside[k] = end, one_in
        assert not bool(in_domain(*touching, wide)), touching
        assert bool(in_domain(*inside, wide)), inside


def test_one_base_checks_the_domain_of_every_model():
    from eyeviz.core.domain import Domain3D
    from eyeviz.estimators.analytic import AnalyticEstimator
    from eyeviz.estimators.analytic3d import Analytic3DEstimator
    from eyeviz.estimators.base import Estimator3D, EstimatorBase

    flat, space = AnalyticEstimator(Domain(m=36)), Analytic3DEstimator(Domain3D(nside=4))
    assert isinstance(flat, EstimatorBase) and isinstance(space, EstimatorBase)
    assert not isinstance(flat, Estimator3D) and flat.kinds == ("planar",)
    assert repr(flat) == "<AnalyticEstimator 'analytic' m=36>"
    assert repr(space) == "<Analytic3DEstimator 'analytic3d' (h, l, nside) = (40.0, 20.0, 4)>"
    with pytest.raises(ValueError, match="^domain must be a Domain, got Domain3D$"):
        AnalyticEstimator(Domain3D(nside=4))
    with pytest.raises(ValueError, match="^domain must be a Domain3D, got Domain$"):
        Analytic3DEstimator(Domain(m=36))


def test_answers_unpack_carry_their_masks_and_pickle():
    import pickle

    from eyeviz.estimators.base import Prediction, Prediction3D

    p = Prediction(np.array([1.0]), np.array([0.5]), np.array([True]), np.array([False]))
    r, phi = p
    assert (p.r is r, p.phi is phi, p.valid[0], p.in_domain[0]) == (True, True, True, False)
    q = Prediction3D(1.0, 0.5, 0.25, True, False, True)
    assert tuple(q) == (1.0, 0.5, 0.25) and (q.azimuth, q.elevation) == (0.5, 0.25)
    back = pickle.loads(pickle.dumps(q))
    assert type(back) is Prediction3D and tuple(back) == tuple(q)
    assert (back.valid, back.in_domain, back.flagged) == (True, False, True)
    with pytest.raises(TypeError, match="Prediction takes 4 values"):
        Prediction(1.0, 0.5, True)
