"""The command line builds only the command it runs (eyeviz.cli.build_parser), and every
command's and report kind's ``--help`` prints (a ``%`` in a help line once broke
``eyeviz report --help``)."""

import subprocess
import sys

import pytest

from eyeviz import cli
from eyeviz.commands import report


def _help(argv: list[str], capsys) -> str:
    with pytest.raises(SystemExit) as exc:
        cli.main(argv)
    assert exc.value.code == 0, capsys.readouterr().err
    return capsys.readouterr().out


@pytest.mark.parametrize("name", sorted(m.NAME for m in cli._command_modules()))
def test_every_command_prints_its_help(name, capsys):
    assert f"usage: eyeviz {name}" in _help([name, "--help"], capsys)


@pytest.mark.parametrize("kind", report.KINDS)
def test_every_report_kind_prints_its_help(kind, capsys):
    assert f"usage: eyeviz report {kind}" in _help(["report", kind, "--help"], capsys)


def test_the_report_list_names_every_kind_with_its_help(capsys):
    out = _help(["report", "--help"], capsys)
    for kind in report.KINDS:
        assert kind in out
    assert "1 % error" in out  # the renderers' help line, its percent sign printed once


def _modules_after(argv: list[str]) -> set[str]:
    code = (
        "import contextlib, io, sys\n"
        "from eyeviz import cli\n"
        "with contextlib.suppress(SystemExit), contextlib.redirect_stderr(io.StringIO()):\n"
        f"    cli.main({argv!r})\n"
        "print(' '.join(m for m in sys.modules if m.startswith('eyeviz.')))\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    return set(out.stdout.split())


def test_a_report_imports_its_own_kind_only(tmp_path):
    loaded = _modules_after(
        ["report", "dataset", str(tmp_path / "absent.npz"), "-o", str(tmp_path / "r")]
    )
    assert "eyeviz.reports.dataset" in loaded
    others = {f"eyeviz.reports.{k}" for k in report.KINDS if k != "dataset"}
    assert not loaded & others


def test_a_command_builds_no_other_command(tmp_path):
    # generate's options need the planar defaults only; predict's estimator registry is
    # not imported when generate runs
    loaded = _modules_after(["generate", "--nside", "0", "-o", str(tmp_path / "a.npz")])
    assert "eyeviz.commands.generate" in loaded
    assert "eyeviz.estimators.registry" not in loaded
