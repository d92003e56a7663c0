"""`eyeviz report information`: a Cramer-Rao bound on distance from graded responses."""

from __future__ import annotations

import argparse
import csv
import itertools
import math
from pathlib import Path

import numpy as np
import pytest
from scipy import sparse

from eyeviz.reports import information
from eyeviz.reports import information_measure as M
from eyeviz.reports.errors import with_error


def _linear_fn(a: np.ndarray, b: np.ndarray):
    """Responses R_j(theta) = a_j . theta + b_j of a few facets (exact derivatives)."""

    def fn(t: np.ndarray) -> sparse.csr_matrix:
        return sparse.csr_matrix(t @ a.T + b)

    return fn


def test_bound_matches_the_fisher_algebra() -> None:
    # theta = (x, y, g); three facets with linear responses: J = sum a a^T / R
    a = np.array([[0.01, 0.002, 0.03], [-0.004, 0.01, 0.02], [0.003, -0.006, 0.05]])
    b = np.array([0.2, 0.3, 0.1])
    theta = np.array([[3.0, 4.0, 1.0], [6.0, 1.0, 2.0]])
    c, change, unresolved = M.crb_distance(_linear_fn(a, b), theta, np.zeros(2))
    for i, t in enumerate(theta):
        R = a @ t + b
        J = (a[:, :, None] * a[:, None, :] / R[:, None, None]).sum(0)
        grad = np.r_[t[:2] / np.linalg.norm(t[:2]), 0.0]
        assert c[i] == pytest.approx(grad @ np.linalg.solve(J, grad), rel=1e-6)
    assert unresolved == 0 and change.max() < 1e-6
    # two facets for three unknowns: no bound
    c2, _, _ = M.crb_distance(_linear_fn(a[:2], b[:2]), theta, np.zeros(2))
    assert np.isinf(c2).all()


@pytest.fixture(scope="module")
def planar() -> M.ModelResult:
    return M.measure_planar(20, seed=3)


def test_planar_bound(planar: M.ModelResult) -> None:
    assert planar.n_balls == 20 and planar.dropped == 0
    assert np.isfinite(planar.crb1).all() and (planar.crb1 > 0).all()
    assert planar.fd_change < 1e-5
    # the bound falls as 1 / sqrt(N)
    assert planar.graded_rms(4000) == pytest.approx(planar.graded_rms(1000) / 2, rel=1e-12)
    # the crossover is where the two RMS errors meet
    n = planar.crossover
    assert 1 < n < 1e4
    assert planar.graded_rms(n) == pytest.approx(planar.binary_rms, rel=1e-9)
    assert 0.01 < planar.binary_rms < 0.5


def test_tables(planar: M.ModelResult) -> None:
    e = M.ball_bootstrap(planar)
    md = information._markdown([planar], 1000.0, [e])
    assert "the paper's planar design" in md and "information limit (limit)" in md
    table, balls = information._csv([planar], 1000.0, [e])
    row = next(csv.DictReader(table.splitlines()))
    assert float(row["crossover_rms"]) == pytest.approx(planar.crossover, rel=1e-5)
    assert len(balls.splitlines()) == 21
    # every figure has its bootstrap error, in the CSV and (to its precision) in the table
    se = {
        "binary_rms_se": e.se["binary_rms"],
        "binary_median_se": e.se["binary_median"],
        "graded_rms_at_n_se": e.se["graded_rms"] / math.sqrt(1000),
        "graded_median_at_n_se": e.se["graded_median"] / math.sqrt(1000),
        "crossover_rms_se": e.se["crossover"],
        "crossover_median_se": e.se["crossover_median"],
    }
    for key, v in se.items():
        assert v > 0 and float(row[key]) == pytest.approx(v, rel=1e-2), key
    assert float(row["crossover_rms_low"]) < planar.crossover < float(row["crossover_rms_high"])
    cells = md.splitlines()[-1].split(" | ")
    assert cells[4] == with_error(100 * planar.binary_rms, 100 * e.se["binary_rms"]) + " %"
    graded = planar.graded_rms(1000.0)
    assert cells[6] == with_error(100 * graded, 100 * se["graded_rms_at_n_se"]) + " %"
    med = planar.binary_median, planar.graded_median(1000.0)
    assert cells[5] == with_error(100 * med[0], 100 * e.se["binary_median"]) + " %"
    assert cells[7] == with_error(100 * med[1], 100 * se["graded_median_at_n_se"]) + " %"
    assert cells[10].startswith(f"{planar.crossover:.3g} (")
    # the ratio at N is sqrt(N / N*), its interval N*'s interval mapped
    lo, hi = (math.sqrt(1000 / x) for x in (e.high["crossover"], e.low["crossover"]))
    assert cells[8] == f"{planar.binary_rms / graded:.3g}x ({lo:.3g}-{hi:.3g})"


def _exact_bootstrap_sd(m: M.ModelResult) -> dict[str, float]:
    """The standard deviation of each statistic over every one of the n^n equally likely
    resamples of the balls: the exact bootstrap, written out directly."""
    ok = m.ok
    vals = []
    for idx in itertools.product(range(int(ok.sum())), repeat=int(ok.sum())):
        sub = M.ModelResult(
            "t", "t", "cell", "b", len(idx), m.r[ok][list(idx)], m.crb1[ok][list(idx)],
            m.binary_rel[ok][list(idx)], 0.0, 0.0,
        )  # fmt: skip
        vals.append(
            [sub.binary_rms, sub.graded_rms(1.0), sub.binary_median, sub.graded_median(1.0),
             sub.crossover, sub.crossover_median]
        )  # fmt: skip
    return dict(zip(M.STATS, np.std(np.array(vals), axis=0), strict=True))


def test_ball_bootstrap_matches_the_exact_bootstrap() -> None:
    # five balls with a bound and a binary answer, one without a bound (left out)
    r = np.array([100.0, 200.0, 300.0, 400.0, 500.0, 600.0])
    crb1 = np.array([4.0, 90.0, 10.0, 400.0, 30.0, np.inf])
    rel = np.array([0.02, -0.1, 0.05, 0.3, -0.01, 0.2])
    m = M.ModelResult("t", "t", "cell", "b", 6, r, crb1, rel, 0.0, 0.0)
    exact = _exact_bootstrap_sd(m)
    got = M.ball_bootstrap(m, n_boot=20000, seed=1)
    for k in M.STATS:
        # Monte Carlo error of a standard deviation from 20,000 resamples: about 1 %
        assert got.se[k] == pytest.approx(exact[k], rel=0.05), k
        assert got.low[k] < got.high[k], k
    assert got.low["crossover"] <= m.crossover <= got.high["crossover"]
    # the graded errors scale as 1 / sqrt(N), as the figures do
    assert got.graded_rms_se(400.0) == pytest.approx(got.se["graded_rms"] / 20, rel=1e-12)
    # the same seed gives the same errors; a single ball has none
    assert M.ball_bootstrap(m, n_boot=200, seed=3) == M.ball_bootstrap(m, n_boot=200, seed=3)
    one = M.ModelResult("t", "t", "cell", "b", 1, r[:1], crb1[:1], rel[:1], 0.0, 0.0)
    assert all(math.isnan(v) for v in M.ball_bootstrap(one).se.values())


def test_bad_photons_exit_2_in_one_line(tmp_path: Path, eyeviz_main) -> None:
    res = eyeviz_main("report", "information", "-o", tmp_path / "x", "--photons", "0")
    assert res.returncode == 2
    assert res.stderr.strip() == "eyeviz: error: --photons must be > 0 and <= 1e12, got 0.0"
    assert not (tmp_path / "x").exists()


@pytest.mark.slow
def test_report_writes_its_files(tmp_path: Path, eyeviz_main) -> None:
    out = tmp_path / "r"
    args = ["--planar-balls", "20", "--bee-balls", "6", "--healpix-balls", "0"]
    res = eyeviz_main("report", "information", "-o", out, *args)
    assert res.returncode == 0, res.stderr
    rows = list(csv.DictReader((out / "information.csv").read_text().splitlines()))
    assert [r["model"] for r in rows] == ["planar", "honeybee"]
    assert all(math.isfinite(float(r["crossover_rms"])) for r in rows)
    assert (out / "information.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert (out / "information.pdf").read_bytes()[:5] == b"%PDF-"
    assert "grades win from" in res.stdout


def test_bad_arguments_are_refused() -> None:
    args = argparse.Namespace(planar_balls=0, bee_balls=0, healpix_balls=0, nside=180, photons=10.0)
    with pytest.raises(ValueError, match="nothing to measure"):
        information._check(args)
    args.planar_balls, args.nside = 5, 7
    with pytest.raises(ValueError, match="--nside must be an even integer >= 2 and <= 1024, got 7"):
        information._check(args)


@pytest.mark.slow  # 36 response calls of the numpy reference: seconds
def test_healpix_bound_from_the_exact_cell_responses() -> None:
    """The HEALPix side's graded bound comes from the pair's own ``cell`` responses (no
    stand-in): its finite differences settle, and it falls with the cells' size."""
    from eyeviz.core.geometry3d import EyePair3D

    theta = np.array([[30.0, 400.0, 20.0, 15.0]])
    c = {}
    for nside in (8, 16):
        pair = EyePair3D(40.0, 20.0, nside)
        fn = M.healpix_fn(pair)
        got = fn(theta).toarray()
        (ia, ja, va), _ = pair.responses(*theta.T, kind="cell")
        np.testing.assert_array_equal(got[0, ja[ia[0] : ia[1]]], va[ia[0] : ia[1]])
        c[nside], change, unresolved = M.crb_distance(fn, theta, np.zeros(3))
        assert np.isfinite(c[nside]).all() and unresolved == 0 and change.max() < 1e-3
    assert (c[16] < c[8]).all()
