"""The Dask runner: real LocalClusters with worker processes (no mocks). Resuming skips
finished points, an unreachable scheduler ends in one line, and killing a worker process
mid-study still gives every point, none recomputed on a re-run."""

import os
import signal
import socket
import subprocess
import sys
import threading
import time

import pytest

from eyeviz import EyevizError
from eyeviz.study import run_study
from eyeviz.study.grid import design_grid
from eyeviz.study.table import StudyTable, read_rows


def seconds_by_point(path):
    rows, _ = read_rows(path)
    return {r["_key"]: r["seconds"] for r in rows if r["bin"] == "all"}


@pytest.mark.slow
def test_a_study_resumes_and_skips_finished_points(tmp_path):
    path = tmp_path / "study.csv"
    first = design_grid("20,40", "10", "8,16", n=300)
    s1 = run_study(path, first, workers=1, progress=False)
    assert (s1.computed, s1.skipped, s1.failures) == (4, 0, ())
    assert set(seconds_by_point(path)) == {p.key for p in first}
    before = seconds_by_point(path)
    lines_before = path.read_text().splitlines()

    # the same grid plus one more m: only the new points run; finished rows stay byte-equal
    more = design_grid("20,40", "10", "8,16,32", n=300)
    s2 = run_study(path, more, workers=1, progress=False)
    assert (s2.computed, s2.skipped, s2.points) == (2, 4, 6)
    after = seconds_by_point(path)
    assert {k: after[k] for k in before} == before  # 'seconds' unchanged: not recomputed
    assert path.read_text().splitlines()[: len(lines_before)] == lines_before
    after_lines = path.read_text().splitlines()

    # everything finished: nothing runs, no cluster is started
    import distributed

    def no_cluster(*a, **kw):
        raise AssertionError("a cluster was started with nothing to compute")

    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(distributed, "LocalCluster", no_cluster)
        mp.setattr(distributed, "Client", no_cluster)
        s3 = run_study(path, more, workers=1, progress=False)
    assert (s3.computed, s3.skipped, s3.workers) == (0, 6, 0)
    assert path.read_text().splitlines() == after_lines  # nothing written either
    assert "0 point(s) computed, 6 skipped" in str(s3)


def unused_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.mark.slow
def test_an_unreachable_scheduler_ends_in_one_line_quickly(tmp_path):
    addr = f"tcp://127.0.0.1:{unused_port()}"
    path = tmp_path / "s.csv"
    with pytest.raises(EyevizError) as err:
        run_study(path, design_grid("20", "10", "8", n=10), scheduler=addr, connect_timeout=2)
    msg = str(err.value)
    assert "\n" not in msg
    assert f"cannot reach the Dask scheduler at '{addr}' within 2 s" in msg
    # a closed port is refused at once by a plain socket probe (issue 25), before dask's
    # connect retries (which gave up only after the timeout)
    assert msg.endswith("Connection refused)"), msg
    assert not path.exists()


@pytest.mark.parametrize(
    ("kwargs", "words"),
    [
        ({"workers": 0}, ["workers must be an integer in [1,", "got 0"]),
        ({"workers": 2, "scheduler": "tcp://127.0.0.1:1"}, ["--workers", "--scheduler"]),
        ({"scheduler": " "}, ["scheduler must be an address"]),
    ],
)
def test_bad_runner_arguments(tmp_path, kwargs, words):
    with pytest.raises(EyevizError) as err:
        run_study(tmp_path / "s.csv", design_grid("20", "10", "8", n=10), **kwargs)
    for w in words:
        assert w in str(err.value)


@pytest.mark.slow
@pytest.mark.parametrize("allowed_failures", [None, 0])
def test_killing_a_worker_mid_study_loses_only_its_point(tmp_path, allowed_failures):
    """Two worker processes, four points of ~1-2 s each; one worker is SIGKILLed while it
    computes a point. Dask reschedules that point (the nanny restarts the worker); the
    study ends with every point, and a re-run computes nothing. With allowed-failures 0
    the scheduler gives the point up at once (KilledWorker): the runner submits it again.
    """
    import dask
    from distributed import Client, LocalCluster

    config = {}
    if allowed_failures is not None:
        config["distributed.scheduler.allowed-failures"] = allowed_failures

    path = tmp_path / "study.csv"
    # the four largest of the grid h 20, 40, 80 x m 360, 720 (the runner starts the
    # largest first): when one has finished and both workers compute, the two points
    # being computed are the same as in the whole grid's six (the kill lands as far
    # inside them), and two smaller points fewer follow
    points = design_grid("20,40,80", "10", "720", n=30_000) + design_grid(
        "80", "10", "360", n=30_000
    )
    assert len(points) == 4
    killed: dict = {}
    with (
        dask.config.set(config),
        LocalCluster(
            n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
        ) as cluster,
        Client(cluster) as client,
    ):
        pids = client.run(os.getpid)
        assert len(pids) == 2

        def killer():
            deadline = time.monotonic() + 120
            while time.monotonic() < deadline and not killed:
                busy = {a: ks for a, ks in client.processing().items() if ks}
                # wait until one point is done and both workers are computing
                done = len(StudyTable.open(path).keys) if path.exists() else 0
                if done >= 1 and len(busy) == 2:
                    time.sleep(0.3)  # well inside the point being computed
                    addr = sorted(busy)[0]
                    killed.update(addr=addr, pid=pids[addr], done_before=done)
                    os.kill(pids[addr], signal.SIGKILL)
                    return
                time.sleep(0.05)

        t = threading.Thread(target=killer, daemon=True)
        t.start()
        summary = run_study(path, points, scheduler=cluster.scheduler_address, progress=False)
        t.join(5)
        assert killed, "the worker was never killed: the test proved nothing"
        with pytest.raises(ProcessLookupError):
            os.kill(killed["pid"], 0)
        assert killed["done_before"] < 4
        assert summary.computed == 4 and summary.failures == ()
        # the scheduler rescheduled the point itself, or gave it up (with any point queued
        # on that worker) and the runner sent it again
        if allowed_failures == 0:
            assert 1 <= summary.resubmitted <= 2
        else:
            assert summary.resubmitted == 0
        assert StudyTable.open(path).finished == {p.key for p in points}
        before = path.read_bytes()
        again = run_study(path, points, scheduler=cluster.scheduler_address, progress=False)
        assert (again.computed, again.skipped) == (0, 4)
        assert path.read_bytes() == before


def _fails_for_m16(point):
    from eyeviz.study.point import evaluate

    if point.m == 16:
        raise ValueError("boom for the test")
    return evaluate(point)


@pytest.mark.slow
def test_a_failing_point_is_named_and_the_others_kept(tmp_path, monkeypatch):
    from distributed import LocalCluster

    from eyeviz.study import runner
    from eyeviz.study.runner import StudyFailed

    monkeypatch.setattr(runner, "evaluate", _fails_for_m16)
    path = tmp_path / "s.csv"
    points = design_grid("20", "10", "8,16,32", n=200)
    with LocalCluster(n_workers=1, processes=False, dashboard_address=None) as cluster:
        with pytest.raises(StudyFailed) as err:
            run_study(path, points, scheduler=cluster.scheduler_address, progress=False)
    msg = str(err.value)
    assert "\n" not in msg
    assert "1 design point(s) failed, the other 2 are in" in msg
    assert "h=20, l=10, m=16" in msg and "boom for the test" in msg
    assert err.value.summary.computed == 2
    assert StudyTable.open(path).finished == {points[0].key, points[2].key}


_FAULTS = """
import resource, sys
from eyeviz.study.point import DesignPoint, evaluate
from eyeviz.study.runner import evaluate_on_worker
run = evaluate_on_worker if sys.argv[1] == "tuned" else evaluate
run(DesignPoint(m=1440, n=2000))  # warm: imports and first allocations
before = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
run(DesignPoint(m=1440, n=4000, seed=1))
print(resource.getrusage(resource.RUSAGE_SELF).ru_minflt - before)
"""


@pytest.mark.slow
def test_a_worker_under_dasks_malloc_trim_threshold_does_not_refault_every_array():
    """Dask's nanny sets MALLOC_TRIM_THRESHOLD_=65536 in its workers: every large
    temporary array becomes a fresh mmap (2.6x slower points). The task the runner submits
    (evaluate_on_worker) raises glibc's thresholds first: counted in page faults, not time."""
    env = {**os.environ, "MALLOC_TRIM_THRESHOLD_": "65536"}

    def faults(mode):
        out = subprocess.run(
            [sys.executable, "-c", _FAULTS, mode], env=env, capture_output=True, text=True
        )
        assert out.returncode == 0, out.stderr
        return int(out.stdout.split()[-1])

    plain, tuned = faults("plain"), faults("tuned")
    assert tuned * 10 < plain, (tuned, plain)


@pytest.mark.slow
def test_a_second_study_into_the_same_file_is_refused_and_the_lock_goes_away(tmp_path):
    import fcntl

    path = tmp_path / "study.csv"
    grid = design_grid("40", "20", "8", n=200)
    run_study(path, grid, workers=1, progress=False)
    before = path.read_bytes()
    lock = tmp_path / ".study.csv.lock"
    assert not lock.exists()  # removed when a study ends
    with open(lock, "w") as held:  # another study holds it
        fcntl.flock(held, fcntl.LOCK_EX)
        with pytest.raises(EyevizError, match="another study is writing") as ei:
            run_study(path, design_grid("40", "20", "8,16", n=200), workers=1, progress=False)
        assert "\n" not in str(ei.value)
    assert path.read_bytes() == before  # nothing written by the refused study
    s = run_study(path, design_grid("40", "20", "8,16", n=200), workers=1, progress=False)
    assert (s.computed, s.skipped) == (1, 1) and not lock.exists()


def test_a_local_cluster_gets_time_to_start_a_users_scheduler_does_not():
    from eyeviz.study import runner

    assert runner.connect_timeout_for("tcp://10.0.0.1:8786", 5.0) == 5.0
    assert runner.connect_timeout_for(None, 5.0) == runner.LOCAL_CONNECT_S >= 30.0
    assert runner.dask_config(60.0)["distributed.comm.timeouts.connect"] == "60.0s"
