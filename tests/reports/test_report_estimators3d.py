"""`eyeviz report estimators --nside/--data`: the spherical eyes' estimators report."""

import csv

import numpy as np

from eyeviz.cli import main
from eyeviz.core.domain import Domain3D
from eyeviz.dataset.algorithm1_3d import generate3d
from eyeviz.dataset.sparse3d import write3d
from eyeviz.estimators import registry
from eyeviz.estimators.metrics import mape
from eyeviz.reports.errors import bootstrap_se, with_error


def test_report_on_a_3d_data_file(tmp_path, capsys):
    d = Domain3D(nside=8)
    data = tmp_path / "t3d.npz"
    write3d(data, 60, d, "single", 97)
    out = tmp_path / "rep"
    args = ["report", "estimators", "-o", str(out), "--data", str(data), "--limit-rows", "20"]
    assert main([*args, "--estimators", "analytic3d,limit3d"]) == 0
    printed = capsys.readouterr().out
    assert "analytic3d" in printed and "limit3d" in printed
    for name in ("estimators3d.md", "estimators3d.csv", "estimators3d.png"):
        assert (out / name).stat().st_size > 0
    assert not (out / "estimators.md").exists()  # not the planar report
    rows = {r["estimator"]: r for r in csv.DictReader(open(out / "estimators3d.csv"))}
    assert set(rows) == {"analytic3d", "limit3d"}
    # the analytic row's figures are recomputable from the estimator and the file
    ds = generate3d(60, d, "single", 97)
    p = registry.load("analytic3d", domain=d).predict_dataset(ds)
    assert np.isclose(float(rows["analytic3d"]["all_dd_mape"]), mape(ds.r, p.r), rtol=1e-5)
    sub = np.arange(0, 60, 3)
    assert np.isclose(float(rows["analytic3d"]["subset_dd_mape"]), mape(ds.r[sub], p.r[sub]),
                      rtol=1e-5)  # fmt: skip
    assert rows["limit3d"]["all_dd_mape"] == ""  # the limit: the subset only
    assert float(rows["limit3d"]["subset_dd_mape"]) > 0
    md = (out / "estimators3d.md").read_text()
    assert "| limit3d |" in md and "el MAE deg" in md
    # each figure carries its bootstrap standard error: about sd / sqrt(n) of the rows' terms
    terms = 100 * np.abs(p.r - ds.r) / ds.r
    se = float(rows["analytic3d"]["all_dd_se"])
    assert 0.8 < se / (terms.std(ddof=1) / np.sqrt(60)) < 1.2
    assert with_error(float(rows["analytic3d"]["all_dd_mape"]), se) in md
    line = next(ln for ln in printed.splitlines() if ln.startswith("analytic3d"))
    sub_se = float(rows["analytic3d"]["subset_dd_se"])
    assert with_error(float(rows["analytic3d"]["subset_dd_mape"]), sub_se) in line


def test_report_3d_fresh_set_and_errors(tmp_path, capsys):
    out = tmp_path / "rep"
    base = ["report", "estimators", "-o", str(out)]
    assert main([*base, "--nside", "8", "--n-test", "30", "--estimators", "analytic3d"]) == 0
    assert "nside = 8" in (out / "estimators3d.md").read_text()
    capsys.readouterr()
    assert main([*base, "--nside", "8", "--estimators", "analytic"]) == 2
    err = capsys.readouterr().err
    assert "unknown 3D estimator" in err and err.count("\n") == 1
    assert main([*base, "--nside", "8", "--data", str(tmp_path / "x.npz")]) == 2
    assert "not both" in capsys.readouterr().err


def test_bootstrap_se_is_the_standard_error_of_a_mean():
    rng = np.random.default_rng(5)
    t = rng.exponential(size=2000)
    assert abs(bootstrap_se(t) / (t.std(ddof=1) / np.sqrt(t.size)) - 1) < 0.1
    assert bootstrap_se(t) == bootstrap_se(t)  # a fixed seed: reports are reproducible
    assert np.isnan(bootstrap_se([1.0]))  # one row says nothing about its spread
    assert bootstrap_se(np.full(50, 3.0)) == 0.0


def test_with_error_prints_to_the_precision_the_error_allows():
    assert with_error(0.77512, 0.02634) == "0.775 ± 0.026"
    assert with_error(1.01834, 0.0291) == "1.018 ± 0.029"
    assert with_error(0.0038123, 0.000104) == "0.00381 ± 0.00010"
    assert with_error(1580.4, 37.2) == "1580 ± 37"
    assert with_error(2.0, float("nan")) == "2"


def test_the_figure_draws_each_estimators_standard_error():
    """plot_lit draws every measured estimator's bootstrap error as a bar of +- se about its
    value in each of the three panels (issue 38: the figures carry their errors)."""
    from matplotlib.collections import LineCollection

    from eyeviz.reports.estimators import Result, plot_lit

    keys = ("dd", "ad", "el_mae_deg")
    res = [
        Result(
            name,
            rows=100,
            metrics={"subset": {k: v * (i + 1) for i, k in enumerate(keys)}},
            errors={"subset": {k: se for k in keys}},
            batched_us=10.0,
            single_ms=1.0,
        )
        for name, v, se in (("analytic3d", 1.5, 0.03), ("limit3d", 0.7, 0.02))
    ]
    fig = plot_lit(res)
    for i, ax in enumerate(fig.axes[:3]):
        bars = sorted(
            tuple(np.round(seg[:, 1], 9))
            for c in ax.collections
            if isinstance(c, LineCollection)
            for seg in c.get_segments()
        )
        want = sorted(
            (round(v * (i + 1) - se, 9), round(v * (i + 1) + se, 9))
            for v, se in ((1.5, 0.03), (0.7, 0.02))
        )
        assert bars == want
