"""The study over measured eyes: reshaped pairs, their points, their table, the command."""

from __future__ import annotations

import math

import numpy as np
import pytest

from eyeviz import EyevizError
from eyeviz.cli import main
from eyeviz.study.kinds import columns_of, open_table
from eyeviz.study.point import DesignPoint3D, evaluate3d
from eyeviz.study.point_measured import (
    COLUMNS_MEASURED,
    DesignPointMeasured,
    StudyTableMeasured,
    _shipped,
    measured_grid,
    reshape_pair,
)

EYE = "BT_77973-real.eye"  # the smallest shipped pair (1889 facets per eye)


def test_reshape_keeps_a_fraction_and_widens_the_baseline():
    real = _shipped(EYE)
    half = reshape_pair(real, 0.5, 2.0)
    assert half.facet_counts == (round(0.5 * real.eye_a.n), round(0.5 * real.eye_b.n))
    assert half.h == pytest.approx(2 * reshape_pair(real, 0.5, 1.0).h)
    # each eye is translated, not deformed: lens spread about its centroid unchanged
    assert half.l == pytest.approx(reshape_pair(real, 0.5, 1.0).l)
    idx = np.sort(np.random.default_rng(0).permutation(real.eye_a.n)[: half.eye_a.n])
    assert np.array_equal(half.eye_a.axes, real.eye_a.axes[idx])
    assert np.allclose(half.eye_a.acceptance * math.sqrt(0.5), real.eye_a.acceptance[idx])
    same = reshape_pair(real, 1.0, 1.0)
    assert same.fingerprint == real.fingerprint


def test_a_point_evaluates_into_its_table(tmp_path):
    pts = measured_grid(EYE, "1,0.5", "2", n=30, seed=2)
    assert [(p.facets, p.widen) for p in pts] == [(1.0, 2.0), (0.5, 2.0)]
    assert pts[1].m == round(0.5 * 1889) and pts[0].r_max == pytest.approx(51.3608, rel=1e-4)
    assert pts[1].gamma > pts[0].gamma  # fewer facets: a coarser interommatidial angle
    rows = evaluate3d(pts[1])
    assert tuple(rows[0]) == COLUMNS_MEASURED == columns_of(pts[1])
    assert rows[0]["bin"] == "all" and rows[0]["count"] == 30
    assert rows[0]["h"] == pytest.approx(2 * reshape_pair(_shipped(EYE), 0.5, 1.0).h)
    path = tmp_path / "m.csv"
    table = open_table(path, pts)
    assert isinstance(table, StudyTableMeasured)
    table.append(rows)
    again = StudyTableMeasured.open(path)  # every line through the one parser
    assert again.keys == {pts[1].key}
    with pytest.raises(EyevizError, match="measured study table"):
        open_table(path, [])  # the planar study refuses it


def test_a_tampered_row_is_named(tmp_path):
    rows = evaluate3d(DesignPointMeasured(EYE, 0.5, 1.0, 10.3, 51.4, 5.1, n=20, seed=1))
    path = tmp_path / "m.csv"
    StudyTableMeasured.open(path).append(rows)
    text = path.read_text().splitlines()
    cut = text[1].split(",")
    cut[COLUMNS_MEASURED.index("gamma")] = "0.5"
    path.write_text("\n".join([text[0], ",".join(cut), *text[2:]]) + "\n")
    with pytest.raises(EyevizError, match="line 2: gamma = 0.5 is not the eyes'"):
        StudyTableMeasured.open(path)


@pytest.mark.parametrize(
    "kw, words",
    [({"facets": 0.0}, "facets must be"), ({"widen": 0.1}, "widen must be"),
     ({"eye": "../x.eye"}, "shipped eye"), ({"eye": "none.eye"}, "no shipped eye")],
)  # fmt: skip
def test_bad_points(kw, words):
    base = {"eye": EYE, "r_min": 10.0, "r_max": 50.0, "g_max": 5.0, "n": 10}
    with pytest.raises(EyevizError, match=words):
        DesignPointMeasured(**{**base, **kw})
    assert DesignPoint3D().key  # the other kinds unchanged


def test_command_refuses_reshaping_without_an_eye(tmp_path, capsys):
    out = tmp_path / "s.csv"
    assert main(["study", "-o", str(out), "--widen", "2"]) == 2
    assert "need --eye" in capsys.readouterr().err
    assert main(["study", "-o", str(out), "--eye", EYE, "--nside", "8"]) == 2
    assert "--eye is the measured study" in capsys.readouterr().err
    assert not out.exists()


@pytest.mark.slow
def test_the_runner_runs_a_measured_study(tmp_path, capsys):
    out = tmp_path / "s.csv"
    args = ["study", "-o", str(out), "--eye", EYE, "--facets", "0.5", "--widen", "1,2",
            "--n", "20", "--seed", "5", "--workers", "1", "--no-progress"]  # fmt: skip
    assert main(args) == 0
    assert "2 point(s) computed" in capsys.readouterr().out
    assert len(StudyTableMeasured.open(out).keys) == 2
    assert main(args) == 0  # resumed: nothing left
    assert "0 point(s) computed, 2 skipped" in capsys.readouterr().out
