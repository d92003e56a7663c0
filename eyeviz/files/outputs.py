"""A command's output path, checked before any work (issue 36, item 7).

``eyeviz generate -o adir.npz``, where ``adir.npz`` is a directory, generated every row and
then failed on the final rename ("[Errno 21] Is a directory"). Every command declares its
outputs (``parser.set_defaults(_outputs={"output": "file"})``) and :func:`eyeviz.cli.main`
calls :func:`check_outputs` before the command runs, so such a run is refused in one line
naming the path before anything is computed.

Kinds: ``"file"`` (a file written through :func:`eyeviz.files.atomic.atomic_output`: not
a directory, its folder exists and is writable), ``"dir"`` (a report folder: not a file,
its nearest existing ancestor a writable folder, since a report makes the folders it
needs) and ``"path"`` (either: a model directory, or the bayes table's ``.npz``). A device
or FIFO is not refused here: what is written through it is :mod:`eyeviz.files.atomic`'s
rule.
"""

from __future__ import annotations

import os
from pathlib import Path

from eyeviz import EyevizError

__all__ = ["KINDS", "check_output", "check_outputs"]

KINDS = ("file", "dir", "path")


def _folder_ok(path: Path, folder: Path) -> None:
    if not folder.is_dir():
        what = "is not a folder" if folder.exists() else "does not exist"
        raise EyevizError(f"output {str(path)!r}: its folder {str(folder)!r} {what}")
    if not os.access(folder, os.W_OK | os.X_OK):
        raise EyevizError(f"output {str(path)!r}: its folder {str(folder)!r} is not writable")


def _existing_ancestor(path: Path) -> Path:
    p = path.parent if str(path.parent) else Path(".")
    while not os.path.lexists(p) and p != p.parent:
        p = p.parent
    return p


def check_output(path, kind: str = "file") -> Path:
    """``path`` as a Path when a command may write it as ``kind`` (:data:`KINDS`); else
    one :class:`EyevizError` line naming the path and what is wrong with it."""
    if kind not in KINDS:
        raise ValueError(f"kind must be one of {KINDS}, got {kind!r}")
    p = Path(path)
    if not str(path):
        raise EyevizError("output: an empty path")
    if kind == "file":
        if p.is_dir():
            raise EyevizError(f"output {str(p)!r} is a directory; give a file name")
        _folder_ok(p, p.parent if str(p.parent) else Path("."))
        return p
    if kind == "dir":
        if p.exists() and not p.is_dir():
            raise EyevizError(f"output {str(p)!r} is not a folder (a report writes a folder)")
        if p.is_dir():
            _folder_ok(p, p)
            return p
    _folder_ok(p, _existing_ancestor(p))
    return p


def check_outputs(args) -> None:
    """Check each output a command declared in ``args._outputs`` ({attribute: kind}) and
    was given (an option left at None is the command's default place: not checked)."""
    for attr, kind in (getattr(args, "_outputs", None) or {}).items():
        value = getattr(args, attr, None)
        if value is not None:
            check_output(value, kind)
