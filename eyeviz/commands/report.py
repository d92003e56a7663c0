"""``eyeviz report KIND ... -o DIR``: reports as Markdown + CSV + PNG.

Each kind is a module with ``HELP``, ``add_arguments`` and ``run(args) -> int``: the
package's own live in ``eyeviz.reports.<kind>``; :func:`register` adds another (a plug-in
module of any name, docs/extending.md). Kinds whose module is absent are not offered.

Every report is written into a staging folder beside ``-o DIR`` and moved in only when it
is complete (:func:`eyeviz.files.atomic.atomic_folder`): an interrupted report leaves DIR
as it was, never old and new files side by side (issue 35). What the report prints comes
out once its files are in place, naming DIR.
"""

from __future__ import annotations

import argparse
import contextlib
import importlib
import io
import sys
from pathlib import Path

NAME = "report"
HELP = "write a report (Markdown, CSV and plots) into a directory"
#: What the command writes, checked before any work (eyeviz.files.outputs).
OUTPUTS = {"output": "dir"}
KINDS = (
    "stability",
    "dataset",
    "estimators",
    "trajectories",
    "study",
    "atlas",
    "renderers",
    "information",
)
#: kind -> module path: the package's reports, then any registered with :func:`register`.
MODULES: dict[str, str] = {kind: f"eyeviz.reports.{kind}" for kind in KINDS}


def register(kind: str, module: str) -> None:
    """Offer ``eyeviz report KIND``, run by ``module`` (importable, with ``HELP``,
    ``add_arguments(parser)`` and ``run(args) -> int``). ValueError for a taken kind."""
    if not kind.isidentifier():
        raise ValueError(f"a report kind must be an identifier, got {kind!r}")
    if kind in MODULES and MODULES[kind] != module:
        raise ValueError(f"report kind {kind!r} is taken by {MODULES[kind]}")
    MODULES[kind] = module


def add_arguments(parser: argparse.ArgumentParser, argv: list[str] | None = None) -> None:
    """One sub-parser per kind. Given the words after ``report`` (``argv``), only the kind
    they name imports its module and builds its options: a report's module may import
    matplotlib, scipy or torch, and ``report study`` should not pay for the others."""
    wanted = argv[0] if argv else None
    every = wanted is None or wanted.startswith("-") or wanted not in MODULES
    sub = parser.add_subparsers(dest="kind", metavar="KIND", required=True)
    for kind, path in MODULES.items():
        if not every and kind != wanted:
            sub.add_parser(kind)
            continue
        try:
            mod = importlib.import_module(path)
        except ModuleNotFoundError as exc:
            if exc.name == path:
                continue
            raise
        p = sub.add_parser(kind, help=mod.HELP, description=mod.HELP)
        mod.add_arguments(p)
        p.set_defaults(_report=mod.run)


def run(args: argparse.Namespace) -> int:
    from eyeviz.files.atomic import atomic_folder

    # the package's reports take -o/--output; a plug-in may call it --out
    dest = next((d for d in ("output", "out") if isinstance(getattr(args, d, None), Path)), None)
    if dest is None:
        return args._report(args)
    out = getattr(args, dest)
    printed = io.StringIO()
    with atomic_folder(out) as stage:
        setattr(args, dest, stage)
        try:
            with contextlib.redirect_stdout(printed):
                code = args._report(args)
        finally:
            setattr(args, dest, out)
    sys.stdout.write(printed.getvalue().replace(str(stage), str(out)))
    return code
