"""The data set records of every eye model (a leaf module: numpy and the core only).

A record is a set of rows, one feature each: its centre, its radius g and what each eye
saw. :class:`Dataset` holds the paper's rows (Omega_A, Omega_B, r, phi, g) of
docs/contract.md, dense half bitmaps of the planar eyes; :class:`Chunk` one generated
planar chunk in interval form (Prop. 2, Eq. 11). :class:`Dataset3D` holds the rows of
Algorithm 1 in space (docs/spherical.md), for HEALPix and measured eyes alike: a ball of
radius g centred at (r, azimuth, elevation) about the domain's origin, and per eye the
indices of the facets it lights, in CSR form (row i's facets of eye A are
``indices_a[indptr_a[i]:indptr_a[i + 1]]``, sorted); the same record is one generated
chunk (:mod:`eyeviz.dataset.algorithm1_3d`) and a whole data set read back
(:mod:`eyeviz.dataset.sparse3d`).

What the records share (their length, and :meth:`concat`, which joins parts row after
row) is written once, in :class:`_Rows`: a record states as data which of its fields are
per-row arrays, which are CSR lit sets (the pointers shifted as parts are joined, the
indices and their optional per-facet values appended) and which it keeps of its first
part. The samplers (:mod:`eyeviz.dataset.algorithm1`, ``algorithm1_3d``) and the
readers/writers (:mod:`eyeviz.dataset.io`, ``sparse3d``) import the records from here, so
neither imports the other for its records.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, ClassVar, TypeVar

import numpy as np

from eyeviz.core.domain import PAPER_DOMAIN, Domain3D
from eyeviz.core.geometry import EyePair, intervals_to_bitmap

__all__ = [
    "CHUNK",
    "Chunk",
    "Dataset",
    "Dataset3D",
    "PAPER_EYES",
    "index_dtype",
    "spherical_to_xyz",
]

PAPER_EYES = PAPER_DOMAIN.eyes  # Table 3
CHUNK = 1 << 14  # elements per generated chunk; fixed, so the output never depends on it

_R = TypeVar("_R", bound="_Rows")


class _Rows:
    """Rows of features: the length and the joining every record shares."""

    #: per-row arrays, joined by concatenation
    _row_fields: ClassVar[tuple[str, ...]] = ()
    #: CSR lit sets per eye, (indptr, indices, values or None): the pointers are shifted
    #: by the entries before them; the indices, and the values when the first part has
    #: them, are concatenated
    _csr_fields: ClassVar[tuple[tuple[str, str, str | None], ...]] = ()
    #: fields taken from the first part (a dict is copied)
    _first_fields: ClassVar[tuple[str, ...]] = ()
    r: np.ndarray

    def __len__(self) -> int:
        return int(self.r.shape[0])

    @classmethod
    def concat(cls: type[_R], parts: list[_R]) -> _R:
        """The rows of ``parts`` one after another (the rest of the record of the first)."""
        if not parts:
            raise ValueError("cannot concatenate an empty list of data sets")
        first = parts[0]
        kw: dict[str, Any] = {}
        for indptr, indices, values in cls._csr_fields:
            outs, base = [np.zeros(1, np.int64)], 0
            for p in parts:
                ip = getattr(p, indptr)
                outs.append(ip[1:] + base)
                base += int(ip[-1])
            kw[indptr] = np.concatenate(outs)
            kw[indices] = np.concatenate([getattr(p, indices) for p in parts])
            if values is not None:
                kw[values] = (
                    None
                    if getattr(first, values) is None
                    else np.concatenate([getattr(p, values) for p in parts])
                )
        for name in cls._row_fields:
            kw[name] = np.concatenate([getattr(p, name) for p in parts])
        for name in cls._first_fields:
            v = getattr(first, name)
            kw[name] = dict(v) if isinstance(v, dict) else v
        return cls(**kw)


@dataclass
class Dataset(_Rows):
    """Rows (Omega_A, Omega_B, r, phi, g) of the paper's data set (docs/contract.md).

    ``omega_a``, ``omega_b``: bool (n, m/2), ommatidia 0..m/2-1 of eye A (left), B (right);
    ``r``, ``phi``: centre in polar coordinates about the origin (phi in radians);
    ``g``: feature radius (NaN when read from a CSV without the g column).
    ``params``: the generation parameters (empty when unknown, e.g. read from a CSV).
    """

    omega_a: np.ndarray
    omega_b: np.ndarray
    r: np.ndarray
    phi: np.ndarray
    g: np.ndarray
    eyes: EyePair = PAPER_EYES
    params: dict = field(default_factory=dict)

    _row_fields: ClassVar[tuple[str, ...]] = ("omega_a", "omega_b", "r", "phi", "g")
    _first_fields: ClassVar[tuple[str, ...]] = ("eyes", "params")

    @property
    def m(self) -> int:
        return self.eyes.m

    @property
    def x(self) -> np.ndarray:
        return self.r * np.cos(self.phi)

    @property
    def y(self) -> np.ndarray:
        return self.r * np.sin(self.phi)

    @property
    def bits(self) -> np.ndarray:
        """The network input of Appendix A/B: (n, m) uint8, Omega_A then Omega_B."""
        return np.concatenate([self.omega_a, self.omega_b], axis=1).view(np.uint8)

    def __getitem__(self, idx) -> Dataset:
        return Dataset(
            self.omega_a[idx],
            self.omega_b[idx],
            self.r[idx],
            self.phi[idx],
            self.g[idx],
            self.eyes,
            dict(self.params),
        )


@dataclass
class Chunk(_Rows):
    """One generated chunk in interval form: eye E lights ommatidia L_E..R_E (0 <= L <= R < m/2)."""

    r: np.ndarray
    phi: np.ndarray
    g: np.ndarray
    la: np.ndarray
    ra: np.ndarray
    lb: np.ndarray
    rb: np.ndarray

    _row_fields: ClassVar[tuple[str, ...]] = ("r", "phi", "g", "la", "ra", "lb", "rb")

    def to_dataset(self, p) -> Dataset:
        """The bitmaps of this chunk for the parameters ``p`` (a GenParams)."""
        m = p.eyes.m
        return Dataset(
            intervals_to_bitmap(self.la, self.ra, m, m // 2),
            intervals_to_bitmap(self.lb, self.rb, m, m // 2),
            self.r,
            self.phi,
            self.g,
            p.eyes,
            p.as_dict(),
        )


def index_dtype(npix: int) -> np.dtype:
    """int32 when every RING index fits (npix <= 2^31), int64 beyond."""
    return np.dtype(np.int32) if npix <= 2**31 else np.dtype(np.int64)


def spherical_to_xyz(
    r: np.ndarray, azimuth: np.ndarray, elevation: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """x = r cos(el) cos(az), y = r cos(el) sin(az), z = r sin(el) (x right, y forward,
    z up; az is the planar phi, measured from +x in the plane z = 0)."""
    c = np.cos(elevation)
    return r * c * np.cos(azimuth), r * c * np.sin(azimuth), r * np.sin(elevation)


@dataclass
class Dataset3D(_Rows):
    """Rows (lit_a, lit_b, r, azimuth, elevation, g) of the sparse 3D data set.

    ``indptr_a``/``indptr_b``: int64 (n + 1,), starting at 0; ``indices_a``/``indices_b``:
    facet indices in [0, n_E) (RING order for HEALPix eyes), strictly increasing within a
    row (:func:`index_dtype`);
    ``r``, ``azimuth``, ``elevation`` (radians), ``g``: float64 (n,); ``x``, ``y``, ``z``:
    the centre the lit sets were computed at, :func:`spherical_to_xyz` of (r, azimuth,
    elevation) as evaluated when generated (kept, so a lit set can be checked exactly
    whatever a platform's sin and cos round to).
    ``params``: the generation parameters (mode, seed; ``responses``, the kind, when the
    rows carry graded responses). ``values_a``/``values_b``: None, or float64 in [0, 1]
    aligned with ``indices_a``/``indices_b``, each lit facet's response
    (docs/responses.md).
    """

    indptr_a: np.ndarray
    indices_a: np.ndarray
    indptr_b: np.ndarray
    indices_b: np.ndarray
    r: np.ndarray
    azimuth: np.ndarray
    elevation: np.ndarray
    g: np.ndarray
    x: np.ndarray
    y: np.ndarray
    z: np.ndarray
    domain: Domain3D = field(default_factory=Domain3D)
    params: dict = field(default_factory=dict)
    values_a: np.ndarray | None = None
    values_b: np.ndarray | None = None

    _csr_fields: ClassVar[tuple[tuple[str, str, str | None], ...]] = (
        ("indptr_a", "indices_a", "values_a"),
        ("indptr_b", "indices_b", "values_b"),
    )
    _row_fields: ClassVar[tuple[str, ...]] = ("r", "azimuth", "elevation", "g", "x", "y", "z")
    _first_fields: ClassVar[tuple[str, ...]] = ("domain", "params")

    def lit(self, i: int) -> tuple[np.ndarray, np.ndarray]:
        """Row i's lit facets (lit_a, lit_b), sorted RING indices."""
        a = self.indices_a[self.indptr_a[i] : self.indptr_a[i + 1]]
        b = self.indices_b[self.indptr_b[i] : self.indptr_b[i + 1]]
        return a, b

    def bitmaps(self, start: int = 0, stop: int | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Dense bool (k, n_A) and (k, n_B) bitmaps of rows start..stop-1 (npix bytes per
        row and eye: take few rows at a time at large nside)."""
        stop = len(self) if stop is None else stop
        out = []
        for indptr, indices, npix in (
            (self.indptr_a, self.indices_a, self.domain.facet_counts[0]),
            (self.indptr_b, self.indices_b, self.domain.facet_counts[1]),
        ):
            k = stop - start
            bm = np.zeros((k, npix), bool)
            lo, hi = int(indptr[start]), int(indptr[stop])
            rows = np.repeat(np.arange(k), np.diff(indptr[start : stop + 1]))
            bm[rows, indices[lo:hi]] = True
            out.append(bm)
        return out[0], out[1]
