"""Algorithm 1 (single- and multi-pass) and the paper's data set files (CSV, NPZ).

Stable public path ``eyeviz.dataset``: :mod:`eyeviz.dataset.records` holds the records
(:class:`Dataset`, :class:`Chunk`; a leaf), :mod:`eyeviz.dataset.algorithm1` samples,
:mod:`eyeviz.dataset.io` reads and writes. Every generator function takes the one
parameter record, :class:`eyeviz.core.domain.Domain`, in place of ``eyes`` (or the eyes
and ranges separately); the defaults are Tables 3-4 (``eyeviz.core.domain.DEFAULTS``).
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
]
