"""The 3D study's distance bands (issue 38.3): bins merged into wider bands keep the exact
mean over the band's balls and a sampling error that agrees with a bootstrap over them;
the law is fitted only on bins whose stated error is at most 5 % of their DD; the report
and the table script take the bands."""

import json
import math
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from eyeviz import EyevizError
from eyeviz.estimators.metrics import bootstrap_se
from eyeviz.reports.study_design import Design3D, band_designs, merge_bins
from eyeviz.reports.study_law import REL_MAX, law_points3d
from eyeviz.study.point import BIN_WIDTH

ROOT = Path(__file__).resolve().parents[2]


def _bins_of(r, err, edges):
    """The table's distance rows for balls at distances ``r`` with errors ``err`` (%)."""
    out = []
    for i in range(edges.size - 1):
        sel = (r >= edges[i]) & (r < edges[i + 1])
        e = err[sel]
        out.append({
            "bin": f"r{i}", "lo": float(edges[i]), "hi": float(edges[i + 1]),
            "count": int(sel.sum()), "flagged": int(sel.sum() // 50),
            "dd_mape": float(e.mean()), "dd_se": bootstrap_se(e),
            "ad_mape": float(2 * e.mean()), "el_mae_deg": float(e.mean() / 100),
            "el_se": bootstrap_se(e / 100), "az_mae_deg": float(e.mean() / 50),
        })  # fmt: skip
    return out


def test_a_band_is_the_mean_over_its_balls_with_their_bootstrap_error():
    rng = np.random.default_rng(3)
    r = rng.uniform(1000, 5000, 8000)
    err = rng.lognormal(0, 1.0, r.size) * r / 2000  # heavy-tailed, growing with r
    edges = np.linspace(1000, 5000, 9)
    bins = _bins_of(r, err, edges)
    bands = merge_bins(bins, 2000.0)
    assert [(b["lo"], b["hi"]) for b in bands] == [(1000.0, 3000.0), (3000.0, 5000.0)]
    for b in bands:
        sel = (r >= b["lo"]) & (r < b["hi"])
        assert b["count"] == sel.sum()
        assert b["dd_mape"] == pytest.approx(err[sel].mean(), rel=1e-12)
        assert b["el_mae_deg"] == pytest.approx(err[sel].mean() / 100, rel=1e-12)
        assert b["ad_mape"] == pytest.approx(2 * err[sel].mean(), rel=1e-12)
        assert b["r_mid"] == pytest.approx(
            np.mean(np.floor((r[sel] - 1000) / 500) * 500 + 1250), rel=1e-12
        )
        # the stratified error is the band's own bootstrap error, up to the bootstraps' noise
        assert b["dd_se"] == pytest.approx(bootstrap_se(err[sel]), rel=0.08)
        assert b["flagged"] == sum(x["flagged"] for x in bins if b["lo"] <= x["lo"] < b["hi"])
    # the table's own width leaves the bins as they are
    one = merge_bins(bins, BIN_WIDTH)
    assert [b["dd_mape"] for b in one] == [b["dd_mape"] for b in bins]
    assert [b["dd_se"] for b in one] == pytest.approx([b["dd_se"] for b in bins], rel=1e-12)


def test_an_empty_bin_adds_nothing_and_a_width_off_the_bins_is_refused():
    bins = [
        {"bin": "r0", "lo": 1000.0, "hi": 1500.0, "count": 0, "flagged": 0,
         **dict.fromkeys(("dd_mape", "dd_se", "ad_mape", "el_mae_deg", "el_se",
                          "az_mae_deg"), math.nan)},
        {"bin": "r1", "lo": 1500.0, "hi": 2000.0, "count": 40, "flagged": 0, "dd_mape": 2.0,
         "dd_se": 0.1, "ad_mape": 0.1, "el_mae_deg": 0.01, "el_se": 0.001, "az_mae_deg": 0.01},
    ]  # fmt: skip
    (band,) = merge_bins(bins, 1000.0)
    assert band["count"] == 40 and band["dd_mape"] == 2.0 and band["dd_se"] == pytest.approx(0.1)
    assert band["r_mid"] == 1750.0 and (band["lo"], band["hi"]) == (1000.0, 2000.0)
    for width in (700.0, 250.0, 0.0, math.nan, math.inf):
        with pytest.raises(EyevizError, match="whole multiple of the table's 500-wide") as e:
            merge_bins(bins, width)
        assert "\n" not in str(e.value)


def _design(h, bins):
    all_ = {"n": sum(b["count"] for b in bins), "dd_mape": 1.0, "dd_se": 0.01}
    return Design3D(h, 10.0, 180, 2 * math.pi / 720, all_, bins, [])


def test_the_law_is_fitted_only_on_bins_whose_error_is_under_5_percent():
    def b(i, dd, se):
        return {"bin": f"r{i}", "lo": 1000.0 + 1000 * i, "hi": 2000.0 + 1000 * i,
                "count": 500, "flagged": 0, "dd_mape": dd, "dd_se": se}  # fmt: skip

    d = _design(40.0, [b(0, 0.4, 0.01), b(1, 0.6, 0.6 * REL_MAX * 1.01), b(2, 0.8, math.nan),
                       b(3, 1.0, 0.04)])  # fmt: skip
    # four bins: the first and last are the prior's bounds, the second too imprecise,
    # the third states no error (a version 1 table) and is fitted
    fitted = {p.r: p.fitted for p in law_points3d({d.key: d})}
    assert fitted == {1500.0: False, 2500.0: False, 3500.0: True, 4500.0: False}
    two = _design(40.0, [b(0, 0.4, 0.4 * REL_MAX * 0.99), b(1, 0.6, 0.6 * REL_MAX * 1.01)])
    assert [p.fitted for p in law_points3d({two.key: two})] == [True, False]
    # a band's x is gamma r_mid / (2h) at its own count-weighted r_mid
    fine = [{**b(0, 0.5, 0.01), "bin": f"r{i}", "lo": 1000.0 + 500 * i, "hi": 1500.0 + 500 * i,
             "count": 100 * (i % 4 + 1)} for i in range(8)]  # fmt: skip
    d = _design(40.0, fine)
    pts = law_points3d({d.key: band_designs({d.key: d}, 2000.0)[d.key]})
    r_mid = (100 * 1250 + 200 * 1750 + 300 * 2250 + 400 * 2750) / 1000
    assert [p.r for p in pts] == [r_mid, r_mid + 2000.0] and all(p.fitted for p in pts)
    assert pts[0].x == pytest.approx(2 * math.pi / 720 * r_mid / 80.0)


def _run(*args):
    return subprocess.run(
        [sys.executable, *args],
        capture_output=True,
        text=True,
        cwd=ROOT,
        timeout=120,
        env={**os.environ, "MPLBACKEND": "Agg", "PYTHONPATH": str(ROOT)},
    )


@pytest.fixture(scope="module")
def table3d(tmp_path_factory):
    from eyeviz.study.grid import design_grid3d
    from eyeviz.study.point import evaluate3d
    from eyeviz.study.table import StudyTable3D

    path = tmp_path_factory.mktemp("bands") / "s3.csv"
    for p in design_grid3d("20,40", "10", "16", n=3000, seed=4):
        StudyTable3D.open(path).append(evaluate3d(p))
    return path


def test_the_report_takes_the_bands(table3d, tmp_path):
    from eyeviz.reports.study import write_report

    written = write_report(table3d, tmp_path / "f", band=2000.0)
    assert tmp_path / "f" / "study3d_law.png" in written
    s = json.loads((tmp_path / "f" / "summary3d.json").read_text())
    assert s["band"] == 2000.0 and "5%" in s["fit_rule"]
    assert [(b["h"], b["lo"], b["hi"]) for b in s["bins"]] == [
        (h, lo, hi) for h in (20.0, 40.0) for lo, hi in ((1000.0, 3000.0), (3000.0, 5000.0))
    ]
    assert all(b["count"] > 1000 and b["rel_se"] == pytest.approx(b["dd_se"] / b["dd_mape"])
               for b in s["bins"])  # fmt: skip


def test_the_table_script_marks_every_row_over_5_percent(table3d, tmp_path):
    from eyeviz.reports.study_design import bin_errors, designs3d, read_study3d

    designs = band_designs(designs3d(read_study3d(table3d), "analytic3d", "single"), 2000.0)
    s = {"bins": bin_errors(designs), "designs": [d.all for d in designs.values()]}
    text = _run("scripts/table_study3d.py", str(table3d), "--band", "2000")
    assert text.returncode == 0, text.stderr
    rows = [ln for ln in text.stdout.splitlines() if ln.startswith("| 20 | 10 | 16 |")]
    assert [r.split(" | ")[4] for r in rows] == ["1000-3000", "3000-5000", "all"]
    over = sum(b["rel_se"] > REL_MAX for b in s["bins"])
    over += sum(d["dd_se"] / d["dd_mape"] > REL_MAX for d in s["designs"])
    assert f"{over} row(s) with a relative error above 5%" in text.stdout
    assert text.stdout.count(" * |") == over
    assert "the law over" in text.stdout or "fewer than 2 bands" in text.stdout


def test_a_band_off_the_bins_or_on_a_planar_table_is_one_line(table3d, tmp_path, eyeviz_main):
    out = eyeviz_main("report", "study", table3d, "-o", tmp_path / "f", "--band", "750")
    assert out.returncode != 0
    lines = out.stderr.strip().splitlines()
    assert len(lines) == 1 and "--band must be a whole multiple" in lines[0], out.stderr
    planar = ROOT / "docs" / "study" / "study.csv"
    out = eyeviz_main("report", "study", planar, "-o", tmp_path / "g", "--band", "1000")
    lines = out.stderr.strip().splitlines()
    assert out.returncode != 0 and len(lines) == 1 and "3D study table only" in lines[0]
    assert not (tmp_path / "g").exists()


def _fine_design(h, l_, scale):
    bins = [{"bin": f"r{i}", "lo": 1000.0 + 500 * i, "hi": 1500.0 + 500 * i, "count": 400,
             "flagged": 0, "dd_mape": scale * (i + 1), "dd_se": 0.03 * scale * (i + 1)}
            for i in range(8)]  # fmt: skip
    all_ = {"n": 3200, "dd_mape": 4.5 * scale, "dd_se": 0.1}
    return Design3D(h, l_, 180, 2 * math.pi / 720, all_, bins, [])


def test_the_figures_of_one_nside_draw_a_curve_per_l_and_each_bins_error():
    from matplotlib.container import ErrorbarContainer

    from eyeviz.reports.study_figures import dd_figure, law_figure3d
    from eyeviz.reports.study_law import fit_law

    designs = {d.key: d for d in (_fine_design(40.0, 10.0, 0.2), _fine_design(40.0, 20.0, 0.15),
                                  _fine_design(80.0, 10.0, 0.1))}  # fmt: skip
    points = law_points3d(designs)
    assert all(p.y_se == pytest.approx(0.03 * p.y) for p in points)
    fit = fit_law(points, x_max=math.inf)
    fig = dd_figure(designs, {40.0: 20.0, 80.0: 10.0}, fit, "limit3d")
    ax40, ax80 = fig.axes[:2]
    assert ax40.get_title(loc="left") == "h = 40, l = 10, 20"
    # a curve per l with the bins' error bars, each beside its law line
    bars = [c for c in ax40.containers if isinstance(c, ErrorbarContainer)]
    assert len(bars) == 2
    assert sorted(len(ln.get_xdata()) for ln in ax40.lines if ln.get_marker() == "o") == [8, 8]
    texts = [t.get_text() for t in fig.legends[0].get_texts()]
    assert texts[:2] == ["l = 10, nside 180 (γ = 0.5°)", "l = 20, nside 180 (γ = 0.5°)"]
    assert "standard error" in fig.texts[0].get_text()
    law = law_figure3d(points, fit, None, "limit3d")
    ax = law.axes[0]
    bars = [c for c in ax.containers if isinstance(c, ErrorbarContainer)]
    assert len(bars) == len(points)
    texts = [t.get_text() for t in law.legends[0].get_texts()]
    assert texts[:4] == ["h = 40", "h = 80", "l = 10, nside 180", "l = 20, nside 180"]
