"""A report folder written atomically (issue 35, item 3): an interrupted report leaves the
folder as it was; a finished one moves in whole; a user's other files stay."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time

import pytest

from eyeviz import EyevizError
from eyeviz.files import atomic
from eyeviz.files.atomic import atomic_folder, stage_name, sweep_stale


def _old_report(d):
    d.mkdir()
    (d / "study.md").write_text("old run")
    (d / "study_dd.png").write_bytes(b"old png")
    (d / "my_notes.txt").write_text("the user's")


def _contents(d):
    return {p.name: p.read_bytes() for p in d.iterdir()}


def test_an_interrupted_folder_is_left_as_it_was(tmp_path):
    d = tmp_path / "DIR"
    _old_report(d)
    before = _contents(d)
    with pytest.raises(KeyboardInterrupt), atomic_folder(d) as stage:
        (stage / "study.md").write_text("new run")
        raise KeyboardInterrupt
    assert _contents(d) == before
    assert [p.name for p in tmp_path.iterdir()] == ["DIR"]  # no staging folder left


def test_a_finished_folder_moves_in_and_keeps_the_users_files(tmp_path):
    d = tmp_path / "DIR"
    _old_report(d)
    with atomic_folder(d) as stage:
        assert stage.parent == tmp_path and stage.name.startswith(".DIR.eyeviz-")
        (stage / "study.md").write_text("new run")
        (stage / "study_dd.png").write_bytes(b"new png")
        (stage / "sub").mkdir()
        (stage / "sub" / "x.csv").write_text("1")
    assert sorted(p.name for p in d.iterdir()) == [
        "my_notes.txt",
        "study.md",
        "study_dd.png",
        "sub",
    ]
    assert (d / "study.md").read_text() == "new run"
    assert (d / "study_dd.png").read_bytes() == b"new png"
    assert (d / "my_notes.txt").read_text() == "the user's"
    assert (d / "sub" / "x.csv").read_text() == "1"
    assert [p.name for p in tmp_path.iterdir()] == ["DIR"]


def test_a_new_folder_appears_whole(tmp_path):
    d = tmp_path / "a" / "DIR"
    with atomic_folder(d) as stage:
        (stage / "x.md").write_text("x")
        assert not d.exists()
    assert _contents(d) == {"x.md": b"x"}


@pytest.mark.parametrize("kind", ["file", "fifo"])
def test_an_output_that_is_not_a_folder_is_refused_before_any_work(tmp_path, kind):
    d = tmp_path / "DIR"
    if kind == "file":
        d.write_text("keep")
    else:
        os.mkfifo(d)
    with pytest.raises(EyevizError, match="exists and is not a directory"), atomic_folder(d):
        raise AssertionError("no work may start")
    assert d.exists()


def test_signals_are_held_while_the_files_move_in(tmp_path):
    d = tmp_path / "DIR"
    _old_report(d)
    real = atomic._move_in

    def move_with_a_signal(stage, path):
        os.kill(os.getpid(), signal.SIGINT)  # arrives between two renames
        real(stage, path)

    atomic._move_in = move_with_a_signal
    # Python's own Ctrl-C handler, whatever this process inherited (a shell's background
    # job starts with SIGINT ignored, and the signal would then be held and dropped)
    inherited = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        with pytest.raises(KeyboardInterrupt), atomic_folder(d) as stage:
            (stage / "study.md").write_text("new run")
            (stage / "study_dd.png").write_bytes(b"new png")
    finally:
        atomic._move_in = real
        signal.signal(signal.SIGINT, inherited)
    assert (d / "study.md").read_text() == "new run"  # the whole new set, then the signal
    assert (d / "study_dd.png").read_bytes() == b"new png"


def test_stale_staging_folders_of_that_output_only_are_swept(tmp_path):
    p = subprocess.Popen([sys.executable, "-c", "pass"])
    p.wait()
    old = time.time() - atomic.SWEEP_AGE_S - 60
    mine = tmp_path / stage_name(tmp_path / "DIR", p.pid)
    other = tmp_path / stage_name(tmp_path / "OTHER", p.pid)
    user = tmp_path / ".DIR.staging"
    for s in (mine, other, user):
        s.mkdir()
        (s / "f").write_text("x")
        os.utime(s, (old, old))
    with atomic_folder(tmp_path / "DIR") as stage:
        (stage / "x").write_text("1")
    assert not mine.exists() and other.exists() and user.exists()
    assert sweep_stale(tmp_path, "DIR") == []
