"""`eyeviz study` through the real command line (subprocesses, real LocalClusters): exit
codes, one-line messages, resuming, and Ctrl-C or a crash mid-study keeping whole points.
The refusals before any cluster starts run in the test's process (``eyeviz_main``)."""

import os
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest

from eyeviz.study.table import StudyTable

ROOT = Path(__file__).resolve().parents[2]
pytest.importorskip("distributed")


def eyeviz(*args, timeout=300):
    return subprocess.run(
        [sys.executable, "-m", "eyeviz", "study", *map(str, args)],
        capture_output=True,
        text=True,
        timeout=timeout,
        cwd=ROOT,
    )


def one_error_line(out) -> str:
    assert out.returncode == 2, out.stderr
    lines = out.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("eyeviz: error: "), out.stderr
    assert "Traceback" not in out.stderr
    return lines[0]


@pytest.mark.parametrize(
    ("args", "words"),
    [
        (["--h", "5,10", "--l", "10,20"], ["no design in the grid has l < h"]),
        (["--m", "180,361"], ["m must be an even integer", "361"]),
        (["--m", "2"], ["m must be an even integer", "got 2"]),
        (["--n", "0"], ["n must be", "got 0"]),
        (["--n", "many"], ["n must be an integer", "'many'"]),
        (["--h", "10,x"], ["h:", "'x' is not a number"]),
        (["--workers", "0"], ["workers must be", "got 0"]),
        (["--r-min", "5000", "--r-max", "100"], ["r_max"]),
        (["--seed", "-2"], ["seed", "-2"]),
    ],
)
def test_bad_input_one_line_exit_2_nothing_written(tmp_path, args, words, eyeviz_main):
    out = eyeviz_main("study", "-o", tmp_path / "s.csv", *args)  # refused before any cluster
    line = one_error_line(out)
    for w in words:
        assert w in line, line
    assert os.listdir(tmp_path) == []


@pytest.mark.slow
def test_an_unreachable_scheduler_is_named(tmp_path):
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    out = eyeviz("-o", tmp_path / "s.csv", "--n", "10", "--scheduler", f"tcp://127.0.0.1:{port}")
    line = one_error_line(out)
    assert f"cannot reach the Dask scheduler at 'tcp://127.0.0.1:{port}'" in line
    # a closed port is refused at once (a plain socket before dask's retries, issue 25)
    assert line.endswith("Connection refused)"), line
    assert os.listdir(tmp_path) == []


def test_a_file_of_another_version_is_refused_untouched(tmp_path, eyeviz_main):
    path = tmp_path / "s.csv"
    path.write_text("version,h,l,m,dd_mape\n0,40,20,720,5.0\n")
    before = path.read_bytes()
    line = one_error_line(eyeviz_main("study", "-o", path, "--n", "10"))
    assert "another version of the study table" in line and str(path) in line
    assert path.read_bytes() == before


@pytest.mark.slow
def test_a_small_study_then_a_resume(tmp_path):
    path = tmp_path / "s.csv"
    args = ["-o", path, "--h", "20,40", "--l", "10,20", "--m", "8,16", "--n", "200"]
    with socket.socket() as busy:  # Dask's default HTTP port taken: no warning either
        try:
            busy.bind(("", 8787))
            busy.listen()
        except OSError:
            pass  # somebody else holds it
        out = eyeviz(*args, "--workers", "2")
    assert out.returncode == 0, out.stderr
    assert "arning" not in out.stderr and "Traceback" not in out.stderr, out.stderr
    # (h, l) pairs with l < h: (20, 10), (40, 10), (40, 20); times 2 m
    assert "6 point(s) computed, 0 skipped" in out.stdout
    assert "2 local worker(s)" in out.stdout
    assert "6/6" in out.stderr  # the progress bar reached the end
    assert len(StudyTable.open(path).keys) == 6
    again = eyeviz(*args, "--no-progress")
    assert again.returncode == 0, again.stderr
    assert "0 point(s) computed, 6 skipped" in again.stdout
    assert again.stderr == ""


def start_study(path, h="20,40,80"):
    """A study of slow-enough points in its own process group (as a terminal runs it)."""
    args = ["-o", path, "--h", h, "--l", "10", "--m", "360,720", "--n", "15000"]
    return subprocess.Popen(
        [sys.executable, "-m", "eyeviz", "study", *map(str, args), "--workers", "1"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        cwd=ROOT,
        start_new_session=True,
    ), args


def wait_for_points(proc, path, k, timeout=240):
    """Poll the table until it holds k points; every read must find whole points only."""
    deadline = time.monotonic() + timeout
    reads = 0
    while time.monotonic() < deadline:
        if path.exists():
            n = len(StudyTable.open(path).keys)  # raises on a partial point
            reads += 1
            if n >= k:
                return n, reads
        assert proc.poll() is None, proc.communicate()
        time.sleep(0.02)
    raise AssertionError("the study never wrote its points")


def wait_until_eyeviz_handles_signals(proc, timeout=120) -> None:
    """Wait until the command has installed its own signal handlers (it catches SIGTERM,
    which Python alone does not). A Ctrl-C before then meets Python's start-up and the
    import of the package, where no program can answer it (on a loaded machine that took
    over 0.5 s, and a fixed delay made the test flaky: exit -2 from runpy)."""
    bit = 1 << (signal.SIGTERM - 1)
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        with open(f"/proc/{proc.pid}/status") as f:
            caught = next(int(ln.split()[1], 16) for ln in f if ln.startswith("SigCgt:"))
        if caught & bit:
            return
        assert proc.poll() is None, proc.communicate()
        time.sleep(0.005)
    raise AssertionError("the command never installed its signal handlers")


def group_gone(pgid, timeout=60) -> bool:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        try:
            os.killpg(pgid, 0)
        except ProcessLookupError:
            return True
        time.sleep(0.2)
    return False


@pytest.mark.slow
@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM, signal.SIGKILL])
def test_ctrl_c_or_a_crash_mid_study_keeps_whole_points_and_resumes(tmp_path, sig, eyeviz_main):
    path = tmp_path / "s.csv"
    # four points: the runner starts the largest first, so the first two (the one kept,
    # the one the signal lands in) are those of h 20, 40, 80; two smaller ones fewer follow
    proc, args = start_study(path, h="40,80")
    try:
        n, _ = wait_for_points(proc, path, 1)
        if sig == signal.SIGTERM:
            os.kill(proc.pid, sig)  # `kill PID`, as a batch system's job end does
        else:
            os.killpg(proc.pid, sig)  # Ctrl-C reaches the whole foreground group
        _, err = proc.communicate(timeout=120)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
    if sig in (signal.SIGINT, signal.SIGTERM):
        code, what = (130, "interrupted") if sig == signal.SIGINT else (143, "terminated by")
        assert proc.returncode == code, err
        assert f"eyeviz: {what}" in err and "finished point(s) kept in" in err, err
        assert "Traceback" not in err, err
        assert group_gone(proc.pid), "worker processes outlived the interrupted study"
    else:
        assert proc.returncode == -signal.SIGKILL
        group_gone(proc.pid)
    kept = StudyTable.open(path).keys  # only whole points
    assert 1 <= len(kept) < 4
    lines_before = path.read_text().splitlines()
    # one worker: two Python processes fewer than two (a nanny and its worker, each
    # importing dask and eyeviz), for points of half a second each; the resume in this
    # process (its rows are the point, the signal went to the other)
    out = eyeviz_main("study", *args, "--workers", "1", "--no-progress")
    assert out.returncode == 0, out.stderr
    assert f"{4 - len(kept)} point(s) computed, {len(kept)} skipped" in out.stdout
    assert path.read_text().splitlines()[: len(lines_before)] == lines_before
    assert len(StudyTable.open(path).keys) == 4


@pytest.mark.slow
@pytest.mark.parametrize("delay", [0.7, 2.0])
def test_ctrl_c_while_the_cluster_starts_leaves_no_process_behind(tmp_path, delay):
    # interrupted half-way, a LocalCluster cannot be closed: the runner holds the
    # signal until the cluster is whole, then closes it
    path = tmp_path / "s.csv"
    proc, _ = start_study(path)
    try:
        wait_until_eyeviz_handles_signals(proc)
        time.sleep(delay)
        os.killpg(proc.pid, signal.SIGINT)
        _, err = proc.communicate(timeout=120)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
    assert proc.returncode == 130, err
    # (worker processes still starting may print their own KeyboardInterrupt first)
    assert err.strip().splitlines()[-1].startswith("eyeviz: interrupted;"), err
    assert group_gone(proc.pid, timeout=30), "worker processes outlived the study"
    if path.exists():
        StudyTable.open(path)  # whole points only
