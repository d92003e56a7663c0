"""A real eyeviz window (Qt + VTK) under Xvfb, with settings in a temporary file."""

import os
import sys
from pathlib import Path

import pytest

os.environ.setdefault("QT_API", "pyqt5")
sys.path.insert(0, str(Path(__file__).parent))  # the shared helpers in mouse.py
# the real-X helpers (openbox, the X focus, xdotool keys) shared with the scripts
sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "scripts"))


_XVFB: list = []


def _die_with_parent() -> None:
    """In Xvfb's process before exec: SIGTERM when the worker that started it ends (Linux),
    after Qt has closed its connection."""
    import ctypes
    import signal

    ctypes.CDLL(None).prctl(1, signal.SIGTERM)  # PR_SET_PDEATHSIG


def _own_display() -> None:
    """Under pytest-xdist each worker gets an Xvfb display of its own: windows of other
    workers never take the keyboard focus that real key presses (xdotool) go to.

    The display number is drawn at random from a high range and retried when taken (a lock
    file in /tmp does not show a server in another mount namespace)."""
    import random
    import shutil
    import subprocess

    if shutil.which("Xvfb") is None:
        return  # the shared display then (xvfb-run's)
    for n in random.Random().sample(range(1000, 30000), 20):
        r, w = os.pipe()
        proc = subprocess.Popen(
            ["Xvfb", f":{n}", "-displayfd", str(w), "-screen", "0", "1920x1080x24"]
            + ["-nolisten", "tcp"],
            pass_fds=(w,),
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
            preexec_fn=_die_with_parent if sys.platform == "linux" else None,
        )
        os.close(w)
        with os.fdopen(r) as f:
            ready = f.readline().strip() == str(n)
        if ready and proc.poll() is None:
            _XVFB.append(proc)  # held for the worker's life; it ends with the worker
            os.environ["DISPLAY"] = f":{n}"
            os.environ.pop("XAUTHORITY", None)
            return
        proc.kill()
        proc.wait()
    raise RuntimeError("no Xvfb display could be started for this pytest-xdist worker")


if os.environ.get("PYTEST_XDIST_WORKER"):
    _own_display()

if not os.environ.get("DISPLAY"):
    # a failure, not a skip: a missing display must never pass for a green GUI suite
    raise RuntimeError(
        "the app tests need an X display: run them under xvfb-run -a (scripts/test.sh does)"
    )


@pytest.fixture
def make_window(qtbot, tmp_path):
    from eyeviz.app.window import MainWindow, make_app, make_settings

    make_app()
    made = []

    def make(scene, path=None):
        win = MainWindow(scene, path, settings=make_settings(tmp_path / "settings.json"))
        win._force_close = True  # teardown closes without the unsaved-changes prompt
        qtbot.addWidget(win)
        win.show()
        qtbot.waitExposed(win)
        win.fit_inset()
        win.jobs.wait()  # estimators load on a worker thread
        made.append(win)
        return win

    yield make
    for w in made:
        w.force_close()
