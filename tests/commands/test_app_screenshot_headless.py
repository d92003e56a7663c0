"""``eyeviz app SCENE --screenshot PNG`` with no display (issue 22: on a fresh machine with
no display the app's screenshot still works): the command runs itself under xvfb-run;
without xvfb-run the one-line "no display" error remains."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import matplotlib.image as mpimg
import numpy as np
import pytest

from eyeviz.resources import scenes_dir

pytestmark = pytest.mark.slow


def _headless_env(**extra: str) -> dict[str, str]:
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY")}
    env["VTK_DEFAULT_OPENGL_WINDOW"] = "vtkEGLRenderWindow"  # as eyeviz.render.vtk sets it
    env.update(QT_API="pyqt5", **extra)
    return env


def _app(args: list[str], env: dict[str, str]) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "eyeviz", "app", *args],
        env=env,
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
    )


@pytest.mark.skipif(shutil.which("xvfb-run") is None, reason="xvfb-run is installed by setup.sh")
@pytest.mark.parametrize("scene", ["sphere_teaching.toml", "default.toml"])
def test_screenshot_without_display_runs_on_xvfb(tmp_path: Path, scene: str):
    out = tmp_path / "shot.png"
    done = _app([str(scenes_dir() / scene), "--screenshot", str(out)], _headless_env())
    assert done.returncode == 0, done.stderr
    assert "virtual" in done.stderr
    img = mpimg.imread(out)
    assert img.shape[0] >= 600 and img.shape[1] >= 1000
    # a real picture: many colours, not a blank window
    rgb = (img[..., :3] * 255).astype(np.uint8).reshape(-1, 3)
    assert len(np.unique(rgb, axis=0)) > 50


def test_without_xvfb_run_the_error_is_one_line(tmp_path: Path):
    out = tmp_path / "shot.png"
    bare = tmp_path / "bin"
    bare.mkdir()
    done = _app(
        [str(scenes_dir() / "default.toml"), "--screenshot", str(out)],
        _headless_env(PATH=str(bare)),
    )
    assert done.returncode == 2
    lines = [ln for ln in done.stderr.splitlines() if ln.strip()]
    assert len(lines) == 1 and "no display" in lines[0], done.stderr
    assert not out.exists()
