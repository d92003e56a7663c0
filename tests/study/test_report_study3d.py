"""`eyeviz report study` on a 3D study table: every figure written and readable, the
summary names the estimator, and the power-law fit recovers known exponents."""

import json
import math
import xml.etree.ElementTree as ET

import numpy as np
import pytest

from eyeviz.reports.study_design import read_study3d
from eyeviz.reports.study_law import LawPoint, fit_power, law_uncertainty
from eyeviz.study import run_study
from eyeviz.study.grid import design_grid3d

STEMS = ("study3d_design", "study3d_dd", "study3d_law", "study3d_elevation")


@pytest.mark.slow
def test_report_study_draws_the_3d_figures_and_opens_them(tmp_path, eyeviz_main):
    pytest.importorskip("distributed")
    import matplotlib.image as mpimg

    table = tmp_path / "s3.csv"
    run_study(
        table, design_grid3d("20,40", "5,10", "16,32", n=800, seed=1), workers=1, progress=False
    )
    out = eyeviz_main("report", "study", table, "-o", tmp_path / "f")
    assert out.returncode == 0, out.stderr
    assert "wrote 13 files" in out.stdout
    for stem in STEMS:
        png = mpimg.imread(tmp_path / "f" / f"{stem}.png")
        assert png.ndim == 3 and png.shape[0] > 300 and png.shape[1] > 300
        assert png[..., :3].std() > 0.05  # not a blank page
        assert (tmp_path / "f" / f"{stem}.pdf").read_bytes().startswith(b"%PDF")
        ET.parse(tmp_path / "f" / f"{stem}.svg")  # well-formed
    s = json.loads((tmp_path / "f" / "summary3d.json").read_text())
    assert s["estimator"] == "analytic3d" and s["is_the_limit"] is False
    assert {(d["h"], d["l"], d["nside"]) for d in s["designs"]} == {
        (h, l_, n) for h in (20, 40) for l_ in (5, 10) for n in (16, 32)
    }
    # every distance bin states its DD's sampling error (issue 38.3), and it is the table's
    assert len(s["bins"]) == 8 * 8 and all(b["dd_se"] > 0 for b in s["bins"])
    one = next(b for b in s["bins"] if (b["h"], b["l"], b["nside"], b["bin"]) == (20, 5, 16, "r3"))
    row = next(
        r
        for r in read_study3d(table)
        if (r["h"], r["l"], r["nside"], r["bin"]) == (20, 5, 16, "r3")
    )
    assert one["dd_se"] == pytest.approx(row["dd_se"]) and one["count"] == row["count"]
    assert one["rel_se"] == pytest.approx(row["dd_se"] / row["dd_mape"])
    law = s["law_slope_1"]  # its bootstrap needs 3 fitted bins (DD <= 10 %: few here)
    assert ("free_slope_se" in law) == (law["n"] >= 3)
    assert law["n"] < 3 or (law["free_slope_se"] > 0 and law["C_factor_se"] > 1)
    nside16 = [d["dd_mape"] for d in s["designs"] if d["nside"] == 16]
    nside32 = [d["dd_mape"] for d in s["designs"] if d["nside"] == 32]
    assert max(nside32) < max(nside16)


def test_the_power_law_fit_recovers_known_exponents():
    rng = np.random.default_rng(0)
    pts = []
    for nside in (16, 32, 64):
        gam = 2 * math.pi / (4 * nside)
        for h in (20.0, 40.0, 80.0):
            for l_ in (5.0, 10.0):
                for r in (1500.0, 2500.0, 3500.0):
                    y = 0.01 * gam**1.5 * r**1.4 * h**-0.8 * l_**-0.1
                    y *= math.exp(rng.normal(0, 1e-3))
                    pts.append(LawPoint(h, l_, 4 * nside, r, gam * r / (2 * h), y, True, False))
    fit = fit_power(pts)
    assert fit is not None and fit["n"] == len(pts)
    for k, want in (("exp_gamma", 1.5), ("exp_r", 1.4), ("exp_h", -0.8), ("exp_l", -0.1)):
        assert fit[k] == pytest.approx(want, abs=0.01), (k, fit)
    # a parameter that does not vary is left out, not fitted
    same_l = [p for p in pts if p.l == 5.0]
    assert fit_power(same_l)["exp_l"] is None


def test_the_laws_bootstrap_error_matches_its_scatter():
    """law_uncertainty: with log-normal scatter sd about y = 0.04 x^1.2 over n bins, the
    bootstrap's spread of the free slope and of log C is the regression's textbook one."""
    rng = np.random.default_rng(3)
    n, sd = 400, 0.2
    x = np.exp(rng.uniform(np.log(0.05), np.log(2.0), n))
    y = 0.04 * x**1.2 * np.exp(rng.normal(0, sd, n))
    pts = [LawPoint(40.0, 20.0, 720, 2000.0, a, b, True, False) for a, b in zip(x, y, strict=True)]
    u = law_uncertainty(pts)
    lx = np.log(x)
    slope_se = sd / math.sqrt(((lx - lx.mean()) ** 2).sum())
    assert u["free_slope_se"] == pytest.approx(slope_se, rel=0.15)
    # slope fixed at 1 while the data's is 1.2: log C's spread includes the misfit
    res = np.log(y) - lx
    assert math.log(u["C_factor_se"]) == pytest.approx(res.std() / math.sqrt(n), rel=0.15)
    assert law_uncertainty(pts[:2]) == {}
    assert law_uncertainty([LawPoint(40.0, 20.0, 720, 2000.0, 1.0, 1.0, False, False)] * 9) == {}


def test_the_report_draws_the_limit_else_the_estimator_of_the_most_designs():
    from eyeviz.reports.study_design import choose_estimator

    def rows(spec):
        return [{"estimator": e, "h": 40.0, "l": 20.0, "nside": n} for e, ns in spec for n in ns]

    tri = ("analytic3d", (16, 32, 64))
    assert choose_estimator(rows([tri, ("learned3d", (180,))])) == "analytic3d"
    assert choose_estimator(rows([tri, ("limit3d", (16,))])) == "limit3d"
    assert choose_estimator(rows([("b", (16,)), ("a", (32,))])) == "a"
