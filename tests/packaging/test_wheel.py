"""A built wheel, installed into a clean virtual environment, works on its own: it carries
the scenes and models (package data found with importlib.resources), so `eyeviz snapshot`
and `eyeviz predict -e compact` run there with the source tree out of reach."""

import os
import shutil
import subprocess
import sys
import sysconfig
import venv
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
# both tests share one build (--dist loadgroup keeps them on one worker); the build runs in
# a copy of what it needs, so it neither writes build/ or *.egg-info into the source tree
# nor meets files that other tests' processes create and remove there meanwhile (a CI run
# failed with "[Errno 2] No such file or directory" mid-build)
pytestmark = pytest.mark.xdist_group("wheel")


@pytest.fixture(scope="module")
def clean_env(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("wheel")
    src = tmp / "src"
    src.mkdir()
    for name in ("pyproject.toml", "README.md"):
        shutil.copy2(ROOT / name, src / name)
    shutil.copytree(
        ROOT / "eyeviz", src / "eyeviz", ignore=shutil.ignore_patterns("__pycache__", "*.pyc")
    )
    build = subprocess.run(
        [sys.executable, "-m", "build", "--wheel", "--no-isolation", "-o", str(tmp / "dist")],
        cwd=src,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert build.returncode == 0, build.stdout[-2000:] + build.stderr[-2000:]
    (wheel,) = (tmp / "dist").glob("eyeviz-*.whl")
    env_dir = tmp / "venv"
    venv.EnvBuilder(with_pip=False).create(env_dir)
    py = env_dir / "bin" / "python"
    site = Path(
        subprocess.check_output(
            [str(py), "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"],
            text=True,
        ).strip()
    )
    # Dependencies (numpy, torch, matplotlib, ...) come from this venv's site-packages, added
    # as a plain path: its .pth files (the editable eyeviz finder among them) are not run.
    (site / "deps.pth").write_text(sysconfig.get_paths()["purelib"] + "\n")
    subprocess.run(
        [sys.executable, "-m", "pip", "--python", str(py), "install", "--no-deps", str(wheel)],
        check=True,
        capture_output=True,
        timeout=300,
    )
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    env["MPLBACKEND"] = "Agg"
    work = tmp / "work"
    work.mkdir()
    return py, env, work


def run(clean_env, *args):
    py, env, work = clean_env
    return subprocess.run(
        [str(py), "-m", "eyeviz", *args],
        cwd=work,
        env=env,
        capture_output=True,
        text=True,
        timeout=300,
    )


@pytest.mark.slow
def test_the_wheel_is_imported_not_the_source_tree(clean_env):
    py, env, work = clean_env
    out = subprocess.check_output(
        [
            str(py),
            "-c",
            "import eyeviz, eyeviz.resources as r; print(eyeviz.__file__);"
            "print(r.scene_path('default'))",
        ],
        cwd=work,
        env=env,
        text=True,
    ).split()
    assert not out[0].startswith(str(ROOT)), out
    assert not out[1].startswith(str(ROOT)) and Path(out[1]).is_file(), out


@pytest.mark.slow
def test_snapshot_and_predict_from_the_wheel(clean_env):
    py, env, work = clean_env
    scene = subprocess.check_output(
        [str(py), "-c", "import eyeviz.resources as r; print(r.scene_path('default'))"],
        cwd=work,
        env=env,
        text=True,
    ).strip()
    snap = run(clean_env, "snapshot", scene, "-o", "default.png")
    assert snap.returncode == 0, snap.stderr
    assert (work / "default.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    gen = run(clean_env, "generate", "-n", "200", "--seed", "3", "-o", "data.csv")
    assert gen.returncode == 0, gen.stderr
    pred = run(clean_env, "predict", "-e", "compact", "data.csv", "-o", "pred.csv")
    assert pred.returncode == 0, pred.stderr
    lines = (work / "pred.csv").read_text().splitlines()
    assert len(lines) >= 200
    assert "r_hat" in lines[0]
