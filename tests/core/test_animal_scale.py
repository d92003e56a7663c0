"""The prior at the animal's scale: lengths in mm or baselines (eyeviz.core.animal_scale)
and ``eyeviz generate --eye`` taking them."""

from __future__ import annotations

import math

import numpy as np
import pytest

from eyeviz import EyevizError
from eyeviz.cli import main
from eyeviz.core.animal_scale import (
    Length,
    baseline,
    describe_prior,
    parse_length,
    prior_ranges,
    to_mm,
)
from eyeviz.core.domain import Domain3D, measured_ranges
from eyeviz.core.geometry3d import EyePair3D
from eyeviz.core.measured_from import as_measured


@pytest.fixture(scope="module")
def pair():
    return as_measured(EyePair3D(1.5, 0.5, 4))


@pytest.mark.parametrize(
    "text, value, unit",
    [
        ("30", 30.0, "mm"),
        ("30mm", 30.0, "mm"),
        ("12b", 12.0, "b"),
        (" 1e1 b ", 10.0, "b"),
        (2.5, 2.5, "mm"),
    ],
)
def test_parse_length(text, value, unit):
    assert parse_length(text) == Length(value, unit)


@pytest.mark.parametrize("text", ["x", "3km", "-3", "0b", "nan", "inf", "b", "", True, None])
def test_parse_length_refuses(text):
    with pytest.raises(EyevizError, match="--r-max"):
        parse_length(text, "--r-max")


def test_baselines_are_twice_h(pair):
    assert baseline(pair) == pytest.approx(3.0)
    assert to_mm("4b", pair) == pytest.approx(12.0)
    assert to_mm("4", pair) == 4.0
    got = prior_ranges(pair, r_min="2b", r_max=20.0, g_max=None, el_max=0.5)
    assert got == {"r_min": pytest.approx(6.0), "r_max": 20.0, "g_max": None, "el_max": 0.5}
    with pytest.raises(EyevizError, match="unknown range 'h'"):
        prior_ranges(pair, h=1)


def test_defaults_in_baselines(pair):
    d = Domain3D.for_eyes(pair, **prior_ranges(pair))
    assert (d.r_min, d.r_max, d.g_max) == pytest.approx(
        tuple(measured_ranges(pair)[k] for k in ("r_min", "r_max", "g_max"))
    )
    p = describe_prior(d)
    # r_max = h / dphi, so r_max / b = 1 / (2 dphi)
    assert p["r_max_b"] == pytest.approx(1 / (2 * d.gamma))
    assert p["r_min_b"] == pytest.approx(p["r_max_b"] / 5)
    assert p["el_max_deg"] == pytest.approx(90.0) and p["b_mm"] == pytest.approx(3.0)


def test_generate_eye_takes_baselines(tmp_path, capsys):
    from eyeviz.dataset.sparse3d import load3d
    from eyeviz.files.eye_io import save_eyes

    eye = save_eyes(as_measured(EyePair3D(1.5, 0.5, 4)), tmp_path / "p.eye")
    out = tmp_path / "d.npz"
    args = ["generate", "--eye", str(eye), "-n", "20", "-o", str(out), "--seed", "3"]
    assert main([*args, "--r-min", "1b", "--r-max", "2b", "--g-max", "0.5b"]) == 0
    assert "[1, 2] b" in capsys.readouterr().out
    ds = load3d(out)
    assert ds.domain.r_min == pytest.approx(3.0) and ds.domain.r_max == pytest.approx(6.0)
    assert ds.domain.g_max == pytest.approx(1.5)
    assert np.all((ds.r >= 3.0) & (ds.r <= 6.0))


def test_model_eyes_refuse_baselines(tmp_path, capsys):
    out = tmp_path / "d.csv"
    assert main(["generate", "-n", "5", "-o", str(out), "--r-max", "4b"]) == 2
    err = capsys.readouterr().err.strip()
    assert "are for --eye" in err and len(err.splitlines()) == 1
    assert not out.exists()
    assert math.isfinite(Length(1.0).value)
