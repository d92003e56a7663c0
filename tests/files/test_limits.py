"""Bounds on sizes a user or a file controls (issue 13): one line and exit 2, before any
work or allocation; the API raises EyevizError."""

from __future__ import annotations

import pytest

from eyeviz import EyevizError
from eyeviz import dataset as D
from eyeviz.files import limits


@pytest.fixture
def run_eyeviz(eyeviz_main):
    """``eyeviz ARGS`` in this process (the exit code and message are the point, not the
    process): (exit code, stderr's lines)."""

    def run(*args, cwd):
        p = eyeviz_main(*args, cwd=cwd)
        return p.returncode, p.stderr.strip().splitlines()

    return run


@pytest.mark.parametrize(
    "args, words",
    [
        (["-n", "10000000000"], "n must be an integer >= 1 and <= 1000000000"),
        (["-n", "1000000000"], "would need about 1.5e+03 GB"),
        (["-n", "10", "--mode", "multi", "--segments", "1000000000"], "segments must be an"),
        (["-n", "10", "--r-min", "1e-300", "--r-max", "1e-299"], "r_min = 1e-300 is below"),
        (["-n", "10", "--r-min", "1e-300"], "r_min = 1e-300 is below"),
        (["-n", "1", "--m", "2000000000"], "m must be an even integer >= 4 and <= 1048576"),
        # a whole float is a count (docs/contract.md), and 1e23 is beyond the bound
        (["-n", "1e23"], "n must be an integer >= 1 and <= 1000000000"),
        (["-n", "inf"], "invalid int value"),
    ],
)
def test_generate_bounds(tmp_path, run_eyeviz, args, words):
    code, err = run_eyeviz("generate", *args, "-o", "x.csv", cwd=tmp_path)
    assert code == 2 and words in err[-1], err
    assert err[-1].startswith("eyeviz")
    assert list(tmp_path.iterdir()) == []


def test_check_functions():
    assert limits.check_rows(5) == 5 and limits.check_rows(5.0) == 5
    for bad in (0, 10**9 + 1, 1e23, float("inf"), float("nan"), 2.5, True, "x", None):
        with pytest.raises(EyevizError):
            limits.check_rows(bad)
    assert limits.check_model_shape("w", (30, 720)) == (30, 720)
    with pytest.raises(EyevizError, match="dimension 30000 outside"):
        limits.check_model_shape("compact", (30000, 720), max_dim=limits.MAX_HIDDEN)
    with pytest.raises(EyevizError, match="parameters exceed"):
        limits.check_model_shape("compact", (30000, 30000))
    with pytest.raises(EyevizError, match="hidden width must be an integer >= 1 and <= 4096"):
        limits.check_hidden("compact", 30000)
    with pytest.raises(EyevizError, match="parameters exceed"):
        limits.check_model_shape("big", (4096, 4096, 4096))


def test_read_bounded(tmp_path):
    p = tmp_path / "a.toml"
    p.write_bytes(b"x" * 100)
    assert limits.read_bounded(p, 100) == b"x" * 100
    with pytest.raises(EyevizError, match="more than 99"):
        limits.read_bounded(p, 99)
    with pytest.raises(EyevizError, match="not a regular file"):
        limits.read_bounded("/dev/zero", 10)


def test_api_generate_bounds():
    with pytest.raises(EyevizError, match="n must be an integer >= 1 and <= 1000000000"):
        D.generate(10**10)
    with pytest.raises(EyevizError, match="segments must be an integer >= 1 and <= 100000"):
        D.make_params(mode="multi", segments=10**9)


@pytest.mark.parametrize(
    "scene, words",
    [
        ("/dev/zero", "is not a regular file"),
        ("m2e9.toml", "eyes.m: m must be an even integer >= 4 and <= 1048576"),
        ("deep.toml", "nested too deeply"),
        ("big.toml", "more than 8388608"),
        ("width.toml", "view.width: must be >= 1e-06"),
        ("nul.toml", "control character"),
    ],
)
def test_snapshot_hostile_scene_files(tmp_path, run_eyeviz, scene, words):
    files = {
        "m2e9.toml": "[eyes]\nm = 2000000000\n",
        "deep.toml": "a = " + "[" * 50_000 + "]" * 50_000 + "\n",
        "big.toml": "# " + "x" * (9 << 20) + "\n",
        "width.toml": "[view]\nwidth = 5e-324\n",
        "nul.toml": '[[features]]\nname = "a\\u0000"\nx = 0.0\ny = 900.0\ng = 5.0\n',
    }
    if scene in files:
        (tmp_path / scene).write_text(files[scene])
    code, err = run_eyeviz("snapshot", scene, "-o", "out.png", cwd=tmp_path)
    assert code == 2 and len(err) == 1 and words in err[0], err
    assert not (tmp_path / "out.png").exists()


def test_files_keep_only_limits_about_files():
    """The model's bounds (m, nside, r, phi) and the run options' live in core.bounds."""
    from eyeviz.core import bounds, validation

    moved = [n for n in dir(bounds) if n.startswith(("MAX_", "MIN_", "check_"))]
    assert "MAX_M" in moved and "check_m" in moved
    assert not [n for n in moved if hasattr(limits, n) and n != "check_int"]
    # one integer checker: limits uses core.validation's, it has none of its own
    assert getattr(limits, "check_int", validation.check_int) is validation.check_int
