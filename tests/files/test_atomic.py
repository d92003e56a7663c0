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
        assert tmp.name.startswith(f".x.csv.eyeviz-{os.getpid()}-")
        assert tmp.name.endswith(".part.csv")
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
    # eyeviz's temporaries of earlier versions had no marker: like a user's, never touched
    unmarked = _plant(tmp_path, f".x.csv.{dead}.0123456789abcdef.part.csv", 10 * old)
    user = [
        _plant(tmp_path, name, 100 * old)
        for name in (
            "x.csv",
            ".x.csv.part",
            "notes.part.csv",
            ".hidden",
            ".a.123.zz.part.csv",
            ".x.csv.ab_cd123.part.csv",
        )
    ]
    folder = tmp_path / f".x.csv.eyeviz-{dead}-0123456789abcdef.part.csv"
    os.mkdir(folder)
    with atomic_output(tmp_path / "x.csv") as tmp:
        tmp.write_text("1")
    left = set(tmp_path.iterdir())
    assert stale not in left
    for p in (stale_npz, young, alive, unmarked, *user):  # y.npz's: not this output's
        assert p in left
    assert (tmp_path / "x.csv").read_text() == "1" and folder.is_dir()
    assert sweep_stale(tmp_path, "x.csv") == []
    assert sweep_stale(tmp_path) == [stale_npz]


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
    assert f".eyeviz-{proc.pid}-" in part.name
    assert sweep_stale(tmp_path) == []  # young: kept
    assert sweep_stale(tmp_path, now=time.time() + atomic.SWEEP_AGE_S + 1) == [part]
    assert list(tmp_path.iterdir()) == []


def test_missing_directory(tmp_path):
    with pytest.raises(EyevizError, match="output directory does not exist"):
        with atomic_output(tmp_path / "no" / "x.csv"):
            pass


# --- a full disk names the file (issue 25, item 8) -------------------------------------


@pytest.mark.parametrize("code", ["ENOSPC", "EDQUOT", "EFBIG"])
def test_a_full_disk_names_the_output_and_keeps_the_old_file(tmp_path, code):
    import errno

    target = tmp_path / "table.csv"
    target.write_text("previous")
    err = getattr(errno, code)
    with pytest.raises(EyevizError) as info, atomic_output(target) as tmp:
        tmp.write_text("half")
        raise OSError(err, os.strerror(err))  # what os.write says: no file name
    msg = str(info.value)
    assert msg.startswith(f"{target}: cannot write: ") and "\n" not in msg
    assert os.strerror(err) in msg
    assert target.read_text() == "previous"
    assert [p.name for p in tmp_path.iterdir()] == ["table.csv"]


def test_other_os_errors_pass_through_unchanged(tmp_path):
    with pytest.raises(PermissionError), atomic_output(tmp_path / "x.csv"):
        raise PermissionError(13, "Permission denied")
    assert list(tmp_path.iterdir()) == []


def test_no_inode_left_names_the_output(tmp_path, monkeypatch):
    import errno

    real_open = os.open

    def full(path, *a, **k):
        if ".part" in str(path):
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
        return real_open(path, *a, **k)

    monkeypatch.setattr(atomic.os, "open", full)
    with pytest.raises(EyevizError, match=r"x\.npz: cannot write: No space left"):
        with atomic_output(tmp_path / "x.npz"):
            pass


def _limited(limit: int):
    """preexec for a child whose files may not grow past ``limit`` bytes (EFBIG, as a
    full disk: a write fails part-way)."""

    def pre():
        import resource
        import signal

        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))

    return pre


@pytest.mark.parametrize(
    ("args", "name"),
    [
        (["generate", "-n", "20000", "--seed", "5", "--quiet"], "data.csv"),
        (["generate", "-n", "20000", "--seed", "5", "--quiet"], "data.npz"),
        (["snapshot", "assets/scenes/default.toml"], "fig.png"),
    ],
)
def test_a_real_write_past_the_limit_names_the_file(tmp_path, args, name):
    """A real child process whose writes fail part-way (file size limit: EFBIG, the
    same path as ENOSPC): one line naming the file, exit 2, no file left."""
    from pathlib import Path

    root = Path(__file__).resolve().parents[2]
    out = tmp_path / name
    res = subprocess.run(
        [sys.executable, "-m", "eyeviz", *args, "-o", str(out)],
        capture_output=True,
        text=True,
        timeout=120,
        cwd=root,
        env={**os.environ, "MPLBACKEND": "Agg"},
        preexec_fn=_limited(20_000),
    )
    assert res.returncode == 2, res.stderr
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1 and str(out) in lines[0] and "cannot write" in lines[0], res.stderr
    assert list(tmp_path.iterdir()) == []


def test_a_full_disk_while_a_fit_stages_its_files_names_the_output(tmp_path):
    """A fit writes weights with torch/numpy into the staging folder (no atomic_output):
    a full disk there names the model folder, and leaves it as it was."""
    import errno

    from eyeviz.estimators.store import staged

    out = tmp_path / "models"
    out.mkdir()
    (out / "old.json").write_text("{}")
    with pytest.raises(EyevizError, match=r"models: cannot write: No space left"):
        with staged(out) as stage:
            (stage / "w.pt").write_bytes(b"half")
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
    assert [p.name for p in out.iterdir()] == ["old.json"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["models"]
