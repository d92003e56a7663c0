"""A bad ``--scheduler`` ends in one line (issue 25 item 6): before, each of these printed
the right line and then a 9-line "Exception ignored in Client.__del__" traceback, exiting
after about 13 s; and ``--workers`` beyond the usable CPUs is warned about."""

import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
pytest.importorskip("distributed")


def eyeviz(*args):
    return subprocess.run(
        [sys.executable, "-m", "eyeviz", "study", *map(str, args)],
        capture_output=True,
        text=True,
        timeout=120,
        cwd=ROOT,
    )


@pytest.mark.parametrize(
    ("address", "why"),
    [
        ("nonsense", "missing port number"),
        ("http://localhost:8786", "unknown address scheme 'http'"),
        ("inproc://x", "inproc:// stays in-process"),
        ("tcp://[::1", "invalid address"),
    ],
)
def test_a_bad_scheduler_is_one_line(tmp_path, address, why):
    out = eyeviz("-o", tmp_path / "s.csv", "--n", "10", "--scheduler", address)
    assert out.returncode == 2, out.stderr
    lines = out.stderr.strip().splitlines()
    assert len(lines) == 1, out.stderr
    assert lines[0].startswith("eyeviz: error: scheduler must be an address such as tcp://")
    assert repr(address) in lines[0] and why in lines[0]
    assert list(tmp_path.iterdir()) == []


def test_check_scheduler_accepts_real_addresses():
    from eyeviz.study.runner import check_scheduler

    for a in ("tcp://127.0.0.1:8786", "tcp://[::1]:8786", "tls://host:8786", "ws://h:1"):
        check_scheduler(a)


def test_more_workers_than_cpus_warns(tmp_path, monkeypatch):
    from eyeviz.study import cpus

    assert cpus.workers_warning(1, cpus=2) is None
    assert cpus.workers_warning(2, cpus=2) is None
    msg = cpus.workers_warning(4, cpus=2)
    assert msg is not None and "--workers 4" in msg and "2 CPU(s)" in msg and "\n" not in msg
