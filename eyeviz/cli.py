"""The ``eyeviz`` command line (DESIGN.md §3).

Sub-commands are discovered from :mod:`eyeviz.commands`. Every error a user can cause
ends in a one-line message on stderr and a non-zero exit, never a traceback.
"""

from __future__ import annotations

import argparse
import importlib
import pkgutil
import sys

from eyeviz import EyevizError, __version__, commands

DEFAULT_COMMAND = "app"


def _command_modules() -> list:
    mods = []
    for info in sorted(pkgutil.iter_modules(commands.__path__), key=lambda i: i.name):
        if info.name.startswith("_"):
            continue
        mod = importlib.import_module(f"eyeviz.commands.{info.name}")
        if hasattr(mod, "run") and hasattr(mod, "add_arguments"):
            mods.append(mod)
    return mods


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="eyeviz",
        description="Planar binocular compound-eye model: app, datasets, estimators, reports.",
    )
    parser.add_argument("--version", action="version", version=f"eyeviz {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    for mod in _command_modules():
        p = sub.add_parser(mod.NAME, help=mod.HELP, description=mod.HELP)
        mod.add_arguments(p)
        p.set_defaults(_run=mod.run)
    return parser


def main(argv: list[str] | None = None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    parser = build_parser()
    if (
        not argv
        or argv[0] not in parser._subparsers._group_actions[0].choices
        and not argv[0].startswith("-")
    ):
        argv = [DEFAULT_COMMAND, *argv]
    args = parser.parse_args(argv)
    if getattr(args, "_run", None) is None:
        args = parser.parse_args([DEFAULT_COMMAND])
    try:
        return int(args._run(args) or 0)
    except EyevizError as exc:
        print(f"eyeviz: error: {exc}", file=sys.stderr)
        return 2
    except (ValueError, OSError) as exc:
        print(f"eyeviz: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("eyeviz: interrupted; no partial output was kept", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
