"""One eye's lit sets as CSR rows: checked input, and rows taken in any order.

The estimators of the eyes in space (:class:`eyeviz.estimators.base.Estimator3D`) take an
eye's lit facets as CSR rows ``(indptr, indices)`` (:data:`LitCSR`): row i lit the sorted
facet indices ``indices[indptr[i]:indptr[i + 1]]``, as the 3D data set stores them
(:class:`eyeviz.dataset.records.Dataset3D`, ``EyePair3D.lit_csr``), or as dense bitmaps,
which :func:`as_csr` turns into CSR rows. This module imports numpy only.
"""

from __future__ import annotations

from typing import Any

import numpy as np

__all__ = ["LitCSR", "as_csr", "take_rows"]

#: One eye's lit sets as CSR rows: (indptr int (n + 1,), indices int (nnz,)).
LitCSR = tuple[np.ndarray, np.ndarray]

#: indices per pass of the sortedness check (its temporaries stay in cache)
_CHECK_BLOCK = 1 << 16


def _check_indices(name: str, ptr: np.ndarray, ind: np.ndarray, npix: int) -> None:
    """Range by min/max; sortedness by one difference pass in cache-sized blocks: every
    step that does not rise must land on a row start (an ``indptr`` entry). No copy of
    ``indices``."""
    if ind.size == 0:
        return
    lo, hi = int(ind.min()), int(ind.max())
    if lo < 0 or hi >= npix:
        bad = lo if lo < 0 else hi
        raise ValueError(f"{name}: indices must lie in [0, npix = {npix}), got {bad}")
    m = ind.size - 1  # steps
    if m == 0:
        return
    k = min(_CHECK_BLOCK, m)
    step = np.empty(k, ind.dtype)  # in range, so no step overflows the dtype
    down = np.empty(k, bool)
    for s in range(0, m, _CHECK_BLOCK):
        e = min(s + _CHECK_BLOCK, m)
        np.subtract(ind[s + 1 : e + 1], ind[s:e], out=step[: e - s])
        np.less_equal(step[: e - s], 0, out=down[: e - s])
        at = np.flatnonzero(down[: e - s])
        if at.size:
            nxt = at + (s + 1)  # where the non-rising step lands
            pos = np.searchsorted(ptr, nxt)
            if not np.array_equal(ptr[np.minimum(pos, ptr.size - 1)], nxt):
                raise ValueError(f"{name}: indices must increase strictly within a row")


def as_csr(
    name: str, lit: Any, npix: int, *, check_indices: bool = True
) -> tuple[np.ndarray, np.ndarray, bool]:
    """(indptr int64, indices, single) from CSR rows ``(indptr, indices)`` or dense
    bitmaps (npix,) / (N, npix); ``single`` is True for one 1-D bitmap. ValueError in one
    line naming ``name`` for anything else (wrong shape, non-binary values, indices out
    of [0, npix) or not increasing within a row, an indptr that does not fit). CSR
    indices of int64, or of int32 when npix < 2^31, are returned as given (no copy); other
    integer types, and dense bitmaps, as int64.

    ``check_indices=False`` leaves out the one pass over the CSR indices (range and
    order) for a caller that makes it itself (:meth:`Estimator3D.predict` for an
    estimator with ``checks_indices``); every other check is made."""
    if isinstance(lit, tuple):
        if len(lit) != 2:
            raise ValueError(f"{name} must be (indptr, indices) or bitmaps, got a {len(lit)}-tuple")
        ptr = np.asarray(lit[0])
        ind = np.asarray(lit[1])
        if ptr.ndim != 1 or ptr.size < 1 or ptr.dtype.kind not in "iu":
            raise ValueError(f"{name}: indptr must be a 1-D integer array of length n + 1")
        if ind.ndim != 1 or (ind.size and ind.dtype.kind not in "iu"):
            raise ValueError(f"{name}: indices must be a 1-D integer array")
        ptr = ptr.astype(np.int64, copy=False)
        if ptr[0] != 0 or ptr[-1] != ind.size or np.any(np.diff(ptr) < 0):
            raise ValueError(
                f"{name}: indptr must start at 0, not decrease and end at len(indices) = {ind.size}"
            )
        if not (ind.dtype == np.int64 or (ind.dtype == np.int32 and npix < 2**31)):
            ind = ind.astype(np.int64)
        if check_indices:
            _check_indices(name, ptr, ind, npix)
        return ptr, ind, False
    try:
        a = np.asarray(lit)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be (indptr, indices) or bitmaps") from None
    if a.ndim not in (1, 2) or a.shape[-1] != npix:
        raise ValueError(
            f"{name} must be (indptr, indices) or bitmaps of shape (npix,) or (N, npix) with "
            f"npix = {npix}, got shape {a.shape}"
        )
    if a.dtype != np.bool_:
        if a.dtype.kind not in "biuf" or not np.isin(a, (0, 1)).all():
            raise ValueError(f"{name} bitmaps must hold 0/1 values")
        a = a != 0
    single = a.ndim == 1
    a = a.reshape(-1, npix)
    rows, cols = np.nonzero(a)
    ptr = np.zeros(a.shape[0] + 1, np.int64)
    np.cumsum(np.bincount(rows, minlength=a.shape[0]), out=ptr[1:])
    return ptr, cols.astype(np.int64), single


def take_rows(indptr: np.ndarray, indices: np.ndarray, rows: np.ndarray) -> LitCSR:
    """The CSR rows ``rows`` (in that order) of (indptr, indices)."""
    rows = np.asarray(rows, np.int64)
    lens = (indptr[1:] - indptr[:-1])[rows]
    out_ptr = np.zeros(rows.size + 1, np.int64)
    np.cumsum(lens, out=out_ptr[1:])
    src = np.repeat(indptr[rows] - out_ptr[:-1], lens) + np.arange(int(out_ptr[-1]))
    return out_ptr, indices[src]
