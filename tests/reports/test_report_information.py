"""`eyeviz report information`: a Cramer-Rao bound on distance from graded responses."""

from __future__ import annotations

import argparse
import csv
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from scipy import sparse

from eyeviz.reports import information
from eyeviz.reports import information_measure as M


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
    md = information._markdown([planar], 1000.0)
    assert "the paper's planar design" in md and "information limit (limit)" in md
    table, balls = information._csv([planar], 1000.0)
    row = next(csv.DictReader(table.splitlines()))
    assert float(row["crossover_rms"]) == pytest.approx(planar.crossover, rel=1e-5)
    assert len(balls.splitlines()) == 21


def test_bad_photons_exit_2_in_one_line(tmp_path: Path) -> None:
    res = subprocess.run(
        [sys.executable, "-m", "eyeviz", "report", "information", "-o", str(tmp_path / "x")]
        + ["--photons", "0"],
        capture_output=True,
        text=True,
    )
    assert res.returncode == 2
    assert res.stderr.strip() == "eyeviz: error: --photons must be > 0 and <= 1e12, got 0.0"
    assert not (tmp_path / "x").exists()


@pytest.mark.slow
def test_report_writes_its_files(tmp_path: Path) -> None:
    out = tmp_path / "r"
    args = ["--planar-balls", "20", "--bee-balls", "6", "--healpix-balls", "0"]
    res = subprocess.run(
        [sys.executable, "-m", "eyeviz", "report", "information", "-o", str(out), *args],
        capture_output=True,
        text=True,
    )
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
