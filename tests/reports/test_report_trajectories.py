"""`eyeviz report trajectories`: Section 6 experiments for every available estimator."""

import csv

import numpy as np
import pytest

from eyeviz.cli import main
from eyeviz.core.geometry import EyePair, intervals_to_bitmap
from eyeviz.estimators import load
from eyeviz.model.trajectories import horizontal
from eyeviz.reports import trajectories as rep


def test_report_runs_all_trajectories(tmp_path, no_paper_weights):
    out = tmp_path / "traj"
    assert (
        main(
            [
                "report",
                "trajectories",
                "-o",
                str(out),
                "--estimators",
                "analytic,paper",
                "--min-count",
                "5",
                "--max-count",
                "20",
            ]
        )
        == 0
    )
    names = {p.name for p in out.iterdir()}
    assert names == {
        "trajectories.md",
        "trajectories.csv",
        "trajectories_horizontal.png",
        "trajectories_circular.png",
        "trajectories_vertical.png",
    }
    rows = list(csv.DictReader((out / "trajectories.csv").open()))
    # paper is unavailable; analytic covers 10 lines + 10 circles + 9 segments per g
    assert {r["estimator"] for r in rows} == {"analytic"}
    assert len(rows) == 3 * (10 + 10 + 9)
    for r in rows:
        assert 5 <= int(r["n"]) <= 20 or r["trajectory"] == "vertical"
        assert int(r["n_valid"]) == int(r["n"])
        assert float(r["ad_accuracy_pct"]) > 99.0  # triangulated azimuth is near exact
    near = [r for r in rows if r["trajectory"] == "horizontal" and float(r["r"]) == 1000]
    assert all(float(r["dd_accuracy_pct"]) > 85.0 for r in near)
    md = (out / "trajectories.md").read_text()
    assert "not trained here" in md and "Figure 15" in md and "1.5 r/g" in md


def test_accuracy_is_100_minus_mape_along_a_line():
    points, missing = rep.measure(
        ["analytic"], lo=40, hi=40, kinds=("horizontal",), g_values=(50.0,)
    )
    assert not missing
    p = next(p for p in points if p.r == 3000.0)
    x, y = horizontal(3000.0, 50.0, 40)
    eyes = EyePair(40.0, 20.0, 720)
    LA, RA, LB, RB = eyes.intervals(x, y, 50.0)
    r_hat, phi_hat = load("analytic").predict(
        intervals_to_bitmap(LA, RA, 720, 360), intervals_to_bitmap(LB, RB, 720, 360)
    )
    r = np.hypot(x, y)
    assert p.n == 40
    assert p.dd_accuracy == pytest.approx(100 - 100 * np.mean(np.abs(r_hat - r) / r))


def test_bad_counts(tmp_path, capsys):
    assert main(["report", "trajectories", "-o", str(tmp_path), "--min-count", "0"]) == 2
    assert (
        main(
            [
                "report",
                "trajectories",
                "-o",
                str(tmp_path),
                "--min-count",
                "50",
                "--max-count",
                "10",
            ]
        )
        == 2
    )
    assert "--max-count" in capsys.readouterr().err
