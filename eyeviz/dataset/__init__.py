"""Algorithm 1 (single- and multi-pass) and the paper's data set files (CSV, NPZ).

Stable public path ``eyeviz.dataset``: :mod:`eyeviz.dataset.records` holds the records of
every eye model (:class:`Dataset`, :class:`Chunk`, :class:`Dataset3D`; a leaf),
:mod:`eyeviz.dataset.algorithm1` samples,
:mod:`eyeviz.dataset.io` reads and writes. Every generator function takes the one
parameter record, :class:`eyeviz.core.domain.Domain`, in place of ``eyes`` (or the eyes
and ranges separately); the defaults are Tables 3-4 (``eyeviz.core.domain.DEFAULTS``).
The spherical (3D) model's sparse data set: :mod:`eyeviz.dataset.algorithm1_3d` samples,
:mod:`eyeviz.dataset.sparse3d` writes and reads (:class:`Dataset3D`, over the record
:class:`eyeviz.core.domain.Domain3D`).
"""

from eyeviz.core.domain import Domain
from eyeviz.dataset.algorithm1 import (
    CHUNK,
    MODES,
    PAPER_EYES,
    Chunk,
    Dataset,
    GenParams,
    check_n,
    effective_r_max,
    generate,
    iter_chunks,
    iter_generate,
    load,
    make_params,
    save,
    segment_plan,
    write,
)
from eyeviz.dataset.algorithm1_3d import generate3d, iter_chunks3d, make_params3d
from eyeviz.dataset.records import Dataset3D
from eyeviz.dataset.sparse3d import Sparse3DReader, load3d, write3d

__all__ = [
    "Domain",
    "CHUNK",
    "MODES",
    "Chunk",
    "Dataset",
    "GenParams",
    "check_n",
    "effective_r_max",
    "iter_chunks",
    "make_params",
    "segment_plan",
    "PAPER_EYES",
    "generate",
    "iter_generate",
    "load",
    "save",
    "write",
    "Dataset3D",
    "Sparse3DReader",
    "generate3d",
    "iter_chunks3d",
    "load3d",
    "make_params3d",
    "write3d",
]
