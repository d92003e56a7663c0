"""A real eyeviz window (Qt + VTK) under Xvfb, with settings in a temporary file."""

import os
import sys
from pathlib import Path

import pytest

os.environ.setdefault("QT_API", "pyqt5")
sys.path.insert(0, str(Path(__file__).parent))  # the shared helpers in mouse.py

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
