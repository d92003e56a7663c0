"""`eyeviz report estimators`: figures recomputable, unavailable estimators listed, not fatal."""

import csv
import math

import numpy as np
import pytest

from eyeviz.cli import main
from eyeviz.estimators import load, metrics
from eyeviz.reports import estimators as rep


def test_report_writes_md_csv_png_and_lists_missing_paper(tmp_path, no_paper_weights, capsys):
    out = tmp_path / "rep"
    seed = 4242
    assert (
        main(
            [
                "report",
                "estimators",
                "-o",
                str(out),
                "--n-test",
                "300",
                "--estimators",
                "analytic,paper",
                "--seed",
                str(seed),
            ]
        )
        == 0
    )
    assert {p.name for p in out.iterdir()} == {"estimators.md", "estimators.csv", "estimators.png"}
    rows = list(csv.DictReader((out / "estimators.csv").open()))
    by = {(r["estimator"], r["test_set"]): r for r in rows}
    # paper without weights: listed as not trained here, no crash
    paper = [r for r in rows if r["estimator"] == "paper"]
    assert len(paper) == 1 and "not trained here" in paper[0]["status"]
    # Table 5 quoted as a reference row
    t5 = [r for r in rows if r["status"] == "reference"][0]
    assert float(t5["ad_mape_pct"]) == 0.832 and float(t5["dd_mape_pct"]) == 7.713
    # analytic figures equal a direct computation on the same fresh test sets
    sets = rep.make_test_sets(300, seed)
    est = load("analytic")
    for mode in ("single", "multi"):
        row = by[("analytic", mode)]
        d = sets[mode]
        r_hat, phi_hat = est.predict(d.omega_a, d.omega_b)
        assert float(row["dd_mape_pct"]) == pytest.approx(metrics.mape(d.r, r_hat))
        assert float(row["ad_mape_pct"]) == pytest.approx(metrics.mape(d.phi, phi_hat))
        assert float(row["dd_r2"]) == pytest.approx(metrics.r2(d.r, r_hat))
        assert int(row["n"]) == int(row["n_valid"]) == 300
        assert float(row["infer_us_per_sample_batched"]) > 0
        assert float(row["infer_ms_single"]) > 0
        assert row["n_weights"] == "0"
    md = (out / "estimators.md").read_text()
    assert "standard" in md and "not trained here" in md and "Table 5" in md
    assert "estimators.png" in md
    # each estimator described once, from its registry entry
    from eyeviz.estimators import registry

    assert f"- **analytic**: {registry.get('analytic').help}" in md
    assert f"- **paper**: {registry.get('paper').help}" in md
    assert (out / "estimators.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert "unavailable" in capsys.readouterr().out


def test_bad_arguments_are_one_line_errors(tmp_path, capsys):
    assert main(["report", "estimators", "-o", str(tmp_path), "--estimators", "oracle"]) == 2
    err = capsys.readouterr().err
    assert "unknown estimator" in err and "oracle" in err and err.count("\n") == 1
    assert main(["report", "estimators", "-o", str(tmp_path), "--n-test", "3"]) == 2
    assert "--n-test" in capsys.readouterr().err
    assert not list(tmp_path.iterdir())


def test_accuracy_metrics_ignore_nan_rows():
    y = np.array([1000.0, 2000.0, 4000.0])
    got = rep.accuracy_metrics(y, np.array([1100.0, np.nan, 4000.0]))
    assert got["mape"] == pytest.approx(5.0)
    assert math.isnan(rep.accuracy_metrics(y, np.full(3, np.nan))["mape"])


def test_plot_colours_come_from_the_palette_by_name():
    """Every estimator, limit included, has its palette colour in the report figure."""
    from matplotlib.colors import to_hex

    from eyeviz.model.palette import estimator_color

    m = {"ad": {"mape": 1.0}, "dd": {"mape": 7.0}}
    results = [
        rep.Result(n, batched_us=t, single_ms=0.5, metrics={"single": m, "multi": m})
        for n, t in (("limit", 2.0), ("analytic", 0.1), ("bayes", 0.3))
    ]
    fig = rep.plot(results)
    seen = {to_hex(c) for ax in fig.axes for coll in ax.collections for c in coll.get_edgecolors()}
    for name in ("limit", "analytic", "bayes"):
        assert to_hex(estimator_color(name)) in seen, name
    assert rep._COLORS["limit"] == estimator_color("limit")
