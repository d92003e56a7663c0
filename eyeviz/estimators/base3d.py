"""The estimator protocol of the spherical eyes: lit sets -> (r, azimuth, elevation).

docs/spherical.md ("Estimators of the spherical eyes") states the contract. An eye's lit
facets are given, per eye, as one of

- **CSR rows** ``(indptr, indices)`` (:data:`LitCSR`): row i lit the sorted RING indices
  ``indices[indptr[i]:indptr[i + 1]]``, as the 3D data set stores them
  (:class:`eyeviz.dataset.records.Dataset3D`, ``EyePair3D.lit_csr``);
- **dense bitmaps**: bool (or 0/1) arrays (npix,) for one row or (N, npix).

``predict(lit_a, lit_b)`` answers a :class:`Prediction3D` (r, azimuth, elevation) in the
data set's convention: the ball's centre (x, y, z) = r (cos el cos az, cos el sin az,
sin el) about the origin midway between the eyes, az = atan2(y, x) (in (0, pi) in front),
el = asin(z / r) (:func:`eyeviz.dataset.records.spherical_to_xyz`).
``predict_dataset(ds)`` takes a :class:`Dataset3D` (a generated chunk or a
``Sparse3DReader`` block) directly.

Rows where an eye lit nothing get NaN and ``valid = False``; ``in_domain`` is False where
the rows cannot come from the domain's Algorithm 1 (fewer than two facets lit in an eye,
Definition 1 in 3D: False proves absence, True does not prove membership); ``flagged``
marks rows the estimator answered by a fallback (its own docstring says which).

This module imports numpy and the standard library only (no torch).
"""

from __future__ import annotations

from typing import Any, ClassVar

import numpy as np

from eyeviz import EyevizError
from eyeviz.core.domain import PAPER_DOMAIN3D, Domain3D
from eyeviz.core.validation import check_int

__all__ = [
    "Estimator3D",
    "LitCSR",
    "Prediction3D",
    "as_csr",
    "take_rows",
]

#: One eye's lit sets as CSR rows: (indptr int (n + 1,), indices int (nnz,)).
LitCSR = tuple[np.ndarray, np.ndarray]

#: rows per block in :meth:`Estimator3D.predict`
_BLOCK = 1 << 14


class Prediction3D(tuple):
    """``(r, azimuth, elevation)`` (radians) with ``valid``, ``in_domain`` and ``flagged``
    masks; unpacks as a triple. For a single row every field is a numpy scalar. An
    estimator may add per-row fields of its own (limit3d: ``mc_error``, ``n_accepted``)."""

    valid: Any
    in_domain: Any
    flagged: Any

    def __new__(cls, r, azimuth, elevation, valid, in_domain, flagged):
        obj = super().__new__(cls, (r, azimuth, elevation))
        obj.valid = valid
        obj.in_domain = in_domain
        obj.flagged = flagged
        return obj

    @property
    def r(self):
        return self[0]

    @property
    def azimuth(self):
        return self[1]

    @property
    def elevation(self):
        return self[2]

    def __getnewargs__(self):
        return (self[0], self[1], self[2], self.valid, self.in_domain, self.flagged)


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


class Estimator3D:
    """Base of the estimators of the spherical eyes: validation, blocks, masks.

    Subclasses implement :meth:`_predict_csr`, which receives valid rows only (every
    row lights at least one facet per eye) and returns float64 arrays
    (r, azimuth, elevation, flagged).
    """

    name: ClassVar[str] = "base3d"
    #: the eye models (:attr:`Domain3D.kind`) the estimator answers for; a domain of
    #: another kind is refused in one line naming these
    kinds: ClassVar[tuple[str, ...]] = ("spherical",)
    #: True for an estimator whose :meth:`_predict_csr` reads every index anyway and
    #: refuses indices out of range or not increasing within a row there, with
    #: :func:`as_csr`'s ValueError naming ``lit_a`` or ``lit_b`` (one pass over the
    #: indices instead of two); :meth:`predict` then checks only the rows it does not
    #: hand over (those where an eye lit nothing).
    checks_indices: ClassVar[bool] = False
    #: rows per :meth:`_predict_csr` call (an integer >= 1, checked by :meth:`predict`)
    block_rows: ClassVar[int] = _BLOCK

    def __init__(self, domain: Domain3D = PAPER_DOMAIN3D, metadata: dict | None = None) -> None:
        if not isinstance(domain, Domain3D):
            raise ValueError(f"domain must be a Domain3D, got {type(domain).__name__}")
        if domain.kind not in self.kinds:
            raise EyevizError(
                f"estimator {self.name!r} answers for {' and '.join(self.kinds)} eyes, not "
                f"{domain.kind} ones"
            )
        self.domain = domain
        self.metadata: dict[str, Any] = dict(metadata or {})

    # --- to implement -------------------------------------------------------------------
    def _predict_csr(
        self, lit_a: LitCSR, lit_b: LitCSR
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        raise NotImplementedError

    # --- public ---------------------------------------------------------------------------
    @property
    def n_weights(self) -> int:
        """Number of learned parameters (0 for estimators that do not learn)."""
        return int(self.metadata.get("n_weights", 0))

    def predict(self, lit_a, lit_b) -> Prediction3D:
        """(r, azimuth, elevation) per row from each eye's lit facets (CSR rows or dense
        bitmaps, see the module docstring). ValueError naming the argument for malformed
        input or a row-count mismatch; NaN and ``valid = False`` where an eye lit nothing."""
        na, nb = self.domain.facet_counts
        check = not self.checks_indices
        pa, ia, single_a = as_csr("lit_a", lit_a, na, check_indices=check)
        pb, ib, single_b = as_csr("lit_b", lit_b, nb, check_indices=check)
        if pa.size != pb.size:
            raise ValueError(
                f"lit_a and lit_b have different row counts: {pa.size - 1} and {pb.size - 1}"
            )
        n = pa.size - 1
        ca, cb = np.diff(pa), np.diff(pb)
        valid = (ca > 0) & (cb > 0)
        if not check and not valid.all():  # rows _predict_csr does not see
            skip = np.flatnonzero(~valid)
            _check_indices("lit_a", *take_rows(pa, ia, skip), na)
            _check_indices("lit_b", *take_rows(pb, ib, skip), nb)
        r = np.full(n, np.nan)
        az = np.full(n, np.nan)
        el = np.full(n, np.nan)
        flagged = np.zeros(n, bool)
        rows = np.flatnonzero(valid)
        step = check_int("block_rows", self.block_rows, ge=1)
        for s in range(0, rows.size, step):
            blk = rows[s : s + step]
            contiguous = blk.size and blk[-1] - blk[0] == blk.size - 1
            if contiguous:
                lo, hi = int(blk[0]), int(blk[-1]) + 1
                sub_a = (pa[lo : hi + 1] - pa[lo], ia[pa[lo] : pa[hi]])
                sub_b = (pb[lo : hi + 1] - pb[lo], ib[pb[lo] : pb[hi]])
            else:
                sub_a, sub_b = take_rows(pa, ia, blk), take_rows(pb, ib, blk)
            rr, aa, ee, ff = self._predict_csr(sub_a, sub_b)
            r[blk], az[blk], el[blk], flagged[blk] = rr, aa, ee, ff
        in_dom = valid & (ca >= 2) & (cb >= 2)
        if single_a and single_b and n == 1:
            return Prediction3D(r[0], az[0], el[0], valid[0], in_dom[0], flagged[0])
        return Prediction3D(r, az, el, valid, in_dom, flagged)

    def predict_dataset(self, ds) -> Prediction3D:
        """:meth:`predict` on the rows of a :class:`~eyeviz.dataset.records.Dataset3D`
        (a generated chunk, ``load3d``'s data set or a ``Sparse3DReader`` block)."""
        for k in ("indptr_a", "indices_a", "indptr_b", "indices_b"):
            if not hasattr(ds, k):
                raise ValueError(f"ds must be a Dataset3D (no {k}), got {type(ds).__name__}")
        if ds.domain.design != self.domain.design:
            raise ValueError(
                f"ds has the eyes {_design_text(ds.domain)}, the estimator "
                f"{_design_text(self.domain)}"
            )
        return self.predict((ds.indptr_a, ds.indices_a), (ds.indptr_b, ds.indices_b))

    def __repr__(self) -> str:
        return f"<{type(self).__name__} {self.name!r} {_design_text(self.domain)}>"


def _design_text(d: Domain3D) -> str:
    """The eyes of a domain in words: h, l, nside, or the measured pair's fingerprint."""
    if d.kind == "measured":
        return f"h={d.h:g} l={d.l:g} measured pair {str(d.eyes.fingerprint)[:12]}"
    return f"(h, l, nside) = {d.design}"
