"""``eyeviz predict``: refuses to overwrite its input, checks the data's design against the
estimator's, builds an any-design estimator's domain from flags."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest

from eyeviz import dataset


@pytest.fixture
def cli(eyeviz_main):
    """``eyeviz ARGS`` in this process (the command's result is the point here)."""
    return eyeviz_main


@pytest.fixture(scope="module")
def data(tmp_path_factory):
    d = tmp_path_factory.mktemp("data")
    dataset.write(d / "paper.npz", 300, seed=2)
    dataset.write(d / "paper.csv", 300, seed=2)
    dataset.write(d / "m360.csv", 300, dataset.PAPER_EYES.__class__(40, 20, 360), seed=3)
    dataset.write(d / "m360.npz", 300, dataset.PAPER_EYES.__class__(40, 20, 360), seed=3)
    return d


def _one_line_error(res, *parts):
    assert res.returncode == 2, res.stderr
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("eyeviz: error: "), res.stderr
    for p in parts:
        assert p in lines[0], lines[0]


@pytest.mark.parametrize("how", ["same", "symlink", "hardlink", "relative"])
def test_output_equal_to_input_refused(data, tmp_path, how, cli):
    src = tmp_path / "in.csv"
    src.write_bytes((data / "paper.csv").read_bytes())
    before = src.read_bytes()
    out = {"same": src, "relative": Path("in.csv")}.get(how, tmp_path / "link.csv")
    if how == "symlink":
        out.symlink_to(src)
    elif how == "hardlink":
        os.link(src, out)
    res = cli("predict", "-e", "analytic", src, "-o", out, cwd=tmp_path)
    _one_line_error(res, "is the input data file")
    assert src.read_bytes() == before


@pytest.mark.slow
def test_npz_design_mismatch_names_both(data, tmp_path, cli):
    res = cli("predict", "-e", "compact", data / "m360.npz", "-o", tmp_path / "p.csv")
    _one_line_error(res, "h=40, l=20, m=360", "'compact'", "h=40, l=20, m=720")
    assert not (tmp_path / "p.csv").exists()


@pytest.mark.slow
def test_csv_design_from_flags(data, tmp_path, cli):
    res = cli("predict", "-e", "compact", "--m", "360", data / "m360.csv", "-o", tmp_path / "p")
    _one_line_error(res, "m=360", "'compact' answers for h=40, l=20, m=720")
    res = cli("predict", "-e", "bayes", data / "m360.csv", "-o", tmp_path / "p.csv")
    _one_line_error(res, "m=360", "m=720")  # no --m: the default (Table 3) does not fit


def test_npz_flags_contradicting_the_file_refused(data, tmp_path, cli):
    res = cli("predict", "-e", "analytic", "--h", "30", data / "paper.npz", "-o", tmp_path / "p")
    _one_line_error(res, "has design h=40, l=20, m=720", "--h 30")


def test_any_design_estimator_takes_the_data_design(data, tmp_path, cli):
    out = tmp_path / "p.csv"
    res = cli("predict", "-e", "analytic", "--m", "360", data / "m360.csv", "-o", out)
    assert res.returncode == 0, res.stderr
    pred = np.loadtxt(out, delimiter=",", skiprows=1)
    truth = dataset.load(data / "m360.npz")
    assert pred.shape == (300, 2)
    assert np.median(np.abs(pred[:, 0] / truth.r - 1)) < 0.5  # answers in the right design
    res = cli("predict", "-e", "analytic", data / "m360.npz", "-o", out)
    assert res.returncode == 0, res.stderr


def test_csv_and_npz_give_the_same_predictions(data, tmp_path, cli):
    for name in ("paper.csv", "paper.npz"):
        res = cli("predict", "-e", "bayes", data / name, "-o", tmp_path / f"{name}.out")
        assert res.returncode == 0, res.stderr
    a = np.loadtxt(tmp_path / "paper.csv.out", delimiter=",", skiprows=1)
    b = np.loadtxt(tmp_path / "paper.npz.out", delimiter=",", skiprows=1)
    assert np.allclose(a, b, equal_nan=True)


def test_unknown_estimator_lists_the_registry(data, tmp_path, cli):
    res = cli("predict", "-e", "nope", data / "paper.npz", "-o", tmp_path / "p.csv")
    _one_line_error(res, "unknown estimator 'nope'", "analytic", "bayes", "compact", "paper")


def test_streamed_output_equals_in_memory_prediction(data, tmp_path, cli):
    from eyeviz import estimators

    out = tmp_path / "p.csv"
    res = cli("predict", "-e", "bayes", data / "paper.npz", "-o", out)
    assert res.returncode == 0, res.stderr
    assert out.read_text().splitlines()[0] == "r_hat,phi_hat"
    got = np.loadtxt(out, delimiter=",", skiprows=1)
    ds = dataset.load(data / "paper.npz")
    want = estimators.load("bayes").predict(ds.omega_a, ds.omega_b)
    assert np.array_equal(got[:, 0], want.r, equal_nan=True)
    assert np.array_equal(got[:, 1], want.phi, equal_nan=True)
    assert "300 rows" in res.stderr and "DD MAPE" in res.stderr


def test_limit_domain_and_prior_from_flags(data, tmp_path, cli):
    out = tmp_path / "p.csv"
    args = ["predict", "-e", "limit", "--m", "360", "--r-min", "1000", "--r-max", "5000"]
    args += ["--g-max", "500", "--prior", "multi", data / "m360.csv", "-o", out]
    res = cli(*args)
    assert res.returncode == 0, res.stderr
    got = np.loadtxt(out, delimiter=",", skiprows=1)
    from eyeviz import estimators

    ds = dataset.load(data / "m360.npz")
    dom = estimators.Domain(40, 20, 360, 1000, 5000, 500)
    want = estimators.load("limit", domain=dom, prior="multi").predict(ds.omega_a, ds.omega_b)
    assert np.allclose(got[:, 0], want.r, equal_nan=True)
    single = estimators.load("limit", domain=dom, prior="single").predict(ds.omega_a, ds.omega_b)
    assert not np.allclose(got[:, 0], single.r, equal_nan=True)  # --prior reached the estimator
    res = cli("predict", "-e", "limit", "--prior", "triple", data / "m360.csv", "-o", out)
    assert res.returncode == 2 and "triple" in res.stderr


@pytest.mark.parametrize(
    ("extra", "parts"),
    [
        (["--weights", "x"], ("'analytic' has no weights", "--weights", "compact")),
        (["--target", "mae"], ("--target is an option of estimator 'bayes'", "'analytic'")),
        (["--device", "cpu"], ("--device is an option of estimator 'paper'",)),
    ],
)
def test_options_the_estimator_does_not_take_are_refused(data, tmp_path, extra, parts, cli):
    out = tmp_path / "p.csv"
    res = cli("predict", "-e", "analytic", *extra, data / "paper.npz", "-o", out)
    _one_line_error(res, *parts)
    assert not out.exists()


def test_ranges_for_a_fixed_design_estimator_are_refused(data, tmp_path, cli):
    res = cli("predict", "-e", "bayes", "--r-min", "10", data / "paper.npz", "-o", tmp_path / "p")
    _one_line_error(res, "--r-min is for estimators of any design", "'bayes'")


def test_rows_without_a_single_feature_are_nan_and_exit_0(data, tmp_path, capsys):
    """Invalid bitmaps (no lit ommatidium) have no answer by definition: nan, counted."""
    from eyeviz.cli import main

    ds = dataset.load(data / "paper.npz")
    ds.omega_a[[3, 7]] = False
    src = tmp_path / "d.npz"
    dataset.save(ds, src)
    out = tmp_path / "p.csv"
    code = main(["predict", "-e", "analytic", str(src), "-o", str(out)])
    err = capsys.readouterr().err
    assert code == 0, err
    got = np.loadtxt(out, delimiter=",", skiprows=1)
    assert np.isnan(got[[3, 7]]).all() and np.isfinite(np.delete(got, [3, 7], 0)).all()
    assert "2 not a single feature (nan)" in err and "warning" not in err


def test_valid_rows_left_unanswered_exit_3_after_writing(data, tmp_path, capsys):
    """An estimator that returns nan for rows that are a single feature: the output is
    written (nothing lost), one warning line counts them, exit 3 (documented in --help)."""
    from eyeviz.cli import main
    from eyeviz.estimators import analytic, registry

    class Holes(analytic.AnalyticEstimator):
        name = "holes"

        def _predict_intervals(self, LA, RA, LB, RB):
            r, phi = super()._predict_intervals(LA, RA, LB, RB)
            r = r.copy()
            r[::100] = np.nan
            return r, phi

    registry.register(
        registry.Entry("holes", "test: nan for every 100th row", lambda: Holes()),
        replace=True,
    )
    try:
        out = tmp_path / "p.csv"
        code = main(["predict", "-e", "holes", str(data / "paper.npz"), "-o", str(out)])
    finally:
        registry.unregister("holes")
    err = capsys.readouterr().err
    assert code == 3, err
    got = np.loadtxt(out, delimiter=",", skiprows=1)
    assert got.shape == (300, 2) and np.isnan(got[::100, 0]).all()
    warn = [ln for ln in err.splitlines() if "warning" in ln]
    assert len(warn) == 1 and "no finite answer for 3 of 300 single-feature rows" in warn[0]
    assert "DD MAPE" in err  # the metrics still cover the answered rows


def test_help_documents_the_exit_status(cli):
    res = cli("predict", "--help")
    assert res.returncode == 0 and "exit status: 0 written" in " ".join(res.stdout.split())
