"""`eyeviz report renderers`: sampled against exact responses (issue 34.4)."""

from __future__ import annotations

import argparse
import csv
import math
from pathlib import Path

import pytest

from eyeviz.reports import renderers, renderers_measure


@pytest.fixture(scope="module")
def measured():
    args = argparse.Namespace(balls=400, acceptance=2.6, mc_balls=40, mc_rays=32, seed=5)
    return renderers.measure(args)


def test_biases_and_rays(measured) -> None:
    rows, curves, cdf, example = measured
    by = {r.key: r for r in rows}
    # unbiased samplers: bias at quadrature level, rays for 1 % finite, <= 2500 (q = 1/2)
    for key in ("gauss2d", "uniform-flat"):
        assert by[key].bias_rms < 1e-8
        assert 100 < by[key].rays_for_target <= 2500
        assert by[key].rays_for_target_worst <= 2500
    # the biased ones never reach 1 % on this population
    for key in ("compoundray", "invertpy", "uniform"):
        assert by[key].bias_rms > 0.02 and math.isinf(by[key].rays_for_target)
    assert round(by["compoundray"].within_half_fwhm, 3) == 0.761
    assert round(by["compoundray"].example, 3) == 0.121
    assert round(by["compoundray"].example_exact, 3) == 0.159
    assert example["compoundray"] == by["compoundray"].example
    # the error law falls as 1 / sqrt(N) for an unbiased sampler
    g = by["gauss2d"].rms
    assert g[4096] == pytest.approx(g[1024] / 2, rel=1e-9)
    # the Monte-Carlo check agrees with the closed form
    for r in rows:
        assert r.mc_rms == pytest.approx(r.mc_predicted, rel=0.35)
    assert curves["gaussian"].shape == curves["delta"].shape
    top = cdf["theta"][-1] / (math.radians(2.6) / renderers_measure.S.FWHM_PER_SIGMA)
    assert cdf["compoundray"][-1] == pytest.approx(math.erf(top / math.sqrt(2)), abs=1e-9)


def test_tables(measured) -> None:
    rows, *_, example = measured
    md = renderers._markdown(rows, 2.6, 400, example)
    assert "| CompoundRay (shaders.cu) | gaussian | 76.1% |" in md
    assert "never (bias > 1 %)" in md and "renderers.png" in md
    table, curves = renderers._csv(rows)
    parsed = list(csv.DictReader(table.splitlines()))
    assert [p["sampler"] for p in parsed] == list(renderers_measure.TARGETS)
    assert any(line.startswith("invertpy,7,") for line in curves.splitlines())


@pytest.mark.slow
def test_report_writes_its_files(tmp_path: Path, eyeviz_main) -> None:
    out = tmp_path / "r"
    res = eyeviz_main("report", "renderers", "-o", out, "--balls", "300", "--mc-balls", "20")
    assert res.returncode == 0, res.stderr
    for name in ("renderers.md", "renderers.csv", "curves.csv", "renderers.svg"):
        assert (out / name).stat().st_size > 100
    assert (out / "renderers.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert (out / "renderers.pdf").read_bytes()[:5] == b"%PDF-"
    assert f"wrote {out / 'renderers.md'}" in res.stdout
    assert not [p for p in out.iterdir() if p.name.startswith(".")]


def test_bad_arguments_exit_2_in_one_line(tmp_path: Path, eyeviz_main) -> None:
    res = eyeviz_main("report", "renderers", "-o", tmp_path / "x", "--acceptance", "0")
    assert res.returncode == 2
    assert res.stderr.strip() == "eyeviz: error: --acceptance must be in (0, 180) degrees, got 0.0"
    assert not (tmp_path / "x").exists()
