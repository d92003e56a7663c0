"""`eyeviz report study`: the study table's reader, the law's fit and the figures written.

The tables are made here: a real one from :func:`eyeviz.study.point.evaluate` on a small
grid (not the study runner), synthetic ones where the law holds exactly.
"""

from __future__ import annotations

import csv
import json
import math
import os
import re
import shutil
import signal
import subprocess
import sys
import time
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest

from eyeviz import EyevizError
from eyeviz.reports import study, study_table
from eyeviz.reports.study_table import COLUMNS, read_study


def write_table(path, rows, header=COLUMNS):
    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=header, extrasaction="ignore")
        w.writeheader()
        for r in rows:
            w.writerow(r)
    return path


def synthetic_rows(C=0.4, hs=(40.0, 80.0, 160.0), ls=(20.0,), ms=(720, 1440, 2880), version=1):
    """Rows of a table where relative DD error = C gamma r_mid / (2h) holds exactly."""
    rows = []
    edges = np.linspace(1000.0, 5000.0, 9)
    for h in hs:
        for l_ in ls:
            if l_ >= h:
                continue
            for m in ms:
                gamma = 2 * math.pi / m
                base = dict(
                    version=version,
                    h=h,
                    l=l_,
                    m=m,
                    gamma=gamma,
                    r_min=1000.0,
                    r_max=5000.0,
                    g_max=500.0,
                    prior="single",
                    n=8000,
                    seed=0,
                    dd_r2=0.9,
                    ad_r2=0.99,
                    flagged=0,
                    seconds=0.1,
                )
                rows.append(
                    {
                        **base,
                        "bin": "all",
                        "r_lo": 1000.0,
                        "r_hi": 5000.0,
                        "count": 8000,
                        "dd_mape": 100 * C * gamma * 3000 / (2 * h),
                        "ad_mape": 0.05 * 720 / m,
                    }
                )
                for i in range(8):
                    lo, hi = edges[i], edges[i + 1]
                    x = gamma * 0.5 * (lo + hi) / (2 * h)
                    rows.append(
                        {
                            **base,
                            "bin": str(i),
                            "r_lo": lo,
                            "r_hi": hi,
                            "count": 1000,
                            "dd_mape": 100 * C * x,
                            "ad_mape": 0.05 * 720 / m,
                        }
                    )
    return rows


@pytest.fixture(scope="module")
def real_table(tmp_path_factory):
    """A small real study: evaluate() on h in {20, 40}, l in {10, 20}, m in {360, 720}."""
    from eyeviz.study.point import DesignPoint, evaluate

    path = tmp_path_factory.mktemp("study") / "study.csv"
    rows = []
    for h in (20.0, 40.0):
        for l_ in (10.0, 20.0):
            if l_ >= h:
                continue
            for m in (360, 720):
                rows += evaluate(DesignPoint(h=h, l=l_, m=m, n=2000, seed=3))
    return write_table(path, rows)


def test_reader_reads_a_real_table(real_table, tmp_path):
    import pandas as pd

    rows = read_study(real_table)
    # the same table written back by pandas (NaN as "") reads the same
    again = tmp_path / "pandas.csv"
    df = pd.read_csv(real_table, dtype={"bin": str})
    df.loc[1, "dd_r2"] = float("nan")  # a missing R^2: pandas writes ""
    df.to_csv(again, index=False)
    assert ",," in again.read_text()
    rows2 = read_study(again)
    assert math.isnan(rows2[1].dd_r2)
    assert [(r.design, r.bin, r.count) for r in rows2] == [(r.design, r.bin, r.count) for r in rows]
    assert [r.dd_mape for r in rows2] == pytest.approx([r.dd_mape for r in rows], nan_ok=True)
    # 3 designs x 2 m x (all + 8 bins)
    assert len(rows) == 6 * 9
    assert {r.design for r in rows} >= {(40.0, 20.0, 720), (20.0, 10.0, 360)}
    assert rows[0].line == 2 and rows[0].bin == "all"


@pytest.mark.slow
def test_report_writes_figures_a_paper_can_use(real_table, tmp_path, eyeviz_main):
    out = tmp_path / "report"
    res = eyeviz_main("report", "study", real_table, "-o", out)
    assert res.returncode == 0, res.stderr
    for stem in ("study_dd", "study_ad", "study_heatmap", "study_law"):
        for ext in ("pdf", "svg", "png"):
            assert (out / f"{stem}.{ext}").stat().st_size > 5000, (stem, ext)
        png = (out / f"{stem}.png").read_bytes()
        assert png[:8] == b"\x89PNG\r\n\x1a\n"
    assert not [p for p in out.iterdir() if p.name.startswith(".")]  # no temporary left

    # SVG: text kept as text (svg.fonttype none); the paper's design named; sizes >= 7 pt
    svg = (out / "study_dd.svg").read_text()
    root = ET.fromstring(svg)
    texts = "".join(root.itertext())
    assert "m = 720" in texts and "m = 360" in texts
    assert "paper's eyes (h 40, l 20, m 720)" in texts
    assert "h = 20, l = 10  (no l 20 at this h)" in texts
    sizes = [float(s) for s in re.findall(r"font-size: ?([0-9.]+)px", svg)]
    assert sizes and min(sizes) >= 7.0 * 0.99  # matplotlib writes pt as px in SVG
    heat = ET.fromstring((out / "study_heatmap.svg").read_text())
    heat_text = "".join(heat.itertext())
    assert "DD limit: MAPE (%) at r = 3000 (bin 3000–3500), l = 20" in heat_text
    assert "20 (l 10)" in heat_text  # h = 20 has no l = 20: its l is stated

    # the table behind the heatmap, and the values written in the cells
    with open(out / "summary.csv") as f:
        summary = list(csv.DictReader(f))
    assert len(summary) == 4  # h in {20, 40} x m in {360, 720}
    paper = next(r for r in summary if r["paper_design"] == "True")
    assert (float(paper["h"]), float(paper["l"]), int(paper["m"])) == (40.0, 20.0, 720)
    rows = read_study(real_table)
    truth = next(
        r for r in rows if r.design == (40.0, 20.0, 720) and r.r_lo == 3000.0 and r.bin != "all"
    )
    assert float(paper["dd_mape"]) == pytest.approx(truth.dd_mape)
    assert study._cell(truth.dd_mape) in heat_text.split()
    assert [study._cell(v) for v in (18.0, 2.5, 0.8641, 123.4)] == ["18.0", "2.50", "0.864", "123"]

    js = json.loads((out / "summary.json").read_text())
    assert 0.1 < js["law"]["C"] < 1.0  # the limit's constant (about 0.36 at n = 20000)
    assert "log space" in js["law"]["method"]
    assert js["paper_design"]["m"] == 720
    assert len(js["heatmap"]) == 4

    if shutil.which("pdftotext"):
        txt = subprocess.run(
            ["pdftotext", str(out / "study_law.pdf"), "-"], capture_output=True, text=True
        ).stdout
        assert "paper's eyes (h 40, l 20, m 720)" in txt
        assert re.search(r"C = 0\.\d+", txt)
    if shutil.which("pdfinfo"):
        info = subprocess.run(
            ["pdfinfo", str(out / "study_dd.pdf")], capture_output=True, text=True
        ).stdout
        w, h = map(float, re.search(r"Page size:\s+([0-9.]+) x ([0-9.]+) pts", info).groups())
        assert w == pytest.approx(7.2 * 72, rel=0.02)  # two printed columns


def test_law_fit_recovers_the_constant_of_a_synthetic_table(tmp_path):
    path = write_table(tmp_path / "s.csv", synthetic_rows(C=0.4))
    designs = study.designs_of(read_study(path), "single")
    pts = study.law_points(designs, x_max=10.0)
    fit = study.fit_law(pts, x_max=10.0)
    assert fit.C == pytest.approx(0.4, rel=1e-9)
    assert fit.log_sd == pytest.approx(0.0, abs=1e-9)
    assert fit.slope == pytest.approx(1.0, abs=1e-9)
    # 9 designs x 6 interior bins (first and last bins are not fitted)
    assert fit.n == 9 * 6
    # a factor 2 noise on half the points: C is the geometric mean, the spread is log 2
    for k, p in enumerate(pts):
        if p.fitted:
            p.y *= 2.0 if k % 2 else 0.5
    fit2 = study.fit_law(pts, x_max=10.0)
    assert fit2.log_sd > 0.5
    assert 0.3 < fit2.C < 0.55


@pytest.mark.slow
def test_report_on_a_synthetic_table_states_c_everywhere(tmp_path):
    path = write_table(tmp_path / "s.csv", synthetic_rows(C=0.25))
    out = tmp_path / "r"
    study.write_report(path, out, law_max=10.0)
    js = json.loads((out / "summary.json").read_text())
    assert js["law"]["C"] == pytest.approx(0.25, rel=1e-9)
    with open(out / "summary.csv") as f:
        for r in csv.DictReader(f):  # the law's prediction beside the measured value
            x = float(r["gamma"]) * 3250 / (2 * float(r["h"]))  # bin 3000-3500
            assert float(r["law_dd_mape"]) == pytest.approx(25 * x, rel=1e-5)
    svg = "".join(ET.fromstring((out / "study_law.svg").read_text()).itertext())
    assert "C = 0.25" in svg
    md = (out / "study.md").read_text()
    assert "C = 0.25" in md and "Fewest ommatidia" in md
    for stem in ("study_dd", "study_ad", "study_heatmap", "study_law"):
        assert f"]({stem}.png)" in md and (out / f"{stem}.png").exists()


def test_formats_chooses_the_figures_files_and_study_md_links_what_was_written(tmp_path):
    path = write_table(tmp_path / "s.csv", synthetic_rows(ms=(720,), hs=(40.0,)))
    out = tmp_path / "r"
    written = study.write_report(path, out, formats=("svg",))
    figures = sorted(p.name for p in out.iterdir() if p.suffix in (".png", ".pdf", ".svg"))
    assert figures == [f"study_{s}.svg" for s in ("ad", "dd", "heatmap", "law")]
    assert sorted(p.name for p in written) == sorted(p.name for p in out.iterdir())
    md = (out / "study.md").read_text()
    assert "](study_dd.svg)" in md and ".png" not in md and "(each as SVG)" in md
    with pytest.raises(EyevizError, match="--formats takes png, svg and pdf, got gif"):
        study.write_report(path, tmp_path / "x", formats=("gif",))
    assert not (tmp_path / "x").exists()


@pytest.mark.slow
def test_one_m_only_still_draws_everything(tmp_path):
    path = write_table(tmp_path / "s.csv", synthetic_rows(ms=(720,), hs=(40.0,)))
    out = tmp_path / "r"
    study.write_report(path, out)
    for stem in ("study_dd", "study_ad", "study_heatmap", "study_law"):
        assert (out / f"{stem}.png").stat().st_size > 5000
    svg = "".join(ET.fromstring((out / "study_heatmap.svg").read_text()).itertext())
    assert "720" in svg


@pytest.mark.slow
def test_a_table_without_the_papers_eyes_says_so(tmp_path):
    path = write_table(tmp_path / "s.csv", synthetic_rows(ms=(1440, 2880)))
    out = tmp_path / "r"
    study.write_report(path, out, formats=("svg",))
    assert "are not in this table" in (out / "study.md").read_text()
    assert json.loads((out / "summary.json").read_text())["paper_design"] is None
    svg = "".join(ET.fromstring((out / "study_dd.svg").read_text()).itertext())
    assert "paper's eyes" not in svg  # nothing claims to mark a design that is absent


# --- bad input -------------------------------------------------------------------------


def _raises(path, match):
    with pytest.raises(EyevizError, match=match) as ei:
        read_study(path)
    assert "\n" not in str(ei.value)
    return str(ei.value)


def test_bad_line_is_named(tmp_path):
    rows = synthetic_rows()
    rows[3]["m"] = "abc"  # the 4th data row: line 5 of the file
    _raises(write_table(tmp_path / "a.csv", rows), r"line 5: m must be an integer")
    rows = synthetic_rows()
    rows[6]["dd_mape"] = "inf"
    _raises(write_table(tmp_path / "b.csv", rows), r"line 8: column dd_mape: must be >= 0")
    rows = synthetic_rows()
    rows[2]["gamma"] = 0.5
    _raises(write_table(tmp_path / "c.csv", rows), r"line 4: gamma = 0.5 is not 2 pi / m")
    rows = synthetic_rows()
    rows[1]["l"] = 50.0
    _raises(write_table(tmp_path / "d.csv", rows), r"line 3: .*l")
    p = write_table(tmp_path / "e.csv", synthetic_rows())
    lines = p.read_text().splitlines()
    lines[9] = lines[9] + ",extra"
    p.write_text("\n".join(lines) + "\n")
    _raises(p, r"line 10: 22 fields, expected 21")
    rows = synthetic_rows()
    rows.append(dict(rows[4]))
    _raises(write_table(tmp_path / "f.csv", rows), r"bin \w+ of this design point appears twice")


def test_other_version_is_refused(tmp_path):
    msg = _raises(write_table(tmp_path / "v.csv", synthetic_rows(version=2)), r"line 2:.*version")
    assert "version 2" in msg and "this is version 1" in msg
    other = (*COLUMNS[:-1], "seconds_total")
    _raises(write_table(tmp_path / "h.csv", synthetic_rows(), other), "another version")
    p = tmp_path / "x.csv"
    p.write_text("a,b\n1,2\n")
    _raises(p, "not a study table")


def test_empty_and_oversized_and_binary_tables(tmp_path, monkeypatch):
    p = tmp_path / "empty.csv"
    p.write_text("")
    _raises(p, "has no rows")
    _raises(write_table(tmp_path / "h.csv", []), "has no rows")
    _raises(tmp_path, "not a regular file")
    big = write_table(tmp_path / "big.csv", synthetic_rows())
    with pytest.raises(EyevizError, match=r"more than 1000"):
        read_study(big, max_bytes=1000)
    monkeypatch.setattr(study_table, "MAX_STUDY_BYTES", 1000)  # the default bound
    _raises(big, r"more than 1000")
    monkeypatch.undo()
    b = tmp_path / "bin.csv"
    b.write_bytes(",".join(COLUMNS).encode() + b"\n\xff\xfe\x00\n")
    _raises(b, "line 2: not UTF-8")


@pytest.mark.slow
def test_cli_one_line_errors_and_nothing_written(tmp_path, eyeviz_main):
    rows = synthetic_rows()
    rows[0]["version"] = 7
    bad = write_table(tmp_path / "bad.csv", rows)
    out = tmp_path / "out"
    for args, want in (
        ([str(bad)], "line 2: written by study version 7"),
        (
            [str(write_table(tmp_path / "ok.csv", synthetic_rows())), "--at", "9000"],
            "--at 9000 lies outside the study's distances [1000, 5000]",
        ),
        ([str(tmp_path / "ok.csv"), "--prior", "multi"], "no rows of prior 'multi'"),
        ([str(tmp_path / "ok.csv"), "--law-max", "-1"], "--law-max must be a finite number"),
        ([str(tmp_path / "ok.csv"), "--at", "nan"], "--at must be a finite number"),
        ([str(tmp_path / "ok.csv"), "--formats", "png,eps"], "--formats takes png, svg and pdf"),
    ):
        res = eyeviz_main("report", "study", *args, "-o", out)
        assert res.returncode == 2, res.stderr
        err = res.stderr.strip()
        assert err.startswith("eyeviz: error:") and want in err and "\n" not in err, err
        assert not out.exists() or not list(out.iterdir())


@pytest.mark.slow
def test_the_prior_is_the_tables_own_unless_chosen(tmp_path):
    rows = [{**r, "prior": "multi"} for r in synthetic_rows(C=0.3)]
    path = write_table(tmp_path / "m.csv", rows)
    study.write_report(path, tmp_path / "a", law_max=10.0, formats=("svg",))
    js = json.loads((tmp_path / "a" / "summary.json").read_text())
    assert js["source"]["prior"] == "multi" and js["law"]["C"] == pytest.approx(0.3)
    both = write_table(tmp_path / "b.csv", rows + synthetic_rows(C=0.2))
    study.write_report(both, tmp_path / "b", law_max=10.0, formats=("svg",))
    js = json.loads((tmp_path / "b" / "summary.json").read_text())
    assert js["source"]["prior"] == "single" and js["law"]["C"] == pytest.approx(0.2)
    with pytest.raises(EyevizError, match="no rows of prior 'single'"):
        study.write_report(path, tmp_path / "c", prior="single")


def test_the_largest_run_of_a_design_is_drawn(tmp_path):
    rows = synthetic_rows(hs=(40.0,), ms=(720,), C=0.4)
    more = [{**r, "n": 16000, "seed": 1, "dd_mape": 2 * float(r["dd_mape"])} for r in rows]
    path = write_table(tmp_path / "s.csv", rows + more)
    d = study.designs_of(read_study(path), "single")[(40.0, 20.0, 720)]
    assert d.all.n == 16000 and d.all.line > 9


# --- an interrupted report (issue 35, item 3) -------------------------------------------


def _report_written(tmp_path, out, before: dict) -> bool:
    """Whether the run has written a figure yet (in its staging folder, or in ``out``)."""
    for p in tmp_path.rglob("*"):
        if p.is_file() and p.suffix in (".pdf", ".png", ".svg") and ".part" not in p.name:
            if p.parent != out or p.stat().st_mtime_ns != before.get(p.name):
                return True
    return False


@pytest.mark.slow
def test_sigint_leaves_the_old_report_folder_unmixed(tmp_path):
    table = write_table(tmp_path / "s.csv", synthetic_rows())
    out = tmp_path / "DIR"
    out.mkdir()
    for name in ("study_dd.pdf", "study_dd.png", "study.md", "summary.json"):
        (out / name).write_text(f"old run: {name}")
    os.utime(out / "study.md", (1e9, 1e9))
    before = {p.name: p.stat().st_mtime_ns for p in out.iterdir()}
    proc = subprocess.Popen(
        [sys.executable, "-m", "eyeviz", "report", "study", str(table), "-o", str(out)],
        cwd=tmp_path,
        env={
            **os.environ,
            "PYTHONPATH": str(Path(__file__).resolve().parents[2]),
            "MPLBACKEND": "Agg",
        },
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    t = time.monotonic()
    while not _report_written(tmp_path, out, before):
        assert proc.poll() is None, proc.communicate()
        assert time.monotonic() - t < 300, "no figure written in 300 s"
        time.sleep(0.02)
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == 130, err
    assert {p.name: p.read_text() for p in out.iterdir()} == {
        name: f"old run: {name}" for name in before
    }
    assert sorted(p.name for p in tmp_path.iterdir()) == ["DIR", "s.csv"]  # no staging left
