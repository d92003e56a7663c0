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


def test_one_commands_parser_builds_only_its_own_options():
    # `eyeviz app` paid for the estimators' and reports' option lists (issue 32 item 14)
    code = (
        "import sys\n"
        "from eyeviz import cli\n"
        "p = cli.build_parser(['app'])\n"
        "print(' '.join(m for m in ('eyeviz.estimators.registry', 'eyeviz.reports.renderers')"
        " if m in sys.modules))\n"
        "p.parse_args(['app', '--help'])\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    assert out.stdout.splitlines()[0] == ""
    assert "--screenshot" in out.stdout


def test_report_help_lists_every_kind():
    # a kind's help with "1 % error" made argparse raise TypeError on `report --help`
    code = "from eyeviz import cli\ncli.main(['report', '--help'])\n"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    assert "1 % error" in out.stdout


def test_a_spherical_snapshot_loads_no_plotter_no_scipy_no_data_sets(tmp_path):
    # issue 32.14: pyvista's plotting package (and matplotlib.pyplot with it) was imported
    # for an off-screen plotter, scipy and eyeviz.dataset for what the figure never used;
    # together about half a second of a 3D snapshot
    out = tmp_path / "s.png"
    code = (
        "import sys\n"
        "from eyeviz import cli\n"
        "from eyeviz.resources import scene_path\n"
        f"cli.main(['snapshot', str(scene_path('sphere_lecture')), '-o', {str(out)!r}])\n"
        "names = ('pyvista.plotting', 'matplotlib.pyplot', 'scipy', 'numba', 'eyeviz.dataset')\n"
        "print('loaded:', *[m for m in names if m in sys.modules])\n"
    )
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    assert out.stat().st_size > 10_000
    assert r.stdout.strip().splitlines()[-1] == "loaded:"
