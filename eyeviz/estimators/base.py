"""The estimator protocol of every eye model: what each eye saw -> where the feature is.

One base, :class:`EstimatorBase`, holds what every estimator has: a ``name``, the eye
models it answers for (``kinds``; a domain of another kind, or not a domain, is refused
in one line), its domain and metadata, ``n_weights`` and its repr. Each model's input
and answer are its subclass's (docs/contract.md; docs/spherical.md, "Estimators of the
spherical eyes"):

- :class:`Estimator`, the planar eyes: the paper's half bitmaps (Omega_A, Omega_B) of
  length m/2 (ommatidia 0..m/2-1, Section 4) -> :class:`Prediction` (r, phi). A feature
  lights one contiguous run of ommatidia per eye (Prop. 2, Eq. 11), so a bitmap pair is
  fully described by four integers, the lit intervals (LA, RA, LB, RB):
  :func:`bitmaps_to_intervals` extracts them, vectorised, and every planar estimator
  shares it. Rows that are not a single feature (an eye with nothing lit, or more than
  one lit run) get NaN and ``valid = False``; rows whose intervals could not come from
  the training domain (Table 3, Table 4) get ``in_domain = False``.
- :class:`Estimator3D`, the eyes in space (HEALPix and measured): each eye's lit facets
  as CSR rows or dense bitmaps (:mod:`eyeviz.estimators.lit_csr`) ->
  :class:`Prediction3D` (r, azimuth, elevation) in the data set's convention: the
  ball's centre (x, y, z) = r (cos el cos az, cos el sin az, sin el) about the domain's
  origin, az = atan2(y, x) (in (0, pi) in front), el = asin(z / r)
  (:func:`eyeviz.dataset.records.spherical_to_xyz`). ``predict_dataset(ds)`` takes a
  :class:`~eyeviz.dataset.records.Dataset3D` (a generated chunk or a
  ``Sparse3DReader`` block) directly. Rows where an eye lit nothing get NaN and
  ``valid = False``; ``in_domain`` is False where the rows cannot come from the
  domain's Algorithm 1 (fewer than two facets lit in an eye, Definition 1 in 3D);
  ``flagged`` marks rows the estimator answered by a fallback (its own docstring says
  which).

Both masks travel with the result:

>>> from eyeviz import dataset, estimators
>>> ds = dataset.generate(50, seed=2)
>>> est = estimators.load("analytic")
>>> r, phi = est.predict(ds.omega_a, ds.omega_b)     # unpacks like a pair
>>> p = est.predict(ds.omega_a, ds.omega_b)
>>> bool(p.valid.all()), bool(p.in_domain.all())    # Algorithm 1's rows are in the domain
(True, True)

This module imports numpy and the standard library only (no torch).
"""

from __future__ import annotations

import math
from typing import Any, ClassVar

import numpy as np

from eyeviz import EyevizError
from eyeviz.core.domain import PAPER_DOMAIN, PAPER_DOMAIN3D, Domain, Domain3D
from eyeviz.core.geometry import intervals_to_bitmap
from eyeviz.core.validation import check_int
from eyeviz.estimators.lit_csr import LitCSR, _check_indices, as_csr, take_rows

__all__ = [
    "Domain",
    "PAPER_DOMAIN",
    "Estimator",
    "Estimator3D",
    "EstimatorBase",
    "LitCSR",
    "Prediction",
    "Prediction3D",
    "as_csr",
    "bitmaps_to_intervals",
    "validate_bitmaps",
    "take_rows",
    "triangulate",
    "in_domain",
]


class _Answer(tuple):
    """An estimator's answer: a tuple of its coordinates (``coords``) that carries the
    boolean masks (``masks``) as attributes. For a single row all are numpy scalars."""

    coords: ClassVar[tuple[str, ...]] = ()
    masks: ClassVar[tuple[str, ...]] = ()

    def __new__(cls, *values):
        k, n = len(cls.coords), len(cls.coords) + len(cls.masks)
        if len(values) != n:
            raise TypeError(f"{cls.__name__} takes {n} values ({cls.coords + cls.masks})")
        obj = super().__new__(cls, values[:k])
        for name, v in zip(cls.masks, values[k:], strict=True):
            setattr(obj, name, v)
        return obj

    def __getnewargs__(self):
        return (*self, *(getattr(self, m) for m in self.masks))


class Prediction(_Answer):
    """``(r, phi)`` that also carries ``valid`` and ``in_domain`` masks.

    Unpacks as a pair; ``r`` and ``phi`` are NaN where ``valid`` is False. For a single
    row all four are numpy scalars.
    """

    coords = ("r", "phi")
    masks = ("valid", "in_domain")
    valid: Any
    in_domain: Any

    @property
    def r(self):
        return self[0]

    @property
    def phi(self):
        return self[1]


class Prediction3D(_Answer):
    """``(r, azimuth, elevation)`` (radians) with ``valid``, ``in_domain`` and ``flagged``
    masks; unpacks as a triple. For a single row every field is a numpy scalar. An
    estimator may add per-row fields of its own (limit3d: ``mc_error``, ``n_accepted``)."""

    coords = ("r", "azimuth", "elevation")
    masks = ("valid", "in_domain", "flagged")
    valid: Any
    in_domain: Any
    flagged: Any

    @property
    def r(self):
        return self[0]

    @property
    def azimuth(self):
        return self[1]

    @property
    def elevation(self):
        return self[2]


def validate_bitmaps(omega_a, omega_b, width: int) -> tuple[np.ndarray, np.ndarray, bool]:
    """Check two bitmap arrays and return them as 2-D bool arrays plus a 'was one row' flag.

    Raises ValueError naming the problem: wrong length, mismatched rows, non-binary values.
    """
    arrays = []
    single = None
    for name, om in (("omega_a", omega_a), ("omega_b", omega_b)):
        try:
            a = np.asarray(om)
        except (TypeError, ValueError) as exc:
            raise ValueError(f"{name} must be an array of 0/1 values: {exc}") from None
        if a.ndim not in (1, 2):
            raise ValueError(f"{name} must have shape (m/2,) or (N, m/2), got shape {a.shape}")
        is_single = a.ndim == 1
        if single is None:
            single = is_single
        elif single != is_single:
            raise ValueError("omega_a and omega_b must both be single rows or both be 2-D")
        a = a.reshape(-1, a.shape[-1]) if a.size or a.ndim == 2 else a.reshape(0, width)
        if a.shape[1] != width:
            raise ValueError(
                f"{name} rows must have length m/2 = {width} (m = {2 * width}), "
                f"got length {a.shape[1]}"
            )
        if a.dtype != np.bool_:
            if a.dtype.kind not in "biuf":
                raise ValueError(f"{name} must hold 0/1 numbers, got dtype {a.dtype}")
            zero = a == 0
            bad = ~(zero | (a == 1))
            if bad.any():
                i, j = np.argwhere(bad)[0]
                raise ValueError(
                    f"{name} must be binary (0/1): {int(bad.sum())} other value(s), "
                    f"first {a[i, j]!r} at row {i}, column {j}"
                )
            a = ~zero
        arrays.append(a)
    if arrays[0].shape[0] != arrays[1].shape[0]:
        raise ValueError(
            f"omega_a and omega_b have different row counts: "
            f"{arrays[0].shape[0]} and {arrays[1].shape[0]}"
        )
    return arrays[0], arrays[1], bool(single)


# Bit position (0 = most significant, as np.packbits orders bits) of a byte's first and
# last set bit; 8 / 0 for a zero byte (such rows are invalid anyway).
_LEAD = np.array([8 if v == 0 else 8 - v.bit_length() for v in range(256)], np.int64)
_TRAIL = np.array([0 if v == 0 else 8 - (v & -v).bit_length() for v in range(256)], np.int64)


def _runs(bits: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """First and last lit index per row and whether the lit bits form one run.

    Works on the packed bytes (8 ommatidia each), which reads the bitmap once.
    """
    n = bits.shape[0]
    if n == 0:
        e = np.zeros(0, np.int64)
        return e, e, np.zeros(0, bool)
    packed = np.packbits(bits, axis=1)
    nz = packed != 0
    fb = np.argmax(nz, axis=1)
    lb = packed.shape[1] - 1 - np.argmax(nz[:, ::-1], axis=1)
    rows = np.arange(n)
    first = fb * 8 + _LEAD[packed[rows, fb]]
    last = lb * 8 + _TRAIL[packed[rows, lb]]
    count = np.bitwise_count(packed).sum(axis=1, dtype=np.int64)
    ok = (count > 0) & (count == last - first + 1)
    return first, last, ok


def bitmaps_to_intervals(omega_a, omega_b, width: int | None = None):
    """Lit intervals (LA, RA, LB, RB) int64 and a ``valid`` mask from half bitmaps.

    ``valid`` is False for a row where either eye has no lit ommatidium or more than one
    lit run; its interval values are then meaningless. Inverse of
    :func:`eyeviz.core.geometry.intervals_to_bitmap` with ``width = m/2`` on single runs.
    """
    if width is None:
        width = np.shape(omega_a)[-1]
    a, b, _ = validate_bitmaps(omega_a, omega_b, width)
    LA, RA, va = _runs(a)
    LB, RB, vb = _runs(b)
    return LA, RA, LB, RB, va & vb


def triangulate(theta_a, theta_b, h: float, min_disparity: float = 0.0):
    """Intersect the rays from A = (-h, 0) at angle theta_a and B = (h, 0) at theta_b.

    Law of sines in triangle A B P (angle at P is the disparity theta_b - theta_a):
    r_A = 2h sin(theta_b) / sin(theta_b - theta_a). Disparities below ``min_disparity``
    are raised to it (parallel rays would meet at infinity). Returns (r, phi) about the
    origin, phi by atan2 (docs/conventions.md).
    """
    theta_a = np.asarray(theta_a, np.float64)
    theta_b = np.asarray(theta_b, np.float64)
    d = np.maximum(theta_b - theta_a, min_disparity)
    tb = theta_a + d
    ra = 2.0 * h * np.sin(tb) / np.sin(d)
    x = -h + ra * np.cos(theta_a)
    y = ra * np.sin(theta_a)
    return np.hypot(x, y), np.arctan2(y, x)


def _triangulated_r(theta_a, theta_b, h: float) -> np.ndarray:
    """Distance from the origin of the rays' meeting point (no azimuth: cheaper)."""
    d = np.maximum(theta_b - theta_a, 1e-12)
    ra = 2.0 * h * np.sin(theta_b) / np.sin(d)
    x = ra * np.cos(theta_a) - h
    y = ra * np.sin(theta_a)
    return np.sqrt(x * x + y * y)


def in_domain(LA, RA, LB, RB, domain: Domain) -> np.ndarray:
    """Necessary conditions for intervals to come from a feature of the training domain.

    A feature of the domain lies in the BFV at r_min <= r <= r_max with g <= g_max and
    is seen by both eyes, so its intervals end inside the half bitmap (not touching its
    ends), its centre disparity admits some distance in [r_min, r_max], and its angular
    size admits g <= g_max at the nearest such distance. Those intervals are flagged
    True; True does not prove membership, False proves absence.
    """
    gam = 2.0 * math.pi / domain.m
    w = domain.width
    LA, RA, LB, RB = (np.asarray(v, np.int64) for v in (LA, RA, LB, RB))
    inside = (np.minimum(LA, LB) > 0) & (np.maximum(RA, RB) < w - 1)
    inside &= (RA > LA) & (RB > LB)  # (compared, not subtracted: no int64 overflow)
    ca = 0.5 * (LA + RA + 1) * gam
    cb = 0.5 * (LB + RB + 1) * gam
    # each tangent lies in its edge sector, so the true centre direction is within half a
    # sector of the interval's mid-angle and the true disparity within one sector of cb - ca
    # (the near and far rays triangulated in one call: fewer numpy calls for a few rows)
    hg = np.array([[-0.5 * gam], [0.5 * gam]]).reshape((2,) + (1,) * np.ndim(ca))
    with np.errstate(divide="ignore", invalid="ignore"):
        r_near, r_far = _triangulated_r(ca + hg, cb - hg, domain.h)
    far_ok = (cb - ca - gam <= 0) | (r_far >= domain.r_min * (1 - 1e-9))
    near_ok = r_near <= domain.r_max * (1 + 1e-9)
    half = 0.5 * np.maximum(np.minimum(RA - LA, RB - LB) - 1, 0) * gam
    size_ok = np.maximum(r_near, domain.r_min) * np.sin(half) <= domain.g_max * (1 + 1e-9)
    return inside & far_ok & near_ok & size_ok


class EstimatorBase:
    """What every estimator has, whatever its eyes: a name, the eye models it answers for,
    its domain (checked here), its metadata."""

    name: ClassVar[str] = "base"
    #: the eye models (:attr:`~eyeviz.core.domain.Domain.kind`) the estimator answers
    #: for; a domain of another kind is refused in one line naming these
    kinds: ClassVar[tuple[str, ...]] = ()
    #: the domain record the estimator takes (:mod:`eyeviz.core.domain`)
    domain_type: ClassVar[type[Any]] = object
    domain: Any

    def __init__(self, domain: Any, metadata: dict | None = None) -> None:
        if not isinstance(domain, self.domain_type):
            raise ValueError(
                f"domain must be a {self.domain_type.__name__}, got {type(domain).__name__}"
            )
        if domain.kind not in self.kinds:
            raise EyevizError(
                f"estimator {self.name!r} answers for {' and '.join(self.kinds)} eyes, not "
                f"{domain.kind} ones"
            )
        self.domain = domain
        self.metadata: dict[str, Any] = dict(metadata or {})

    @property
    def n_weights(self) -> int:
        """Number of learned parameters (0 for estimators that do not learn)."""
        return int(self.metadata.get("n_weights", 0))

    def _eyes_text(self) -> str:
        """The domain's eyes in the repr."""
        return str(self.domain.design)

    def __repr__(self) -> str:
        return f"<{type(self).__name__} {self.name!r} {self._eyes_text()}>"


_BLOCK = 1 << 16  # rows per block in Estimator.predict


class Estimator(EstimatorBase):
    """Base of every estimator of the planar eyes: validation, interval extraction, masks.

    Subclasses implement :meth:`_predict_intervals` (estimators of the four integers) or,
    when they read the raw bitmaps (``uses_bitmaps = True``), :meth:`_predict_bitmaps`.
    Both receive valid rows only and return float64 arrays (r, phi).
    """

    name: ClassVar[str] = "base"
    kinds: ClassVar[tuple[str, ...]] = ("planar",)
    domain_type: ClassVar[type[Any]] = Domain
    uses_bitmaps: ClassVar[bool] = False
    domain: Domain

    def __init__(self, domain: Domain = PAPER_DOMAIN, metadata: dict | None = None) -> None:
        super().__init__(domain, metadata)

    # --- to implement -------------------------------------------------------------------
    def _predict_intervals(self, LA, RA, LB, RB) -> tuple[np.ndarray, np.ndarray]:
        """(r, phi) for valid int64 interval arrays. Default: via the bitmaps."""
        w = self.domain.width
        m = self.domain.m
        return self._predict_bitmaps(
            intervals_to_bitmap(LA, RA, m, w), intervals_to_bitmap(LB, RB, m, w)
        )

    def _predict_bitmaps(self, omega_a, omega_b) -> tuple[np.ndarray, np.ndarray]:
        """(r, phi) for valid 2-D bool bitmaps. Default: via the intervals."""
        LA, RA, _ = _runs(omega_a)
        LB, RB, _ = _runs(omega_b)
        return self._predict_intervals(LA, RA, LB, RB)

    # --- public ---------------------------------------------------------------------------
    def predict(self, omega_a, omega_b) -> Prediction:
        """(r, phi) per row of half bitmaps (N, m/2) or a single row (m/2,); phi in radians.

        ValueError for a wrong length or non-binary values; NaN and ``valid = False`` for
        rows that are not a single lit run in each eye.
        """
        a, b, single = validate_bitmaps(omega_a, omega_b, self.domain.width)
        n = a.shape[0]
        r = np.full(n, np.nan)
        phi = np.full(n, np.nan)
        valid = np.zeros(n, bool)
        dom = np.zeros(n, bool)
        for s in range(0, n, _BLOCK):  # blocks keep the temporaries in cache
            blk = slice(s, min(s + _BLOCK, n))
            r[blk], phi[blk], valid[blk], dom[blk] = self._predict_block(a[blk], b[blk])
        return self._pack(r, phi, valid, dom, single)

    def predict_dataset(self, ds) -> Prediction:
        """:meth:`predict` on the rows of a planar data set or block (its ``omega_a``,
        ``omega_b``): the call every kind's estimator answers on its kind's rows."""
        return self.predict(ds.omega_a, ds.omega_b)

    def _predict_block(self, a, b):
        LA, RA, va = _runs(a)
        LB, RB, vb = _runs(b)
        valid = va & vb
        n = a.shape[0]
        r = np.full(n, np.nan)
        phi = np.full(n, np.nan)
        sel = slice(None) if valid.all() else np.flatnonzero(valid)
        if n and valid.any():
            if self.uses_bitmaps:
                rr, pp = self._predict_bitmaps(a[sel], b[sel])
            else:
                rr, pp = self._predict_intervals(LA[sel], RA[sel], LB[sel], RB[sel])
            r[sel] = rr
            phi[sel] = pp
        return r, phi, valid, valid & in_domain(LA, RA, LB, RB, self.domain)

    def predict_intervals(self, LA, RA, LB, RB) -> Prediction:
        """Like :meth:`predict` but from intervals (as ``EyePair.intervals`` returns them).

        Intervals that do not fit in the half bitmap as one run (R >= m/2, or L > R) are
        not valid.
        """
        arrs = [np.asarray(v) for v in (LA, RA, LB, RB)]
        single = all(v.ndim == 0 for v in arrs)
        try:
            LA, RA, LB, RB = (np.atleast_1d(v).astype(np.int64, casting="same_kind") for v in arrs)
        except TypeError:
            raise ValueError("intervals must be integer arrays") from None
        if not (LA.shape == RA.shape == LB.shape == RB.shape) or LA.ndim != 1:
            raise ValueError("LA, RA, LB, RB must be 1-D arrays of equal length")
        w = self.domain.width
        valid = (np.minimum(LA, LB) >= 0) & (np.maximum(RA, RB) < w)
        valid &= (LA <= RA) & (LB <= RB)
        n = LA.shape[0]
        r = np.empty(n)
        r.fill(np.nan)
        phi = r.copy()
        sel = slice(None) if valid.all() else valid.nonzero()[0]
        if n and valid.any():
            rr, pp = self._predict_intervals(LA[sel], RA[sel], LB[sel], RB[sel])
            r[sel] = rr
            phi[sel] = pp
        dom = valid & in_domain(LA, RA, LB, RB, self.domain)
        return self._pack(r, phi, valid, dom, single)

    @staticmethod
    def _pack(r, phi, valid, dom, single) -> Prediction:
        if single:
            return Prediction(r[0], phi[0], valid[0], dom[0])
        return Prediction(r, phi, valid, dom)

    def _eyes_text(self) -> str:
        return f"m={self.domain.m}"


#: rows per block in :meth:`Estimator3D.predict`
_BLOCK3D = 1 << 14


class Estimator3D(EstimatorBase):
    """Base of the estimators of the eyes in space (HEALPix; measured for an estimator
    whose ``kinds`` name them): validation, blocks, masks.

    Subclasses implement :meth:`_predict_csr`, which receives valid rows only (every
    row lights at least one facet per eye) and returns float64 arrays
    (r, azimuth, elevation, flagged).
    """

    name: ClassVar[str] = "base3d"
    kinds: ClassVar[tuple[str, ...]] = ("spherical",)
    domain_type: ClassVar[type[Any]] = Domain3D
    #: True for an estimator whose :meth:`_predict_csr` reads every index anyway and
    #: refuses indices out of range or not increasing within a row there, with
    #: :func:`as_csr`'s ValueError naming ``lit_a`` or ``lit_b`` (one pass over the
    #: indices instead of two); :meth:`predict` then checks only the rows it does not
    #: hand over (those where an eye lit nothing).
    checks_indices: ClassVar[bool] = False
    #: rows per :meth:`_predict_csr` call (an integer >= 1, checked by :meth:`predict`)
    block_rows: ClassVar[int] = _BLOCK3D
    domain: Domain3D

    def __init__(self, domain: Domain3D = PAPER_DOMAIN3D, metadata: dict | None = None) -> None:
        super().__init__(domain, metadata)

    # --- to implement -------------------------------------------------------------------
    def _predict_csr(
        self, lit_a: LitCSR, lit_b: LitCSR
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        raise NotImplementedError

    # --- public ---------------------------------------------------------------------------
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
                f"ds has the eyes {ds.domain.design_text}, the estimator {self.domain.design_text}"
            )
        return self.predict((ds.indptr_a, ds.indices_a), (ds.indptr_b, ds.indices_b))

    def _eyes_text(self) -> str:
        return self.domain.design_text
