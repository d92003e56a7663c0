"""The estimator protocol: bitmaps (Omega_A, Omega_B) -> (r, phi) (docs/contract.md).

Every estimator sees the paper's half bitmaps of length m/2 (ommatidia 0..m/2-1, Section 4).
A feature lights one contiguous run of ommatidia per eye (Prop. 2, Eq. 11), so a bitmap
pair is fully described by four integers, the lit intervals (LA, RA, LB, RB):
:func:`bitmaps_to_intervals` extracts them, vectorised, and every estimator shares it.

Rows that are not a single feature (an eye with nothing lit, or more than one lit run)
get NaN and ``valid = False``; rows whose intervals could not come from the training
domain (Table 3, Table 4) get ``in_domain = False``. Both masks travel with the result:

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

from eyeviz.core.domain import PAPER_DOMAIN, Domain
from eyeviz.core.geometry import intervals_to_bitmap

__all__ = [
    "Domain",
    "PAPER_DOMAIN",
    "Estimator",
    "Prediction",
    "bitmaps_to_intervals",
    "validate_bitmaps",
    "triangulate",
    "in_domain",
]


class Prediction(tuple):
    """``(r, phi)`` that also carries ``valid`` and ``in_domain`` masks.

    Unpacks as a pair; ``r`` and ``phi`` are NaN where ``valid`` is False. For a single
    row all four are numpy scalars.
    """

    valid: Any
    in_domain: Any

    def __new__(cls, r, phi, valid, in_domain):
        obj = super().__new__(cls, (r, phi))
        obj.valid = valid
        obj.in_domain = in_domain
        return obj

    @property
    def r(self):
        return self[0]

    @property
    def phi(self):
        return self[1]

    def __getnewargs__(self):
        return (self[0], self[1], self.valid, self.in_domain)


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


_BLOCK = 1 << 16  # rows per block in Estimator.predict


class Estimator:
    """Base of every estimator: validation, interval extraction, masks.

    Subclasses implement :meth:`_predict_intervals` (estimators of the four integers) or,
    when they read the raw bitmaps (``uses_bitmaps = True``), :meth:`_predict_bitmaps`.
    Both receive valid rows only and return float64 arrays (r, phi).
    """

    name: ClassVar[str] = "base"
    uses_bitmaps: ClassVar[bool] = False

    def __init__(self, domain: Domain = PAPER_DOMAIN, metadata: dict | None = None) -> None:
        self.domain = domain
        self.metadata: dict[str, Any] = dict(metadata or {})

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
    @property
    def n_weights(self) -> int:
        """Number of learned parameters (0 for estimators that do not learn)."""
        return int(self.metadata.get("n_weights", 0))

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

    def __repr__(self) -> str:
        return f"<{type(self).__name__} {self.name!r} m={self.domain.m}>"
