"""`eyeviz report` offers registered plug-in kinds (docs/extending.md)."""

from __future__ import annotations

import sys
import types

import pytest

from eyeviz import cli
from eyeviz.commands import report


@pytest.fixture
def plugin(monkeypatch):
    mod = types.ModuleType("eyeviz_test_report_plugin")
    mod.HELP = "a test report"
    calls = []

    def add_arguments(p):
        p.add_argument("--value", type=int, required=True)

    def run(args):
        calls.append(args.value)
        return 0

    mod.add_arguments, mod.run = add_arguments, run
    monkeypatch.setitem(sys.modules, mod.__name__, mod)
    monkeypatch.setattr(report, "MODULES", dict(report.MODULES))
    report.register("plugin_kind", mod.__name__)
    return calls


def test_registered_report_runs_through_the_cli(plugin):
    assert cli.main(["report", "plugin_kind", "--value", "7"]) == 0
    assert plugin == [7]


def test_a_taken_kind_is_refused(monkeypatch):
    monkeypatch.setattr(report, "MODULES", dict(report.MODULES))
    with pytest.raises(ValueError, match="report kind 'stability' is taken"):
        report.register("stability", "somewhere.else")
    with pytest.raises(ValueError, match="identifier"):
        report.register("not a kind", "x")
