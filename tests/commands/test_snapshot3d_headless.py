"""``eyeviz snapshot SCENE3D -o x.png`` with no display (issue 22): VTK renders off-screen
through EGL and the command prints no VTK warning ("bad X server connection")."""

from __future__ import annotations

import os
import subprocess
import sys

import matplotlib.image as mpimg
import pytest

from eyeviz.resources import scenes_dir

pytestmark = pytest.mark.slow


def test_spherical_png_snapshot_without_display_is_quiet(tmp_path):
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY")}
    env.pop("VTK_DEFAULT_OPENGL_WINDOW", None)
    out = tmp_path / "teaching.png"
    done = subprocess.run(
        [sys.executable, "-m", "eyeviz", "snapshot", str(scenes_dir() / "sphere_teaching.toml"),
         "-o", str(out), "--scale", "0.5"],
        env=env, capture_output=True, text=True, timeout=300, check=False,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    assert "WARN" not in done.stderr and "X server" not in done.stderr, done.stderr
    img = mpimg.imread(out)
    assert img.shape[0] > 100 and img.shape[1] > 100
