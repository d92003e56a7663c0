"""Leave out what is not needed: the public modules import no GUI, no torch, no dask and no
matplotlib, and the command line imports dask only for `eyeviz study`."""

import subprocess
import sys

import pytest

HEAVY = ("torch", "PyQt5", "pyvista", "vtkmodules", "matplotlib", "dask", "distributed")


def loaded_after(code: str) -> list[str]:
    probe = f"{code}\nimport sys\nprint(' '.join(m for m in {HEAVY!r} if m in sys.modules))"
    out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    return out.stdout.split()


@pytest.mark.parametrize(
    "module",
    [
        "eyeviz.geometry",
        "eyeviz.exact",
        "eyeviz.ambiguity",
        "eyeviz.scene",
        "eyeviz.dataset",
        "eyeviz.estimators",
        "eyeviz.core",
        "eyeviz.model.state",
        "eyeviz.model.app_model",
    ],
)
def test_public_modules_import_nothing_heavy(module):
    assert loaded_after(f"import {module}") == []


def test_the_command_line_parser_imports_nothing_heavy():
    # building every sub-command's parser (as `eyeviz --help` does) must stay light
    code = (
        "import contextlib, io\n"
        "from eyeviz import cli\n"
        "with contextlib.suppress(SystemExit), contextlib.redirect_stdout(io.StringIO()):\n"
        "    cli.main(['--help'])\n"
    )
    assert loaded_after(code) == []
