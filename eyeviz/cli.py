"""The ``eyeviz`` command line (docs/contract.md).

Sub-commands are discovered from :mod:`eyeviz.commands`. Every error a user can cause
ends in a one-line message on stderr and a non-zero exit, never a traceback:

- :class:`EyevizError`, ValueError, OSError, OverflowError, RecursionError: exit 2;
- any other exception (a bug: KeyError, TypeError, and ZeroDivisionError or
  FloatingPointError, whose text names no input): exit 2 with one line starting
  ``eyeviz: error: unexpected <type>`` (``EYEVIZ_DEBUG=1`` re-raises it);
- Ctrl-C (SIGINT) exit 130, SIGHUP exit 129, SIGTERM exit 143: each raises
  :class:`Interrupted` (a KeyboardInterrupt) in the main thread, so every
  :func:`eyeviz.files.atomic.atomic_output` removes its temporary file;
- a closed stderr (``2>&-``) or stdout: they are pointed at ``os.devnull`` (progress bars
  and messages are dropped, the work is done); a reader that goes away (``| head``,
  EPIPE) no longer turns a finished command into an error.
"""

from __future__ import annotations

import functools
import os
import signal
import sys
import warnings

DEFAULT_COMMAND = "app"
_SIGNALS = {"SIGINT": 130, "SIGTERM": 143, "SIGHUP": 129}
_SHOW_WARNING = warnings.showwarning


class Interrupted(KeyboardInterrupt):
    """SIGINT, SIGTERM or SIGHUP arrived; ``signame`` and ``exit_code`` say which."""

    def __init__(self, signame: str = "SIGINT"):
        super().__init__(signame)
        self.signame = signame
        self.exit_code = _SIGNALS.get(signame, 130)


def _raise_interrupted(signum, _frame) -> None:
    exc = Interrupted(signal.Signals(signum).name)
    _note_interruption(exc)  # kept: a library may swallow the exception (eyeviz.files.atomic)
    raise exc


def _note_interruption(exc: BaseException) -> None:
    """Replaced by :func:`eyeviz.files.atomic.note_interruption` once handlers are set."""


def install_signal_handlers() -> dict:
    """SIGINT, SIGTERM and SIGHUP end the command alike: an exception that unwinds every
    ``with``, and is remembered so no output is kept even where a library swallows it.

    Returns the previous handlers (for :func:`signal.signal` to put back)."""
    global _note_interruption
    from eyeviz.files import atomic  # imported here, never inside the handler

    atomic.clear_interruptions()
    _note_interruption = atomic.note_interruption
    old = {}
    for name in ("SIGINT", "SIGTERM", "SIGHUP"):
        sig = getattr(signal, name, None)
        if sig is not None:
            old[sig] = signal.signal(sig, _raise_interrupted)
    return old


class _QuietPipe:
    """A text stream that drops writes once its reader has gone (EPIPE)."""

    def __init__(self, stream):
        self._s = stream
        self.broken = False

    def write(self, text):
        if self.broken:
            return len(text)
        try:
            return self._s.write(text)
        except (BrokenPipeError, ValueError):
            self._break()
            return len(text)

    def flush(self):
        if self.broken:
            return
        try:
            self._s.flush()
        except (BrokenPipeError, ValueError):
            self._break()

    def _break(self):
        self.broken = True
        try:  # later flushes (at exit too) go to /dev/null instead of EPIPE
            devnull = os.open(os.devnull, os.O_WRONLY)
            os.dup2(devnull, self._s.fileno())
            os.close(devnull)
        except (OSError, ValueError):
            pass

    def __getattr__(self, name):
        return getattr(self._s, name)


def _fd_open(fd: int) -> bool:
    try:
        os.fstat(fd)
        return True
    except OSError:
        return False


def _safe_std_streams() -> None:
    for name, fd in (("stdout", 1), ("stderr", 2)):
        stream = getattr(sys, name)
        if stream is None or not _fd_open(fd):
            setattr(sys, name, open(os.devnull, "w"))  # noqa: SIM115 - for the process
        elif not isinstance(stream, _QuietPipe):
            setattr(sys, name, _QuietPipe(stream))


def _error(msg: str) -> None:
    text = " ".join(str(msg).split()) or "error"
    if len(text) > 500:
        text = text[:500] + "..."
    print(f"eyeviz: error: {text}", file=sys.stderr)


def build_parser(argv: list[str] | None = None):
    """The whole command line's parser. With ``argv`` (a command line whose first word is
    a command) only that command's options are built: a command's ``add_arguments`` may
    import what its defaults need (the report kinds import their modules), and a command
    line should pay for its own command only. ``eyeviz --help`` still lists every command
    with its help line; a command that takes ``argv`` in its ``add_arguments`` gets the
    words after its name (``report`` builds only the kind asked for)."""
    import argparse
    import inspect

    from eyeviz import __version__

    wanted = argv[0] if argv else None
    parser = argparse.ArgumentParser(
        prog="eyeviz",
        description="Planar binocular compound-eye model: app, datasets, estimators, reports.",
    )
    parser.add_argument("--version", action="version", version=f"eyeviz {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    for mod in _command_modules():
        p = sub.add_parser(mod.NAME, help=mod.HELP, description=mod.HELP)
        if wanted is None or wanted.startswith("-") or wanted == mod.NAME:
            if "argv" in inspect.signature(mod.add_arguments).parameters:
                rest = argv[1:] if argv and wanted == mod.NAME else None
                mod.add_arguments(p, argv=rest)
            else:
                mod.add_arguments(p)
        p.set_defaults(_run=mod.run, _outputs=getattr(mod, "OUTPUTS", None))
    _whole_floats_count(parser)
    return parser


def _int_option(text: str) -> int:
    """A count on the command line, by the package's one integer rule
    (:mod:`eyeviz.core.validation`, docs/contract.md): ``8`` or a float holding a whole
    number (``8.0``, ``1e6``), as a scene's ``nside = 8.0`` is; ``8.5`` is refused."""
    try:
        return int(text)
    except ValueError:
        v = float(text)  # ValueError: argparse says "invalid int value: '...'"
        if not v.is_integer():
            raise ValueError(text) from None
        return int(v)


_int_option.__name__ = "int"  # argparse names the type in its message


def _whole_floats_count(parser) -> None:
    """Every ``type=int`` option of ``parser`` and its sub-parsers takes
    :func:`_int_option` instead (issue 36: ``--nside 8.0`` was refused while a scene's
    ``nside = 8.0`` and ``study --nside 8.0`` were accepted)."""
    import argparse

    for action in parser._actions:
        if action.type is int:
            action.type = _int_option
        if isinstance(action, argparse._SubParsersAction):
            for sub in set(action.choices.values()):
                _whole_floats_count(sub)


@functools.cache
def _command_modules() -> tuple:
    """The command modules, in name order (walked once a process)."""
    import importlib
    import pkgutil

    from eyeviz import commands

    mods = []
    for info in sorted(pkgutil.iter_modules(commands.__path__), key=lambda i: i.name):
        if info.name.startswith("_"):
            continue
        mod = importlib.import_module(f"eyeviz.commands.{info.name}")
        if hasattr(mod, "run") and hasattr(mod, "add_arguments"):
            mods.append(mod)
    return tuple(mods)


def main(argv: list[str] | None = None) -> int:
    """Run one sub-command; return its exit code (0, 2 on a user error, 128+signal)."""
    streams = sys.stdout, sys.stderr
    _safe_std_streams()
    old_handlers: dict = {}
    try:
        argv = list(sys.argv[1:] if argv is None else argv)
        names = {mod.NAME for mod in _command_modules()}
        if not argv or argv[0] not in names and not argv[0].startswith("-"):
            argv = [DEFAULT_COMMAND, *argv]
        parser = build_parser(argv)
        args = parser.parse_args(argv)
        if getattr(args, "_run", None) is None:
            args = parser.parse_args([DEFAULT_COMMAND])
        if args.command != DEFAULT_COMMAND:
            old_handlers = install_signal_handlers()
        return _run(args)
    except KeyboardInterrupt as exc:  # before the command started (imports, parsing)
        return _interrupted(exc)
    finally:
        for sig, handler in old_handlers.items():
            signal.signal(sig, handler)
        for name, old in zip(("stdout", "stderr"), streams, strict=True):
            cur = getattr(sys, name)
            if isinstance(cur, _QuietPipe) and cur._s is old:
                cur.flush()
                setattr(sys, name, old)


def _one_line_warning(message, category, filename, lineno, file=None, line=None) -> None:
    """An eye file's size warning as one line (not Python's two, with the source line)."""
    from eyeviz.files.eye_io import EyeSizeWarning

    if issubclass(category, EyeSizeWarning):
        print(f"eyeviz: warning: {message}", file=sys.stderr if file is None else file)
    else:
        _SHOW_WARNING(message, category, filename, lineno, file, line)


def _run(args) -> int:
    from eyeviz import EyevizError

    try:
        from eyeviz.files.outputs import check_outputs

        check_outputs(args)  # -o a directory: refused before any work (issue 36)
        with warnings.catch_warnings():
            warnings.showwarning = _one_line_warning
            return int(args._run(args) or 0)
    except EyevizError as exc:
        _error(str(exc))
    except (ZeroDivisionError, FloatingPointError) as exc:  # never names a problem: a bug
        _unexpected(exc)
    except (ValueError, OSError, OverflowError, ArithmeticError) as exc:
        _error(str(exc) or type(exc).__name__)
    except RecursionError:
        _error("input nested too deeply")
    except MemoryError:
        _error("out of memory")
    except KeyboardInterrupt as exc:
        return _interrupted(exc)
    except Exception as exc:  # the last resort: a bug, but never a traceback for a user
        from eyeviz.files.atomic import pending_interruption

        # a signal inside compiled code surfaces as another exception (numba: SystemError)
        sig = pending_interruption()
        if sig is not None:
            return _interrupted(sig)
        _unexpected(exc)
    return 2


def _unexpected(exc: Exception) -> None:
    """A bug's one line (``EYEVIZ_DEBUG=1``: the traceback instead)."""
    if os.environ.get("EYEVIZ_DEBUG"):
        raise exc
    _error(f"unexpected {type(exc).__name__}: {exc} (EYEVIZ_DEBUG=1 shows the traceback)")


def _interrupted(exc: BaseException) -> int:
    name = getattr(exc, "signame", "SIGINT")
    what = "interrupted" if name == "SIGINT" else f"terminated by {name}"
    print(f"eyeviz: {what}; no partial output was kept", file=sys.stderr)
    return getattr(exc, "exit_code", 130)


if __name__ == "__main__":
    sys.exit(main())
