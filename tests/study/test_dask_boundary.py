"""Only the study's runner imports dask: every other module of eyeviz (the app's included)
and `eyeviz snapshot` leave dask out of sys.modules, and the runner's import is lazy."""

import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]

PROBE = """
import importlib, pkgutil, sys
import eyeviz
skip = ("eyeviz.__main__", "eyeviz.study.runner")
names = [m.name for m in pkgutil.walk_packages(eyeviz.__path__, "eyeviz.")
         if not m.name.startswith(skip)]
for name in names:
    importlib.import_module(name)
assert "eyeviz.app.window" in sys.modules and "eyeviz.study.table" in sys.modules
from eyeviz.cli import main
rc = main(sys.argv[1:])
dask = sorted(m for m in sys.modules if m.split(".")[0] in ("dask", "distributed"))
print(len(names), rc, "dask:" + ",".join(dask))
"""


def run(code, *args):
    out = subprocess.run(
        [sys.executable, "-c", code, *map(str, args)],
        capture_output=True,
        text=True,
        timeout=300,
        cwd=ROOT,
        env={**__import__("os").environ, "MPLBACKEND": "Agg"},
    )
    assert out.returncode == 0, out.stderr
    return out.stdout.strip().splitlines()[-1].split()


@pytest.mark.slow
def test_no_module_but_the_runner_imports_dask(tmp_path):
    n, rc, dask = run(
        PROBE, "snapshot", ROOT / "assets" / "scenes" / "default.toml", "-o", tmp_path / "s.svg"
    )
    assert int(n) > 50  # every module was imported, the app and the commands included
    assert rc == "0" and (tmp_path / "s.svg").stat().st_size > 1000
    assert dask == "dask:"


def test_the_runner_imports_dask_only_when_a_study_runs():
    has = "print('dask' in sys.modules, 'distributed' in sys.modules)"
    code = f"import sys, eyeviz.study, eyeviz.study.runner\n{has}"
    assert run(code) == ["False", "False"]
    code = (
        "import sys, eyeviz.study as s\n"
        "try:\n"
        "    s.run_study('/nonexistent-dir/x.csv', [s.DesignPoint(n=1)], workers=1)\n"
        "except Exception:\n"
        "    pass\n"
        f"{has}"
    )
    assert run(code) == ["False", "False"]  # refused before the cluster: still no dask
    # and the check can fail: connecting to a cluster does load dask
    code = (
        "import sys, eyeviz.study.runner as r\n"
        "try:\n"
        "    r._connect('tcp://127.0.0.1:1', None, 0.1)\n"
        "except Exception:\n"
        "    pass\n"
        f"{has}"
    )
    assert run(code) == ["True", "True"]
