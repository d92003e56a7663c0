"""Lit intervals (Prop. 2, Eq. 11) expanded to bitmaps at memory speed.

An eye lights ``{k mod m : L <= k <= R}`` with ``0 <= L < m`` and ``L <= R < L + m``; its
bitmap over ommatidia ``0..width-1`` (width = m for the whole eye, m // 2 for the paper's
Omega, Section 4) is at most two runs of ones: ``[L, min(R, m - 1)]`` and, when the run
wraps past m - 1, ``[0, R - m]``, both cut at width.

* :func:`bool_bitmaps` (one byte per bit, numpy bool): every row of the output is one
  memcpy of a window into a small table. For each run length c the table holds
  ``width`` zeros, c ones, then zeros; the row of a run starting at s is the window
  that starts ``width - s`` into it. Rows are gathered by fancy indexing on a strided
  view of the table, so each output byte is written once (a plain ``np.zeros`` + fill
  writes it once too; the benchmark compares the two in one run). Rows that wrap OR a
  second window into theirs.
* :func:`packed_bitmaps` (``np.packbits`` layout, 8 bits per byte, most significant
  first) never materialises one byte per bit: each packed row is ``GE[s] & LE[e]`` from
  two packed tables of (width + 1) rows, or computed per byte for very wide eyes.

Tables are cached per width (about 2 width^2 bytes for the bool table, used up to
width 2048; wider eyes use a comparison per bit in cache-sized blocks).
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np
from numpy.lib.stride_tricks import as_strided

__all__ = ["bool_bitmaps", "packed_bitmaps", "runs"]

_WINDOW_MAX_W = 2048  # bool window table: 2 * w * (w + 1) bytes (8.4 MB at 2048)
_PACKED_TABLE_MAX_W = 8192  # packed tables: 2 * (w + 1) * w / 8 bytes (16.8 MB at 8192)


def runs(L, R, m: int, width: int) -> tuple[np.ndarray, ...]:
    """(s1, e1, e2) int64: first run [s1, e1] (empty when e1 < s1), second [0, e2]
    (empty when e2 < 0), both already cut to ``0..width-1``."""
    L = np.asarray(L, dtype=np.int64)
    R = np.asarray(R, dtype=np.int64)
    e1 = np.minimum(np.minimum(R, m - 1), width - 1)
    e2 = np.minimum(R - m, width - 1)
    return L, e1, e2


@lru_cache(maxsize=4)
def _window_table(w: int) -> tuple[np.ndarray, np.ndarray]:
    """Strided view V (rows are windows of length w) and base offsets per run length."""
    z = np.zeros(2 * w * (w + 1) + w, dtype=bool)
    base = np.arange(w + 1, dtype=np.int64) * (2 * w)
    for c in range(1, w + 1):
        z[base[c] + w : base[c] + w + c] = True
    view = as_strided(z, shape=(z.size - w + 1, w), strides=(1, 1), writeable=False)
    return view, base


def bool_bitmaps(L, R, m: int, width: int | None = None) -> np.ndarray:
    """Bool bitmap (..., width) of ommatidia 0..width-1 lit by {k mod m : L <= k <= R}."""
    L, R = np.broadcast_arrays(np.asarray(L, dtype=np.int64), np.asarray(R, dtype=np.int64))
    w = m if width is None else int(width)
    if w > _WINDOW_MAX_W or w < 1:
        return _bool_by_comparison(L, R, m, w)
    view, base = _window_table(w)
    s1, e1, e2 = runs(L.reshape(-1), R.reshape(-1), m, w)
    c1 = np.maximum(e1 - s1 + 1, 0)
    start = np.where(c1 > 0, s1, 0)
    flat = view[base[c1] + (w - start)]
    wrap = np.flatnonzero(e2 >= 0)
    if wrap.size:
        flat[wrap] |= view[base[e2[wrap] + 1] + w]
    return flat.reshape(L.shape + (w,))


def _bool_by_comparison(L, R, m: int, width: int) -> np.ndarray:
    """Wide eyes: ``k - L`` read as unsigned is at most ``R - L`` exactly on the lit
    ommatidia of a run that does not wrap; the few runs that wrap add ``k <= R - m``."""
    out = np.empty(L.shape + (width,), dtype=bool)
    flat = out.reshape(-1, width)
    sdt = np.int16 if m < 2**15 else np.int32 if m < 2**31 else np.int64
    udt = np.dtype(sdt).str.replace("i", "u")
    k = np.arange(width, dtype=sdt)
    Lf = L.reshape(-1, 1).astype(sdt)
    Cf = (R - L).reshape(-1, 1).astype(udt)
    rows = max(1, (1 << 19) // max(width, 1))
    for s in range(0, flat.shape[0], rows):
        d = k - Lf[s : s + rows]
        np.less_equal(d.view(udt), Cf[s : s + rows], out=flat[s : s + rows])
    wrap = np.flatnonzero(R.reshape(-1) >= m)
    if wrap.size:
        flat[wrap] |= k <= (R.reshape(-1)[wrap, None] - m)
    return out


@lru_cache(maxsize=4)
def _packed_tables(w: int) -> tuple[np.ndarray, np.ndarray]:
    """GE[s] = packed (k >= s), LE[e + 1] = packed (k <= e), for s, e + 1 in 0..w."""
    k = np.arange(w)
    cut = np.arange(w + 1)[:, None]
    ge = np.packbits(k >= cut, axis=1)
    le = np.packbits(k < cut, axis=1)
    return ge, le


def packed_bitmaps(L, R, m: int, width: int | None = None) -> np.ndarray:
    """``np.packbits(bool_bitmaps(L, R, m, width), axis=-1)`` without building the bool
    bitmap: uint8 of shape (..., ceil(width / 8)), bit 7 of byte 0 is ommatidium 0."""
    L, R = np.broadcast_arrays(np.asarray(L, dtype=np.int64), np.asarray(R, dtype=np.int64))
    w = m if width is None else int(width)
    s1, e1, e2 = runs(L.reshape(-1), R.reshape(-1), m, w)
    if w > _PACKED_TABLE_MAX_W:
        flat = _packed_per_byte(s1, e1, w)
        wrap = np.flatnonzero(e2 >= 0)
        if wrap.size:
            flat[wrap] |= _packed_per_byte(np.zeros(wrap.size, np.int64), e2[wrap], w)
    else:
        ge, le = _packed_tables(w)
        empty = e1 < s1
        flat = ge[np.where(empty, w, s1)]
        flat &= le[np.where(empty, 0, e1 + 1)]
        wrap = np.flatnonzero(e2 >= 0)
        if wrap.size:
            flat[wrap] |= le[e2[wrap] + 1]
    return flat.reshape(L.shape + ((w + 7) // 8,))


def _packed_per_byte(lo: np.ndarray, hi: np.ndarray, w: int) -> np.ndarray:
    """Packed rows lit on lo..hi (empty when hi < lo), one byte at a time, in blocks."""
    nb = (w + 7) // 8
    out = np.empty((lo.size, nb), np.uint8)
    start = np.arange(nb, dtype=np.int64) * 8
    rows = max(1, (1 << 18) // nb)
    for s in range(0, lo.size, rows):
        a = np.clip(lo[s : s + rows, None] - start, 0, 8)
        b = np.clip(hi[s : s + rows, None] + 1 - start, 0, 8)
        b = np.maximum(a, b)
        # bits a..b-1 of a byte, most significant first: (0xFF >> a) & ~(0xFF >> b)
        out[s : s + rows] = (0xFF >> a) & ~(0xFF >> b)
    return out
