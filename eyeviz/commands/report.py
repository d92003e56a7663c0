"""``eyeviz report KIND ... -o DIR``: reports as Markdown + CSV + PNG.

Each kind is a module ``eyeviz.reports.<kind>`` with ``HELP``, ``add_arguments`` and
``run(args) -> int``; kinds whose module is absent are not offered.
"""

from __future__ import annotations

import argparse
import importlib

NAME = "report"
HELP = "write a report (Markdown, CSV and plots) into a directory"
KINDS = ("stability", "dataset", "estimators", "trajectories", "study")


def add_arguments(parser: argparse.ArgumentParser) -> None:
    sub = parser.add_subparsers(dest="kind", metavar="KIND", required=True)
    for kind in KINDS:
        try:
            mod = importlib.import_module(f"eyeviz.reports.{kind}")
        except ModuleNotFoundError as exc:
            if exc.name == f"eyeviz.reports.{kind}":
                continue
            raise
        p = sub.add_parser(kind, help=mod.HELP, description=mod.HELP)
        mod.add_arguments(p)
        p.set_defaults(_report=mod.run)


def run(args: argparse.Namespace) -> int:
    return args._report(args)
