"""A signal that arrives inside compiled code (numba) surfaces as another exception
(numba: "SystemError: ... returned a result with an exception set"); the command line
reports it as the interruption it was, with the signal's exit status, not as a bug."""

from __future__ import annotations

import types

from eyeviz import cli
from eyeviz.files import atomic


def _command(exc: BaseException):
    def run(_args):
        atomic.note_interruption(cli.Interrupted("SIGTERM"))
        raise exc

    return types.SimpleNamespace(_run=run)


def test_a_signal_turned_into_another_exception_exits_as_the_signal(capsys):
    atomic.clear_interruptions()
    try:
        assert cli._run(_command(SystemError("returned a result with an exception set"))) == 143
    finally:
        atomic.clear_interruptions()
    err = capsys.readouterr().err
    assert "terminated by SIGTERM" in err and "unexpected" not in err


def test_without_a_signal_a_bug_is_still_a_bug(capsys):
    atomic.clear_interruptions()

    def run(_args):
        raise SystemError("a real bug")

    assert cli._run(types.SimpleNamespace(_run=run)) == 2
    assert "unexpected SystemError" in capsys.readouterr().err
