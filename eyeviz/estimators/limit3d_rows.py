"""A chunk's weighted draws as rows (:mod:`eyeviz.estimators.limit3d`): each key's accepted
draws compacted to the front of its row, rows replaced, and the weighted spread of r per
row that the Monte-Carlo error (the stop rule of limit3d's top-ups) is read from.

Compiled unless ``EYEVIZ_JIT=0`` (kernels.limit3d_region's ``compact_draws_kernel`` and
``spread_rows_kernel``), with the numpy path as the reference."""

from __future__ import annotations

import numpy as np

from eyeviz.core import kernels


def _spread(r: np.ndarray, w: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per row of weighted draws: the weighted mean and standard deviation of r and the
    effective sample size ESS = (sum w)^2 / sum w^2 (NaN where nothing is accepted)."""
    tot = w.sum(axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        wn = w / tot[:, None]
        mean = (wn * r).sum(axis=1)
        sd = np.sqrt(np.maximum((wn * (r - mean[:, None]) ** 2).sum(axis=1), 0.0))
        ess = tot**2 / (w**2).sum(axis=1)
    return mean, sd, ess


def _compact(s: dict, lo: int = 0, hi: int | None = None, rows: np.ndarray | None = None) -> dict:
    """Each row's accepted draws (weight > 0) first, in draw order, the rest dropped: the
    arrays are as wide as the most accepted draws of a row (at least 1). A row's padding
    weighs 0 and holds, for each quantity, the row's largest accepted value (1 where
    none is accepted), so it sorts after every accepted draw and no weighted median or
    spread reads it (:func:`eyeviz.estimators.weighted.weighted_median` interpolates
    between sorted draws: a rejected draw there would move the answer). Only the columns
    lo .. hi - 1 of ``s``, and with ``rows`` (bool (N,)) the other rows weigh 0.
    Compiled unless ``EYEVIZ_JIT=0`` (kernels.limit3d_region.compact_draws_kernel, the same
    arrays; :func:`_compact_ref` the reference)."""
    vals = tuple(s.values())
    if kernels.use(vals[0].size) and all(
        type(v) is np.ndarray and v.ndim == 2 and v.dtype == np.float64 for v in vals
    ):
        from eyeviz.core.kernels.limit3d_region import compact_draws_kernel

        n, m = vals[0].shape
        keep = np.ones(n, np.bool_) if rows is None else kernels.arg(rows, np.bool_)
        o = compact_draws_kernel(tuple(kernels.arg(v) for v in vals), list(s).index("w"), lo,
                                 m if hi is None else hi, keep)  # fmt: skip
        return dict(zip(s, o, strict=True))
    return _compact_ref(s, lo, hi, rows)


def _compact_ref(s: dict, lo: int = 0, hi: int | None = None, rows=None) -> dict:
    """:func:`_compact` in numpy (the reference)."""
    s = {k: v[:, lo:hi] for k, v in s.items()}
    if rows is not None:
        s["w"] = np.where(rows[:, None], s["w"], 0.0)
    w = s["w"]
    acc = w > 0
    return _rows_of(acc.sum(axis=1), {name: v[acc] for name, v in s.items()})


def _compact_sparse(n: int, row: np.ndarray, vals: dict) -> dict:
    """:func:`_compact` of n rows given their accepted draws alone: ``row`` (D,) the row
    of each, non-decreasing, and vals {name: (D,)} in draw order (a proposal's
    ``sample_sparse``): the same arrays bit for bit."""
    return _rows_of(np.bincount(row, minlength=n), vals)


def _rows_of(cnt: np.ndarray, got: dict) -> dict:
    """:func:`_compact`'s arrays from each row's count of accepted draws and their values
    (row by row, in draw order)."""
    k = max(1, int(cnt.max()) if cnt.size else 1)
    # the accepted draws row by row in draw order (row-major), each to its place in its row
    rows = np.repeat(np.arange(cnt.size), cnt)
    first = np.cumsum(cnt) - cnt
    at = rows * k + (np.arange(rows.size) - first[rows])
    some = cnt > 0
    out = {}
    for name, v in got.items():
        pad = np.zeros(cnt.size) if name == "w" else np.ones(cnt.size)
        if name != "w" and v.size:
            top = np.maximum.reduceat(v, first[some])
            pad[some] = np.where(np.isfinite(top), top, 1.0)
        o = np.repeat(pad, k)
        o[at] = v
        out[name] = o.reshape(cnt.size, k)
    return out


def _put_rows(s: dict, rows: np.ndarray, new: dict) -> dict:
    """``s`` with its rows ``rows`` replaced by ``new``'s (the narrower padded with
    zero-weight draws)."""
    ws, wn = s["w"].shape[1], new["w"].shape[1]
    if wn < ws:
        new = {k: np.pad(v, ((0, 0), (0, ws - wn)), mode="edge") for k, v in new.items()}
        new["w"][:, wn:] = 0.0
    elif wn > ws:
        s = {k: np.pad(v, ((0, 0), (0, wn - ws)), mode="edge") for k, v in s.items()}
        s["w"][:, ws:] = 0.0
    for k in s:
        s[k][rows] = new[k]
    return s


def _spread_flat(
    n: int, row: np.ndarray, r: np.ndarray, w: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`_spread` of n rows given their accepted draws alone, flat: ``row`` (D,) the
    row of each, r and w (D,), every w > 0. The sums run in storage order
    (``np.bincount``), not numpy's pairwise order over a padded row: the same values to
    rounding (NaN where a row has none, as there). Compiled (kernels.limit3d_region.
    spread_rows_kernel: the same sums in the same order, bit for bit) unless
    ``EYEVIZ_JIT=0``."""
    if not row.size:  # (np.bincount's sums of no weights are integers)
        return np.full(n, np.nan), np.full(n, np.nan), np.full(n, np.nan)
    if kernels.use(row.size):
        from eyeviz.core.kernels.limit3d_region import spread_rows_kernel

        out = np.empty(n), np.empty(n), np.empty(n)
        spread_rows_kernel(kernels.arg(row, np.int64), kernels.arg(r, np.float64),
                           kernels.arg(w, np.float64), *out)  # fmt: skip
        return out
    tot = np.bincount(row, w, n)
    with np.errstate(invalid="ignore", divide="ignore"):
        wn = w / tot[row]
        mean = np.bincount(row, wn * r, n)
        sd = np.sqrt(np.maximum(np.bincount(row, wn * (r - mean[row]) ** 2, n), 0.0))
        ess = tot**2 / np.bincount(row, w * w, n)
    none = ~(tot > 0)
    mean[none] = sd[none] = np.nan
    return mean, sd, ess
