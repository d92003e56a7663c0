"""Weighted medians of many rows at once: the MAPE- and MAE-optimal point estimates of
weighted posterior samples, shared by the planar limit (:mod:`eyeviz.estimators.limit`)
and the spherical one (:mod:`eyeviz.estimators.limit3d`)."""

from __future__ import annotations

import numpy as np

__all__ = ["weighted_median"]


def _sortable(v: np.ndarray) -> np.ndarray:
    """float32 values as int32 codes in the same order (an involution; no NaN)."""
    b = np.ascontiguousarray(v, np.float32).view(np.int32)
    return b ^ ((b >> 31) & np.int32(0x7FFFFFFF))


def weighted_median(v: np.ndarray, w: np.ndarray) -> np.ndarray:
    """Per row, the median of v under weights w (CDF interpolated at node midpoints).

    One value sort instead of an argsort and two gathers: each float32 value's order code
    (:func:`_sortable`, the raw bits when no value is negative) and its column share one
    int64 (code in the high word, column in the low one), so a plain (SIMD) sort orders
    the values and carries the columns to fetch the weights with; the values themselves
    are read back only at the two nodes around the median. Values are taken as float32
    (the nodes' precision); ties are ordered by column.
    """
    v = np.ascontiguousarray(v, np.float32)
    N, P = v.shape
    signed = bool((v < 0).any())
    code = _sortable(v) if signed else v.view(np.int32)
    packed = np.empty((N, P), np.int64)
    halves = packed.view(np.int32).reshape(N, P, 2)  # little-endian: [low, high]
    if np.little_endian:
        halves[..., 1] = code
        halves[..., 0] = np.arange(P, dtype=np.int32)
    else:
        halves[..., 0] = code
        halves[..., 1] = np.arange(P, dtype=np.int32)
    packed.sort(axis=1)
    halves = packed.view(np.int32).reshape(N, P, 2)
    lo, hi = (0, 1) if np.little_endian else (1, 0)
    ws = np.take_along_axis(np.asarray(w), halves[..., lo], 1)
    cw = np.cumsum(ws, axis=1)
    tot = cw[:, -1:]
    crit = cw - 0.5 * ws  # the CDF at node midpoints, times tot
    i = (crit < 0.5 * tot).sum(axis=1)
    i1 = np.clip(i, 1, P - 1)
    i0 = i1 - 1
    rows = np.arange(N)
    t_ = np.where(tot[:, 0] > 0, tot[:, 0], 1.0)
    m0, m1 = crit[rows, i0] / t_, crit[rows, i1] / t_

    def value(j):
        c = np.ascontiguousarray(halves[rows, j, hi])
        return (_sortable(c.view(np.float32)) if signed else c).view(np.float32)

    v0, v1 = value(i0).astype(np.float64), value(i1).astype(np.float64)
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.clip((0.5 - m0) / (m1 - m0), 0.0, 1.0)
    t = np.where(np.isfinite(t), t, 0.0)
    return v0 + t * (v1 - v0)
