"""Atomic output and the sweep of stale temporary files (issue 13)."""

from __future__ import annotations

import os
import subprocess
import sys
import time

import pytest

from eyeviz import EyevizError
from eyeviz.files import atomic
from eyeviz.files.atomic import atomic_output, part_name, sweep_stale


def _dead_pid() -> int:
    p = subprocess.Popen([sys.executable, "-c", "pass"])
    p.wait()
    return p.pid


def _plant(folder, name, age_s):
    p = folder / name
    p.write_bytes(b"x" * 100)
    t = time.time() - age_s
    os.utime(p, (t, t))
    return p


def test_temp_name_carries_pid_and_is_removed_on_error(tmp_path):
    target = tmp_path / "x.csv"
    with pytest.raises(RuntimeError), atomic_output(target) as tmp:
        assert tmp.name.startswith(f".x.csv.{os.getpid()}.") and tmp.name.endswith(".part.csv")
        assert atomic._PART.match(tmp.name)
        tmp.write_text("half")
        raise RuntimeError
    assert list(tmp_path.iterdir()) == []
    with atomic_output(target) as tmp:
        tmp.write_text("whole")
    assert target.read_text() == "whole" and [p.name for p in tmp_path.iterdir()] == ["x.csv"]


def test_sweep_removes_only_stale_files_of_dead_writers(tmp_path):
    dead = _dead_pid()
    old = atomic.SWEEP_AGE_S + 60
    stale = _plant(tmp_path, part_name(tmp_path / "x.csv", dead), old)
    stale_npz = _plant(tmp_path, part_name(tmp_path / "y.npz", dead), old)
    young = _plant(tmp_path, part_name(tmp_path / "x.csv", dead), 5)
    alive = _plant(tmp_path, part_name(tmp_path / "x.csv", os.getppid()), old)
    legacy_old = _plant(tmp_path, ".x.csv.ab_cd123.part.csv", atomic.SWEEP_AGE_LEGACY_S + 60)
    legacy_young = _plant(tmp_path, ".x.csv.zz_cd123.part.csv", old)
    user = [
        _plant(tmp_path, name, 10 * atomic.SWEEP_AGE_LEGACY_S)
        for name in ("x.csv", ".x.csv.part", "notes.part.csv", ".hidden", ".a.123.zz.part.csv")
    ]
    folder = tmp_path / f".d.csv.{dead}.0123456789abcdef.part.csv"
    os.mkdir(folder)
    with atomic_output(tmp_path / "z.csv") as tmp:
        tmp.write_text("1")
    left = set(tmp_path.iterdir())
    for p in (stale, stale_npz, legacy_old):
        assert p not in left
    for p in (young, alive, legacy_young, *user):
        assert p in left
    assert (tmp_path / "z.csv").exists() and (
        tmp_path / f".d.csv.{dead}.0123456789abcdef.part.csv"
    ).is_dir()
    assert sweep_stale(tmp_path) == []


def test_sweep_after_sigkill(tmp_path):
    """A writer killed with SIGKILL (no handler can run) leaves its file; the next write
    into the folder, once the file is old enough, sweeps it."""
    proc = subprocess.Popen(
        [sys.executable, "-m", "eyeviz", "generate", "-n", "3000000", "-o", "x.csv", "--quiet"],
        cwd=tmp_path,
        env={**os.environ, "PYTHONPATH": os.getcwd()},
    )
    t = time.monotonic()
    while not list(tmp_path.glob(".x.csv.*.part.csv")) and time.monotonic() - t < 60:
        time.sleep(0.02)
    proc.kill()
    proc.wait()
    (part,) = tmp_path.glob(".x.csv.*.part.csv")
    assert f".{proc.pid}." in part.name
    assert sweep_stale(tmp_path) == []  # young: kept
    assert sweep_stale(tmp_path, now=time.time() + atomic.SWEEP_AGE_S + 1) == [part]
    assert list(tmp_path.iterdir()) == []


def test_missing_directory(tmp_path):
    with pytest.raises(EyevizError, match="output directory does not exist"):
        with atomic_output(tmp_path / "no" / "x.csv"):
            pass
