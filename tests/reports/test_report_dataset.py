"""``eyeviz report dataset``: PNG, Markdown and CSV summary of data sets."""

from __future__ import annotations

import csv
import subprocess
import sys

import pytest

from eyeviz import dataset as D

EYEVIZ = [sys.executable, "-m", "eyeviz"]


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    d = tmp_path_factory.mktemp("ds")
    D.write(d / "single.npz", 20000, seed=1)
    D.write(d / "multi.csv", 20000, seed=1, mode="multi")
    return d


@pytest.mark.slow
def test_report_side_by_side(files, tmp_path, eyeviz_main):
    out = tmp_path / "rep"
    res = eyeviz_main(  # in this process: the report's files are the point
        "report",
        "dataset",
        files / "single.npz",
        files / "multi.csv",
        "--labels",
        "one pass",
        "multi-pass",
        "-o",
        out,
    )
    assert res.returncode == 0, res.stderr
    png = (out / "dataset.png").read_bytes()
    assert png[:8] == b"\x89PNG\r\n\x1a\n" and len(png) > 50_000
    # 300 dpi (was 110): the pHYs chunk holds pixels per metre
    phys = png.index(b"pHYs")
    ppm = int.from_bytes(png[phys + 4 : phys + 8], "big")
    assert round(ppm * 0.0254) == 300
    # and as vectors, text kept as text
    svg = (out / "dataset.svg").read_text()
    assert svg.lstrip().startswith("<?xml") and "<text" in svg and "Data set distribution" in svg
    assert (out / "dataset.pdf").read_bytes()[:5] == b"%PDF-"
    assert "dataset.svg" in res.stdout and "dataset.pdf" in res.stdout
    with open(out / "dataset.csv") as f:
        rows = list(csv.DictReader(f))
    assert [r["label"] for r in rows] == ["one pass", "multi-pass"]
    single, multi = rows
    assert single["mode"] == "single" and int(single["n"]) == 20000
    assert single["mode_source"] == "recorded"
    # a CSV does not record how it was made: inferred from r ("unknown" before)
    assert (multi["mode"], multi["mode_source"]) == ("multi", "inferred")
    # one pass: flat in r, so the density per area halves from inner to outer half
    assert float(single["area_density_ratio"]) == pytest.approx(0.5, abs=0.05)
    # multi-pass: uniform over the BFV area
    assert float(multi["area_density_ratio"]) == pytest.approx(1.0, abs=0.05)
    md = (out / "dataset.md").read_text()
    assert "![r histograms and centres](dataset.png)" in md and "| multi-pass | 20,000 |" in md
    assert "| multi (*inferred*) |" in md
    assert not [p for p in out.iterdir() if p.name.endswith(".part")]


def test_report_bad_input(files, tmp_path):
    res = subprocess.run(
        [
            *EYEVIZ,
            "report",
            "dataset",
            str(files / "single.npz"),
            "--labels",
            "a",
            "b",
            "-o",
            str(tmp_path / "r"),
        ],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert res.returncode == 2 and "one label per data set" in res.stderr
    res = subprocess.run(
        [*EYEVIZ, "report", "dataset", str(tmp_path / "none.csv"), "-o", str(tmp_path / "r")],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert res.returncode == 2 and "no such data set file" in res.stderr
    assert "Traceback" not in res.stderr and not (tmp_path / "r").exists()


def test_summary_is_streamed_and_matches_the_whole_file(files, monkeypatch):
    """summarise reads blocks (never the whole data set) and agrees with the figures
    computed on the loaded rows, including the exact count of distinct bitmap pairs."""
    import numpy as np

    from eyeviz.dataset import reader as R
    from eyeviz.reports import dataset as rep

    whole = D.load(files / "single.npz")
    keys = np.concatenate([np.packbits(whole.omega_a, 1), np.packbits(whole.omega_b, 1)], 1)
    distinct = len(np.unique(keys, axis=0))
    real = R.iter_blocks
    monkeypatch.setattr(rep, "_reader", lambda p: real(p, block_rows=997))
    monkeypatch.setattr(D, "load", lambda *a, **k: pytest.fail("report loaded a whole file"))
    s = rep.summarise(files / "single.npz", "x")
    assert s.n == len(whole) and s.distinct_pairs == distinct
    assert s.r_min == whole.r.min() and s.r_max == whole.r.max()
    assert s.r_mean == pytest.approx(whole.r.mean(), rel=1e-12)
    assert s.g_max == whole.g.max() and s.phi_min_deg == pytest.approx(np.degrees(whole.phi.min()))


@pytest.mark.parametrize(
    ("flag", "value", "match"),
    [
        ("--bins", "1000000000", "bins must be an integer"),
        ("--max-points", "0", "--max-points must be"),
    ],
)
def test_bins_and_points_are_bounded(files, tmp_path, flag, value, match):
    res = subprocess.run(
        [*EYEVIZ, "report", "dataset", str(files / "single.npz"), flag, value, "-o", str(tmp_path)],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert res.returncode == 2 and match in res.stderr, res.stderr
    assert len(res.stderr.strip().splitlines()) == 1


@pytest.mark.parametrize(
    ("ratio", "n", "want"),
    [
        (0.5, 20000, "single"),  # 1000..5000: flat r gives (1000 + 3000) / (3000 + 5000)
        (0.56, 20000, "single"),
        (1.0, 20000, "multi"),
        (0.93, 20000, "multi"),
        (0.7, 20000, "unknown"),  # neither
        (0.3, 20000, "unknown"),  # fewer far rows than a single pass (--unique-bitmaps)
        (1.0, 500, "unknown"),  # too few rows
        (float("nan"), 20000, "unknown"),
    ],
)
def test_infer_mode(ratio, n, want):
    from eyeviz.reports.dataset import infer_mode

    assert infer_mode(ratio, 1000.0, 5000.0, n) == want


def test_a_single_pass_csv_is_inferred_single(tmp_path):
    from eyeviz.reports.dataset import summarise

    D.write(tmp_path / "s.csv", 20000, seed=3)
    s = summarise(tmp_path / "s.csv", "s")
    assert (s.mode, s.mode_source) == ("single", "inferred")
