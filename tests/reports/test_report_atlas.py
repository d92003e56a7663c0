"""``eyeviz report atlas``: the atlas of measured eyes on a small pair (fast), its
measurements against direct computations, and its bad-input paths."""

from __future__ import annotations

import csv
import math

import numpy as np
import pytest

from eyeviz.cli import main
from eyeviz.core.geometry3d import EyePair3D
from eyeviz.core.measured_from import as_measured
from eyeviz.files.eye_io import load_eyes, save_eyes
from eyeviz.reports import atlas_measure as am

SMALL = [
    "--rows",
    "40",
    "--limit-rows",
    "10",
    "--bins",
    "3",
    "--field-step",
    "6",
    "--estimators",
    "analytic3d",
    "--ball-deg",
    "5",
    "--formats",
    "png",
]


@pytest.fixture(scope="module")
def small_eye(tmp_path_factory):
    """A measured pair of 192 facets per eye (HEALPix nside 4 as lenses and axes)."""
    path = tmp_path_factory.mktemp("eyes") / "small.eye"
    save_eyes(as_measured(EyePair3D(1.5, 0.5, 4)), path)
    return path


@pytest.fixture(scope="module")
def atlas_dir(small_eye, tmp_path_factory):
    out = tmp_path_factory.mktemp("atlas") / "out"
    assert main(["report", "atlas", "-o", str(out), "--eye", str(small_eye), *SMALL]) == 0
    return out


def _rows(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def test_atlas_writes_every_file(atlas_dir):
    names = {p.name for p in atlas_dir.iterdir()}
    for stem in ("atlas_field", "atlas_distance", "atlas_rule", "atlas_scaling", "atlas_angles"):
        assert f"{stem}.png" in names and f"{stem}.svg" not in names  # --formats png
        with open(atlas_dir / f"{stem}.png", "rb") as f:
            assert f.read(8) == b"\x89PNG\r\n\x1a\n"
    md = (atlas_dir / "atlas.md").read_text()
    assert "## small" in md and "atlas_field.png" in md and "Whole atlas" in md


def test_atlas_tables_agree(atlas_dir):
    summary = _rows(atlas_dir / "atlas_summary.csv")
    assert [r["estimator"] for r in summary] == ["analytic3d"]
    s = summary[0]
    assert s["status"] == "ok" and int(s["rows"]) == 40
    assert int(s["facets_a"]) == int(s["facets_b"]) == 192
    assert float(s["b_mm"]) == pytest.approx(3.0)  # 2h: lens centroids at -+1.5 mm
    assert float(s["r_max_b"]) == pytest.approx(float(s["r_max_mm"]) / 3.0, rel=1e-3)
    bins = _rows(atlas_dir / "atlas_bins.csv")
    assert len(bins) == 3 and sum(int(b["count"]) for b in bins) == 40
    # the overall DD is the count-weighted mean of the bins' DD
    dd = sum(int(b["count"]) * float(b["dd_pct"]) for b in bins) / 40
    assert dd == pytest.approx(float(s["dd_pct"]), rel=1e-3)
    field = _rows(atlas_dir / "atlas_field.csv")
    assert len(field) == 2 and all(float(f["solid_angle_sr"]) > 0 for f in field)
    times = {r["step"] for r in _rows(atlas_dir / "atlas_times.csv")}
    assert {"field map", "test set", "analytic3d", "figures", "whole atlas"} <= times


def test_field_counts_are_the_exact_lit_sets(small_eye):
    pair = load_eyes(small_eye)
    lon, lat = am.grid(15.0)
    origin = np.mean(np.array(pair.centers), axis=0)
    na, nb, both = am.field_counts(pair, origin, 5.0, lon, lat, 8.0)
    i = int(np.flatnonzero(both.ravel())[0])
    az, el = np.radians(90 - lon.ravel()[i]), np.radians(lat.ravel()[i])
    c = origin + 5.0 * np.array([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)])
    g = 5.0 * math.sin(math.radians(8.0))
    la, lb = pair.lit(c[0], c[1], c[2], g)
    assert (len(la), len(lb)) == (na.ravel()[i], nb.ravel()[i])
    assert both.ravel()[i] == bool(pair.in_bfv(c[0], c[1], c[2], g))
    ext = am.field_extent(both, na, nb, lon, lat, 15.0)
    assert ext["cells"] == int(both.sum()) and ext["a_median"] >= 2


def test_binned_standard_errors():
    res = am.BallScores(
        "x",
        rows=np.arange(4),
        ape=np.array([0.1, 0.3, 0.2, 0.6]),
        az_deg=np.zeros(4),
        el_deg=np.ones(4),
    )
    r = np.array([1.0, 1.5, 3.0, 4.0])
    rows = am.binned(res, r, np.full(4, 0.5), np.array([1.0, 2.0, 4.0]), b=2.0)
    assert [b["count"] for b in rows] == [2, 2]
    assert rows[0]["dd"] == pytest.approx(20.0)
    assert rows[0]["dd_se"] == pytest.approx(np.std([10, 30], ddof=1) / math.sqrt(2))
    assert rows[1]["lo_b"] == pytest.approx(1.0) and rows[1]["ratio"] == pytest.approx(0.8)
    assert am.slope(np.array([1.0, 2.0, 4.0]), np.array([3.0, 6.0, 12.0])) == pytest.approx(1.0)
    assert math.isnan(am.slope(np.array([1.0]), np.array([1.0])))


def test_local_spacing_is_the_lit_facets_mean(small_eye):
    pair = load_eyes(small_eye)
    lit_a = (np.array([0, 2]), np.array([0, 5]))
    lit_b = (np.array([0, 1]), np.array([7]))
    got = am.local_spacing(pair, lit_a, lit_b)
    sa = am.facet_spacings(pair.eye("A").unit_axes)
    sb = am.facet_spacings(pair.eye("B").unit_axes)
    assert got[0] == pytest.approx((sa[0] + sa[5] + sb[7]) / 3)


@pytest.mark.parametrize(
    "extra, words",
    [
        (["--estimators", "analytic"], "unknown estimator"),
        (["--rows", "0"], "--rows must be an integer >= 1"),
        (["--field-step", "0.01"], "--field-step must be in"),
        (["--r-max", "3km"], "12b (baselines)"),
        (["--eye", "no_such_dir/x.eye"], "not found"),
        (["--eye", "nothing.eye"], "no shipped eye named"),
        (["--r-min", "9b", "--r-max", "2b"], "r_min must be < r_max"),
        (["--ball-deg", "50"], "--ball-deg"),
        (["--formats", "png,jpg"], "--formats takes"),
    ],
)
def test_atlas_bad_input_one_line_exit_2_nothing_written(tmp_path, capsys, small_eye, extra, words):
    out = tmp_path / "out"
    args = ["report", "atlas", "-o", str(out), *SMALL]
    if "--eye" not in extra:
        args += ["--eye", str(small_eye)]
    assert main([*args, *extra]) == 2
    err = capsys.readouterr().err.strip()
    assert words in err and "Traceback" not in err
    assert len([ln for ln in err.splitlines() if ln.startswith("eyeviz")]) == 1
    assert not out.exists() and list(tmp_path.iterdir()) == []


def test_vector_figures_are_written(tmp_path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from eyeviz.reports.atlas_figures import _save

    fig, ax = plt.subplots(figsize=(2, 2))
    ax.plot([0, 1], [1, 0])
    assert _save(fig, tmp_path, "f", ("svg", "pdf")) == tmp_path / "f.svg"
    plt.close(fig)
    assert (tmp_path / "f.svg").read_text().lstrip().startswith("<?xml")
    assert (tmp_path / "f.pdf").read_bytes().startswith(b"%PDF")
