"""Append-only spool files, one per member of a streamed NPZ (eyeviz.dataset.sparse3d).

Each chunk's arrays are appended raw to the spool of their member; the zip is assembled
at the end by copying each spool into a member whose ``.npy`` header then knows its
length. Spools are temporary files of :mod:`eyeviz.files.atomic`'s naming, next to the
output, removed by :meth:`Spools.close`.
"""

from __future__ import annotations

import contextlib
import shutil
import zipfile
from pathlib import Path
from typing import BinaryIO

import numpy as np

from eyeviz.files.atomic import part_name

__all__ = ["Spools"]

_COPY = 8 << 20  # bytes per copy from a spool into the zip


class Spools:
    """One append-only raw file per member, next to the output (removed by :meth:`close`)."""

    def __init__(self, target: Path, members: tuple[str, ...]):
        d = target.parent if str(target.parent) else Path(".")
        self.paths: dict[str, Path] = {}
        self.files: dict[str, BinaryIO] = {}
        self.counts = dict.fromkeys(members, 0)
        self.dtypes: dict[str, np.dtype] = {}
        try:
            for name in members:
                p = d / part_name(target)
                self.files[name] = open(p, "xb")  # noqa: SIM115 - closed in close()
                self.paths[name] = p
        except BaseException:
            self.close()
            raise

    def append(self, name: str, a: np.ndarray) -> None:
        a = np.ascontiguousarray(a)
        self.dtypes.setdefault(name, a.dtype)
        self.files[name].write(a.data)
        self.counts[name] += a.shape[0]

    def close(self) -> None:
        for f in self.files.values():
            with contextlib.suppress(OSError):
                f.close()
        for p in self.paths.values():
            with contextlib.suppress(OSError):
                p.unlink()

    def copy_into(self, zf: zipfile.ZipFile, name: str) -> None:
        """Member ``name.npy`` from the spool (header from its dtype and count)."""
        self.files[name].flush()
        header = {
            "descr": np.lib.format.dtype_to_descr(self.dtypes[name]),
            "fortran_order": False,
            "shape": (self.counts[name],),
        }
        with zf.open(name + ".npy", "w", force_zip64=True) as out:
            np.lib.format.write_array_header_1_0(out, header)
            with open(self.paths[name], "rb") as src:
                shutil.copyfileobj(src, out, _COPY)
