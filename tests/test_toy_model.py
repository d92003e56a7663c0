"""docs/extending.md, "A new eye model", followed step by step with a toy model in space
(``ToyEyes`` of tests/conftest.py: seven facets per eye, a kind of its own), all the way
through ``eyeviz generate``, ``eyeviz predict`` and ``eyeviz report estimators``; the
app's view of it is tests/app/test_toy_model_view.py. Each step checks that the toy's
own geometry, not the package's idea of it, is what arrives."""

from __future__ import annotations

import csv

import numpy as np
import pytest

from eyeviz import cli
from eyeviz.core.eyes import EyeModel
from eyeviz.core.measured_from import as_measured
from eyeviz.dataset import sparse3d
from eyeviz.dataset.kinds import kind_of
from eyeviz.measured import load_eyes, save_eyes


def _balls(n: int, seed: int = 0) -> tuple[np.ndarray, ...]:
    """Balls in front of the toy's eyes, r in [1, 6], g in [0.05, 0.6]."""
    rng = np.random.default_rng(seed)
    r, az, el = rng.uniform(1, 6, n), rng.uniform(0.6, 2.5, n), rng.uniform(-0.6, 0.6, n)
    x, y, z = r * np.cos(el) * np.cos(az), r * np.cos(el) * np.sin(az), r * np.sin(el)
    return x, y, z, rng.uniform(0.05, 0.6, n)


@pytest.fixture(scope="module")
def toy_files(toy_eyes, tmp_path_factory):
    """Steps 2-3: the toy written as an eye file, and a data set generated from it."""
    d = tmp_path_factory.mktemp("toy")
    eye = save_eyes(toy_eyes, d / "toy.eye")
    npz = d / "toy.npz"
    assert cli.main(["generate", "--eye", str(eye), "-n", "40", "--seed", "3", "-o", str(npz)]) == 0
    return eye, npz


def test_step1_the_toy_implements_the_protocol(toy_eyes):
    assert isinstance(toy_eyes, EyeModel)
    assert (toy_eyes.kind, toy_eyes.dims, toy_eyes.facet_counts) == ("toy", 3, (7, 7))
    a, b = toy_eyes.bitmaps(*_balls(500))
    assert a.shape == b.shape == (500, 7)
    both = toy_eyes.in_bfv(*_balls(500))
    assert 20 < both.sum() < 480  # a binocular field, and not everything in it


def test_step2_its_facets_enter_as_a_pair_with_the_toys_own_lit_sets(toy_eyes):
    pair = as_measured(toy_eyes)
    assert pair.facet_counts == (7, 7)
    for w in "AB":
        for got, want in zip(pair.facets(w), toy_eyes.facets(w), strict=True):
            assert np.array_equal(got, want)
    balls = _balls(1000, seed=1)
    for got, want in zip(pair.bitmaps(*balls), toy_eyes.bitmaps(*balls), strict=True):
        assert got.sum() > 300 and np.array_equal(got, want)
    assert np.array_equal(pair.in_bfv(*balls), toy_eyes.in_bfv(*balls))
    for got, want in zip(pair.overlaps_eye(*balls), toy_eyes.overlaps_eye(*balls), strict=True):
        assert np.array_equal(got, want)


def test_step2_a_model_without_facets_is_refused_by_name():
    class NoFacets:
        kind = "nofacets"

    with pytest.raises(TypeError, match="a model with facets\\(eye\\), got NoFacets"):
        as_measured(NoFacets())


def test_step3_the_eye_file_keeps_the_toy_to_the_last_bit(toy_eyes, toy_files):
    eye, _ = toy_files
    assert load_eyes(eye).fingerprint == as_measured(toy_eyes).fingerprint


def test_step3_generate_writes_the_toys_lit_sets(toy_eyes, toy_files):
    _, npz = toy_files
    assert kind_of(npz) == "measured"
    ds = sparse3d.load3d(npz)
    assert len(ds.r) == 40 and ds.domain.facet_counts == (7, 7)
    assert ds.domain.design[2] == as_measured(toy_eyes).fingerprint
    bm = toy_eyes.bitmaps(ds.x, ds.y, ds.z, ds.g)
    for w, want in zip("ab", bm, strict=True):
        indptr, indices = getattr(ds, f"indptr_{w}"), getattr(ds, f"indices_{w}")
        for i in range(40):
            assert np.array_equal(indices[indptr[i] : indptr[i + 1]], np.flatnonzero(want[i]))
    assert toy_eyes.in_bfv(ds.x, ds.y, ds.z, ds.g).all()  # the sampler's field is the toy's


def test_step3_predict_and_report(toy_files, tmp_path, capsys, read_predictions3d):
    _, npz = toy_files
    pred = tmp_path / "p.csv"
    rc = cli.main(["predict", "--estimator", "analytic3d", str(npz), "-o", str(pred)])
    err = capsys.readouterr().err
    assert rc == 0, err
    assert "analytic3d: 40 rows" in err
    ds, vals, err, unit = read_predictions3d(pred, npz)
    assert len(vals) == 40
    # the direction from seven facets 0.3 rad apart: within about a facet at the median,
    # and better than guessing straight ahead (+y) for every ball
    guess = np.arccos(np.clip(unit[:, 1], -1, 1))
    assert np.median(err) < 0.4 and np.median(err) < 0.8 * np.median(guess)

    out = tmp_path / "rep"
    argv = ["report", "estimators", "--data", str(npz), "--estimators", "analytic3d"]
    rc = cli.main([*argv, "--limit-rows", "2", "-o", str(out)])
    text = capsys.readouterr().out
    assert rc == 0 and "analytic3d" in text, text
    md = (out / "estimators3d.md").read_text()
    assert "a measured pair of 7 + 7 facets" in md and "| analytic3d |" in md
    with open(out / "estimators3d.csv", newline="") as f:
        table = {r["estimator"]: r for r in csv.DictReader(f)}
    assert table["analytic3d"]["status"] == "ok" and table["analytic3d"]["rows"] == "40"
