"""``eyeviz generate --nside``: bad input ends in one line naming the parameter, exit 2,
no traceback and no file; a good run writes the data set the API generates."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from eyeviz import cli
from eyeviz.core.domain import Domain3D
from eyeviz.dataset import algorithm1_3d, sparse3d

SMALL = ["--h", "30", "--l", "10", "--r-min", "100", "--r-max", "400", "--g-max", "60"]


@pytest.mark.parametrize(
    "args, message",
    [
        (["--nside", "7"], "nside must be an even integer >= 2 and <= 1048576, got 7"),
        (["--nside", "0"], "nside must be an even integer >= 2"),
        (["--nside", "8", "--h", "20", "--l", "20"], "l must be < h"),
        (["--nside", "8", "--l", "50"], "l must be < h"),
        (["--nside", "8", "--el-max", "2"], "el_max must be a finite number > 0 and < 1.5708"),
        (["--nside", "8", "--el-max", "0"], "el_max must be a finite number > 0"),
        (["--nside", "8", "--el-max", "nan"], "el_max must be a finite number > 0 and < 1.5708"),
        (["--nside", "8", "--el-max", "-0.2"], "el_max must be a finite number > 0"),
        (["--el-max", "0.3"], "--el-max needs --nside"),
        (["--nside", "8", "--m", "64"], "--m is the planar eye's"),
        (["--nside", "8", "--unique-bitmaps"], "--unique-bitmaps is for the planar"),
        (["--nside", "8", "--g-max", "1"], "no feature can be visible"),
        (["--nside", "8", "--r-min", "500", "--r-max", "400"], "r_min must be < r_max"),
        (["--nside", "8", "--mode", "multi", "--segments", "0"], "segments must be an integer"),
    ],
)
def test_bad_input_is_one_line_exit_2(tmp_path, capsys, args, message):
    out = tmp_path / "x.npz"
    rc = cli.main(["generate", "-n", "10", *args, "-o", str(out)])
    err = capsys.readouterr().err
    assert rc == 2, err
    assert message in err and err.count("\n") == 1 and "Traceback" not in err, err
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("name", ["x.csv", "x.CSV", "x.txt"])
def test_csv_output_refused_for_3d(tmp_path, capsys, name):
    rc = cli.main(["generate", "-n", "10", "--nside", "8", "-o", str(tmp_path / name)])
    err = capsys.readouterr().err
    assert rc == 2 and "written as .npz" in err and err.count("\n") == 1, err
    assert list(tmp_path.iterdir()) == []


def test_n_zero_refused(tmp_path, capsys):
    rc = cli.main(["generate", "-n", "0", "--nside", "8", "-o", str(tmp_path / "x.npz")])
    err = capsys.readouterr().err
    assert rc == 2 and "n must be an integer >= 1" in err and err.count("\n") == 1, err


def test_a_run_writes_what_the_api_generates(tmp_path, capsys):
    out = tmp_path / "x.npz"
    argv = ["generate", "-n", "80", "--nside", "8", "--el-max", "0.3", "--mode", "multi"]
    rc = cli.main([*argv, "--seed", "5", *SMALL, "-o", str(out)])
    text = capsys.readouterr().out
    assert rc == 0 and "wrote 80 3D elements (nside 8, multi pass, seed 5)" in text, text
    dom = Domain3D(h=30, l=10, nside=8, r_min=100, r_max=400, g_max=60, el_max=0.3)
    got = sparse3d.load3d(out)
    want = algorithm1_3d.generate3d(80, dom, mode="multi", seed=5)
    assert got.domain == dom
    for k in ("indptr_a", "indices_a", "indptr_b", "indices_b", "r", "elevation", "g"):
        assert np.array_equal(getattr(got, k), getattr(want, k)), k


def test_sigterm_while_writing_leaves_no_file_nor_spool(tmp_path):
    """A real ``python -m eyeviz generate --nside``, terminated once its spool files
    hold data: exit 143, one line, and nothing left in the folder. (5 x 10^5 rows: long
    enough to be caught writing, and an output of ~3 GB, so the free-space check passes on a
    small disk; 10^7 rows asked for 63 GB and failed where less was free.)"""
    root = Path(__file__).resolve().parents[2]
    extra = os.environ.get("PYTHONPATH")
    env = {**os.environ, "PYTHONPATH": str(root) + (os.pathsep + extra if extra else "")}
    proc = subprocess.Popen(
        [sys.executable, "-m", "eyeviz", "generate", "--nside", "64", "-n", "500000"]
        + ["-o", str(tmp_path / "x.npz"), "--quiet"],
        cwd=tmp_path,
        env=env,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline:
            parts = list(tmp_path.glob(".x.npz.*.part*"))
            if len(parts) > 1 and any(p.stat().st_size > 0 for p in parts):
                break
            assert proc.poll() is None, proc.communicate()
            time.sleep(0.02)
        else:
            pytest.fail("the command never started writing")
        proc.send_signal(signal.SIGTERM)
        _, err = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == 143, err
    assert err.strip().splitlines() == ["eyeviz: terminated by SIGTERM; no partial output was kept"]
    assert list(tmp_path.iterdir()) == []
