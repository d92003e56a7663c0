"""`eyeviz report stability`: files written, core exact, literal formulas shown wrong."""

from __future__ import annotations

import csv

import pytest

from eyeviz.reports import stability


@pytest.mark.slow
def test_report_writes_table_csv_and_plot(tmp_path, eyeviz_main):
    out = tmp_path / "report"
    res = eyeviz_main("report", "stability", "-o", out, "-n", "150", "--n3d", "1")
    assert res.returncode == 0, res.stderr
    md = (out / "stability.md").read_text()
    assert "| grazing |" in md and "eyeviz core diffs" in md
    with open(out / "stability.csv") as f:
        rows = list(csv.DictReader(f))
    assert len(rows) == 8
    assert all(int(r["diffs eyeviz core"]) == 0 for r in rows)
    # the paper's formulas taken literally fail on the tie classes
    ground = next(r for r in rows if r["case"] == "resting on y = 0")
    assert int(ground["diffs paper float64"]) > 0
    assert int(ground["exact fallbacks"]) > 0
    # issue 14: the ground ties are decided vectorised, none by mpmath, and the old core
    # (timed in the same run) is far slower on them
    assert int(ground["exact ties"]) == int(ground["exact fallbacks"])
    assert int(ground["exact mpmath"]) == 0
    assert float(ground["speed-up vs before"]) > 5
    assert "speed-up vs before" in md and "eyeviz core, before issue 14 µs" in md
    png = (out / "stability.png").read_bytes()
    assert png[:8] == b"\x89PNG\r\n\x1a\n" and len(png) > 20_000
    # the spherical eyes' part: one ball per class, every lit set equal to the reference
    with open(out / "stability3d.csv") as f:
        rows3 = list(csv.DictReader(f))
    assert len(rows3) >= 7 and all(int(r["diffs eyeviz core"]) == 0 for r in rows3)
    assert "spherical eyes): 0" in res.stdout
    assert (out / "stability3d.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert not [p for p in out.iterdir() if p.name.startswith(".")]


def test_bad_n_is_refused_in_one_line(tmp_path, eyeviz_main):
    res = eyeviz_main("report", "stability", "-o", tmp_path, "-n", "0")
    assert res.returncode == 2
    assert res.stderr.strip() == "eyeviz: error: -n must be an integer >= 1 and <= 100000, got 0"


def test_measure_times_every_method():
    rows = stability.measure(n=50, seed=3)
    for r in rows:
        assert set(r.seconds_per_feature) == set(stability.TIMED)
        assert stability.OLD in stability.TIMED
        assert all(t > 0 for t in r.seconds_per_feature.values())
