"""`eyeviz report trajectories`: Section 6 experiments for every available estimator."""

import csv

import numpy as np
import pytest

from eyeviz.cli import main
from eyeviz.core.geometry import EyePair, intervals_to_bitmap
from eyeviz.estimators import load
from eyeviz.model.trajectories import horizontal
from eyeviz.reports import trajectories as rep


@pytest.mark.slow
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


def test_limit_uses_the_wide_prior_flags_impossible_keys_and_names_low_levels():
    points, missing = rep.measure(
        ["limit"], lo=20, hi=20, kinds=("vertical",), g_values=(5.0, 50.0)
    )
    assert not missing
    by = {(p.g, p.r): p for p in points}
    # g = 5 lies below r sin(gamma/2) beyond r = 1146: the prior cannot draw it
    assert by[(5.0, 9500.0)].n_flagged == by[(5.0, 9500.0)].n
    assert by[(50.0, 9500.0)].n_flagged == 0  # prior r in [1000, 10000] covers g = 50
    assert by[(50.0, 9500.0)].dd_accuracy > by[(5.0, 9500.0)].dd_accuracy - 50
    below = rep.limit_below_paper(points)
    low = [p for p in points if p.dd_accuracy < 70.0]
    assert bool(below) == bool(low)
    for p in low:
        assert any(f"g = {p.g:g}" in s and f"{p.r:g}: {p.dd_accuracy:.1f} %" in s for s in below)
    md = rep.to_markdown(points, {}, ["limit"], 20, 20, {})
    assert "information limit" in md and "r in [1000, 10000]" in md
    assert "n_flagged" in rep.to_csv(points).splitlines()[0]
