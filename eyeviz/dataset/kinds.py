"""Data set formats by the kind of eye design a file declares: one reader per kind.

A data set names its eyes by its design (:func:`eyeviz.core.eyes.design_kind`): a planar
file (CSV, or an NPZ whose meta has ``m``), a sparse one of HEALPix eyes (meta
``format`` ``eyeviz.sparse3d``, domain with ``nside``) or of a measured pair (domain with
``eye``, the pair's fingerprint; the arrays embedded). :func:`kind_of` reads that design
from the file's bounded ``meta`` member (never the rows), and :data:`READERS` maps each
kind to the reader that checks everything else; ``eyeviz predict`` and the reports open
files through :func:`open_reader`. A new eye model adds its kind here with
:func:`register_reader` (docs/extending.md).

>>> sorted(READERS)
['measured', 'planar', 'spherical']
"""

from __future__ import annotations

import importlib
import json
import os
from pathlib import Path
from typing import Any

from eyeviz import EyevizError
from eyeviz.core.eyes import design_kind
from eyeviz.files.npz import NpzReader

__all__ = ["READERS", "SPARSE_FORMAT", "kind_of", "open_reader", "register_reader"]

#: The ``format`` of a sparse data set's meta (:data:`eyeviz.dataset.sparse3d.FORMAT`).
SPARSE_FORMAT = "eyeviz.sparse3d"
_META_MAX_BYTES = 1 << 20

#: kind -> ``"module:callable"`` opening a block reader of that kind's files: the planar
#: :func:`eyeviz.dataset.io.iter_blocks` (``.eyes``, blocks of bitmaps) or
#: :class:`eyeviz.dataset.sparse3d.Sparse3DReader` (``.domain``, blocks of CSR rows).
READERS: dict[str, str] = {
    "planar": "eyeviz.dataset.io:iter_blocks",
    "spherical": "eyeviz.dataset.sparse3d:Sparse3DReader",
    "measured": "eyeviz.dataset.sparse3d:Sparse3DReader",
}


def register_reader(kind: str, target: str) -> None:
    """Open files of eye-design ``kind`` with ``target`` (``"module:callable"``)."""
    if not kind.isidentifier() or ":" not in target:
        raise ValueError(
            f"a reader is registered as kind, 'module:callable'; got {kind!r}, {target!r}"
        )
    READERS[kind] = target


def kind_of(path: str | os.PathLike) -> str:
    """The eye-design kind of data set ``path``: ``"planar"`` for a CSV and for a file
    whose meta cannot be read (the planar reader then names what is wrong), else the
    kind of the design its meta declares. A sparse file whose domain names no kind is
    ``"spherical"``, whose reader names the problem."""
    p = Path(path)
    if p.suffix.lower() != ".npz":
        return "planar"
    try:
        with NpzReader(p) as npz:
            arr = npz.read_member("meta", 1, dtypes=("U",), ndim=0, max_bytes=_META_MAX_BYTES)
        meta = json.loads(str(arr[()]))
    except Exception:  # noqa: BLE001 - unreadable: left to the planar reader's message
        return "planar"
    if not isinstance(meta, dict):
        return "planar"
    if meta.get("format") != SPARSE_FORMAT:
        return "planar"
    dom = meta.get("domain")
    try:
        return design_kind(dom) if isinstance(dom, dict) else "spherical"
    except EyevizError:
        return "spherical"


def open_reader(path: str | os.PathLike, kind: str | None = None, **kw: Any):
    """The reader of ``path`` for its kind (:func:`kind_of` unless given)."""
    kind = kind_of(path) if kind is None else kind
    target = READERS.get(kind)
    if target is None:
        raise EyevizError(f"no data set reader for eyes of kind {kind!r}")
    mod, _, attr = target.partition(":")
    return getattr(importlib.import_module(mod), attr)(path, **kw)
