"""The data set formats, one per kind of eye design: the one registry that ``eyeviz
generate``, ``eyeviz predict``, the reports and the study go through.

A data set names its eyes by its design (:func:`eyeviz.core.eyes.design_kind`): a planar
file (CSV, or an NPZ whose meta has ``m``), a sparse one of HEALPix eyes (meta
``format`` ``eyeviz.sparse3d``, domain with ``nside``) or of a measured pair (domain with
``eye``, the pair's fingerprint; the arrays embedded). :func:`kind_of` reads that kind
from the file's bounded ``meta`` member (never the rows). :data:`FORMATS` maps each kind
to its :class:`DataFormat`: how its files are read (block by block, or whole), written
(Algorithm 1 straight into a file), sampled in memory (the reports' and the study's test
sets) and what ``predict`` writes and says for each row (:class:`RowFormat`; the one run
loop over the rows is ``eyeviz.commands.predict``'s). The callers ask by kind:
:func:`open_reader`, :func:`load`, :func:`write`, :func:`sample`, :func:`chunks`; a kind
nobody registered is refused in one line naming it and the known ones
(:func:`data_format`). A new eye model adds its kind with :func:`register_format`
(docs/extending.md; ``tests/test_toy_model.py`` registers a toy kind of its own).

>>> sorted(FORMATS)
['measured', 'planar', 'spherical']
>>> FORMATS["measured"].rows.header
'r_hat,azimuth_hat,elevation_hat,flagged'
"""

from __future__ import annotations

import importlib
import json
import os
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from eyeviz import EyevizError
from eyeviz.core.eyes import design_kind
from eyeviz.files.npz import NpzReader

__all__ = [
    "FORMATS",
    "PLANAR_ROWS",
    "SPARSE_FORMAT",
    "SPARSE_ROWS",
    "DataFormat",
    "RowFormat",
    "chunks",
    "data_format",
    "kind_of",
    "load",
    "open_reader",
    "register_format",
    "register_reader",
    "sample",
    "write",
]

#: The ``format`` of a sparse data set's meta (:data:`eyeviz.dataset.sparse3d.FORMAT`).
SPARSE_FORMAT = "eyeviz.sparse3d"
_META_MAX_BYTES = 1 << 20


@dataclass(frozen=True)
class RowFormat:
    """What ``eyeviz predict`` writes and says for the rows of one kind of data set.

    The answer of ``est.predict_dataset(block)`` is a tuple of coordinates (its ``coords``)
    with masks: ``valid`` (the row has an answer by definition) and the mask counted
    aside (:attr:`aside`). The CSV has :attr:`header`'s columns: the coordinates, then
    the ``flagged`` mask as 0/1 when :attr:`flag_column`."""

    #: the output CSV's header line (without the newline)
    header: str
    #: the block's attributes the answer's coordinates are compared with, in order
    truth: tuple[str, ...]
    #: whether the answer's ``flagged`` mask is the CSV's last column (0/1)
    flag_column: bool
    #: the rows with no answer by definition, after their count ("... (nan)")
    no_answer: str
    #: the rows that should have an answer, in the unanswered warning
    answerable: str
    #: the mask counted aside: a function of (answer, valid)
    aside: Callable[[Any, Any], Any]
    #: how the aside count is said: ``{k}`` the count, ``{name}`` the estimator
    aside_text: str
    #: the metrics line, ``{0}``, ``{1}``, ... the metrics of each coordinate
    #: (:class:`eyeviz.estimators.metrics.RunningSummary`)
    summary: str


def _outside(pred: Any, valid: Any) -> Any:
    import numpy as np

    return valid & ~np.asarray(pred.in_domain)


def _flagged(pred: Any, valid: Any) -> Any:
    import numpy as np

    return np.asarray(pred.flagged, bool)


#: The planar rows: (r, phi) from the half bitmaps.
PLANAR_ROWS = RowFormat(
    header="r_hat,phi_hat",
    truth=("r", "phi"),
    flag_column=False,
    no_answer="not a single feature (nan)",
    answerable="single-feature rows",
    aside=_outside,
    aside_text="; {k} outside the training domain",
    summary=(
        "DD MAPE {0[mape]:.3f} %  MAE {0[mae]:.2f}  R^2 {0[r2]:.4f} | "
        "AD MAPE {1[mape]:.4f} %  MAE {1[mae]:.3g} rad  R^2 {1[r2]:.6f}"
    ),
)

#: The rows of lit sets in space: (r, azimuth, elevation) and a ``flagged`` column.
SPARSE_ROWS = RowFormat(
    header="r_hat,azimuth_hat,elevation_hat,flagged",
    truth=("r", "azimuth", "elevation"),
    flag_column=True,
    no_answer="with an eye that lit nothing (nan)",
    answerable="rows where both eyes lit facets",
    aside=_flagged,
    aside_text=(
        "; {k} flagged (column 'flagged' = 1: answered by {name}'s fallback or outside "
        "its domain; not its own answer)"
    ),
    summary=(
        "DD MAPE {0[mape]:.3f} %  MAE {0[mae]:.2f} | azimuth MAE {1[mae]:.3g} rad | "
        "elevation MAE {2[mae]:.3g} rad"
    ),
)


@dataclass(frozen=True)
class DataFormat:
    """How the data sets of one kind of eyes are read, written and predicted on. Each
    callable is ``"module:callable"`` (imported on first use) or a callable:

    - ``reader(path, **kw)``: a block reader, an iterable of blocks (rows with the
      model's data and the truth of :attr:`RowFormat.truth`) with ``.domain`` when the
      file carries its whole domain (:attr:`domain_flags` False), else ``.eyes``;
    - ``loader(path)``: the whole data set in memory;
    - ``writer(path, n, domain, *, mode, seed, segments, progress, **kw)``: Algorithm 1's
      n rows straight into ``path``, every parameter checked first;
    - ``sampler(n, domain, mode, seed)``: n rows in memory;
    - ``chunker(n, domain, mode, seed)``: the same rows chunk by chunk.
    """

    kind: str
    reader: str | Callable[..., Any]
    loader: str | Callable[..., Any]
    writer: str | Callable[..., Any]
    sampler: str | Callable[..., Any]
    chunker: str | Callable[..., Any]
    rows: RowFormat
    #: what a refusal calls one of its files ("a planar data set")
    what: str
    #: the ``format`` its NPZ meta declares (None: no ``format`` key, the planar NPZ)
    meta_format: str | None = None
    #: whether the data's design and ranges may come from ``--h --l --m --r-min --r-max
    #: --g-max`` (a CSV carries none); False: the file carries its whole domain
    domain_flags: bool = False

    def call(self, what: str, *args: Any, **kw: Any) -> Any:
        """Call the format's ``what`` (``"reader"``, ``"writer"``, ...)."""
        target = getattr(self, what)
        if isinstance(target, str):
            mod, _, attr = target.partition(":")
            target = getattr(importlib.import_module(mod), attr)
        return target(*args, **kw)


def _sparse(kind: str, what: str) -> DataFormat:
    return DataFormat(
        kind,
        reader="eyeviz.dataset.sparse3d:Sparse3DReader",
        loader="eyeviz.dataset.sparse3d:load3d",
        writer="eyeviz.dataset.sparse3d:write3d",
        sampler="eyeviz.dataset.algorithm1_3d:generate3d",
        chunker="eyeviz.dataset.algorithm1_3d:chunks_domain3d",
        rows=SPARSE_ROWS,
        what=what,
        meta_format=SPARSE_FORMAT,
    )


#: kind -> its :class:`DataFormat`: the planar eyes' CSV and NPZ of half bitmaps
#: (:mod:`eyeviz.dataset.io`, :mod:`eyeviz.dataset.reader`), and the sparse lit sets of
#: the eyes in space (:mod:`eyeviz.dataset.sparse3d`), HEALPix or measured.
FORMATS: dict[str, DataFormat] = {
    "planar": DataFormat(
        "planar",
        reader="eyeviz.dataset.reader:iter_blocks",
        loader="eyeviz.dataset.reader:load",
        writer="eyeviz.dataset.algorithm1:write",
        sampler="eyeviz.dataset.algorithm1:sample_domain",
        chunker="eyeviz.dataset.algorithm1:chunks_domain",
        rows=PLANAR_ROWS,
        what="a planar data set",
        domain_flags=True,
    ),
    "spherical": _sparse("spherical", "a sparse 3D data set"),
    "measured": _sparse("measured", "a measured-eye data set"),
}


def register_format(fmt: DataFormat, *, replace: bool = False) -> DataFormat:
    """Read, write and predict on the data sets of eyes of kind ``fmt.kind`` with ``fmt``;
    ValueError for a kind that is not a word or is taken (unless ``replace``)."""
    if not fmt.kind.isidentifier():
        raise ValueError(f"a data set format's kind must be a word, got {fmt.kind!r}")
    if fmt.kind in FORMATS and not replace:
        raise ValueError(f"a data set format for eyes of kind {fmt.kind!r} is registered")
    FORMATS[fmt.kind] = fmt
    return fmt


def unregister_format(kind: str) -> None:
    FORMATS.pop(kind, None)


def register_reader(kind: str, target: str) -> None:
    """Open files of eye-design ``kind`` with ``target`` (``"module:callable"``): the
    kind's format with its reader replaced (the kind must have a format)."""
    if not kind.isidentifier() or ":" not in target:
        raise ValueError(
            f"a reader is registered as kind, 'module:callable'; got {kind!r}, {target!r}"
        )
    from dataclasses import replace

    FORMATS[kind] = replace(data_format(kind), reader=target)


def _known() -> str:
    return ", ".join(sorted(FORMATS))


def data_format(kind: str) -> DataFormat:
    """The format of eyes of ``kind``; EyevizError (one line) naming the kind and the
    known ones otherwise."""
    fmt = FORMATS.get(kind)
    if fmt is None:
        raise EyevizError(f"no data set format for eyes of kind {kind!r} (known kinds: {_known()})")
    return fmt


def _read_meta(p: Path) -> Any:
    with NpzReader(p) as npz:
        arr = npz.read_member("meta", 1, dtypes=("U",), ndim=0, max_bytes=_META_MAX_BYTES)
    return json.loads(str(arr[()]))


def kind_of(path: str | os.PathLike) -> str:
    """The eye-design kind of data set ``path``: ``"planar"`` for a CSV and for a file
    whose meta cannot be read (the planar reader then names what is wrong); else the
    ``kind`` its meta states, or the kind of the format its meta declares (a format that
    several kinds share, as the sparse one: the kind of the design in its ``domain``;
    one that names no kind there is the first such kind, whose reader names the problem).
    EyevizError (one line) for a kind or format no registered kind has."""
    p = Path(path)
    if p.suffix.lower() != ".npz":
        return "planar"
    try:
        meta = _read_meta(p)
    except Exception:  # noqa: BLE001 - unreadable: left to the planar reader's message
        return "planar"
    if not isinstance(meta, dict):
        return "planar"
    if isinstance(meta.get("kind"), str):
        data_format(meta["kind"])  # a kind nobody registered: one line naming it
        return meta["kind"]
    fmt = meta.get("format")
    if fmt is None:
        return "planar"
    kinds = [k for k, f in FORMATS.items() if f.meta_format == fmt]
    if not kinds:
        raise EyevizError(
            f"{p}: a data set of format {str(fmt)[:80]!r}, which no kind of eyes reads "
            f"(known kinds: {_known()})"
        )
    dom = meta.get("domain")
    try:
        kind = design_kind(dom) if isinstance(dom, dict) else kinds[0]
    except EyevizError:
        return kinds[0]
    return kind if kind in kinds else kinds[0]


def open_reader(path: str | os.PathLike, kind: str | None = None, **kw: Any):
    """The block reader of ``path`` for its kind (:func:`kind_of` unless given)."""
    kind = kind_of(path) if kind is None else kind
    return data_format(kind).call("reader", path, **kw)


def load(path: str | os.PathLike, kind: str | None = None):
    """The whole data set ``path`` in memory, read by its kind's format."""
    kind = kind_of(path) if kind is None else kind
    return data_format(kind).call("loader", path)


def write(path: str | os.PathLike, n: int, domain: Any, **kw: Any) -> None:
    """Algorithm 1's ``n`` rows of ``domain``'s eyes straight into ``path``, by the
    format of ``domain.kind`` (``mode``, ``seed``, ``segments``, ``progress`` and the
    format's own options as keywords)."""
    data_format(domain.kind).call("writer", path, n, domain, **kw)


def sample(n: int, domain: Any, mode: str = "single", seed: int = 0):
    """Algorithm 1's ``n`` rows of ``domain``'s eyes in memory (a test set)."""
    return data_format(domain.kind).call("sampler", n, domain, mode, seed)


def chunks(n: int, domain: Any, mode: str = "single", seed: int = 0) -> Iterator[Any]:
    """The same rows as :func:`sample`, chunk by chunk (bounded memory)."""
    return data_format(domain.kind).call("chunker", n, domain, mode, seed)
