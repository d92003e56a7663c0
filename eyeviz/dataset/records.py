"""The data set records (a leaf module: numpy and the core geometry only).

:class:`Dataset` holds rows (Omega_A, Omega_B, r, phi, g) of docs/contract.md; :class:`Chunk`
one generated chunk in interval form (Prop. 2, Eq. 11). Both the sampler
(:mod:`eyeviz.dataset.algorithm1`) and the readers/writers (:mod:`eyeviz.dataset.io`)
import them from here, so neither imports the other for its records.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from eyeviz.core.domain import PAPER_DOMAIN
from eyeviz.core.geometry import EyePair, intervals_to_bitmap

__all__ = ["CHUNK", "Chunk", "Dataset", "PAPER_EYES"]

PAPER_EYES = PAPER_DOMAIN.eyes  # Table 3
CHUNK = 1 << 14  # elements per generated chunk; fixed, so the output never depends on it


@dataclass
class Dataset:
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

    def __len__(self) -> int:
        return int(self.r.shape[0])

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

    @staticmethod
    def concat(parts: list[Dataset]) -> Dataset:
        if not parts:
            raise ValueError("cannot concatenate an empty list of data sets")
        first = parts[0]
        oa, ob, r, phi, g = (
            np.concatenate([getattr(p, k) for p in parts])
            for k in ("omega_a", "omega_b", "r", "phi", "g")
        )
        return Dataset(oa, ob, r, phi, g, eyes=first.eyes, params=dict(first.params))


@dataclass
class Chunk:
    """One generated chunk in interval form: eye E lights ommatidia L_E..R_E (0 <= L <= R < m/2)."""

    r: np.ndarray
    phi: np.ndarray
    g: np.ndarray
    la: np.ndarray
    ra: np.ndarray
    lb: np.ndarray
    rb: np.ndarray

    def __len__(self) -> int:
        return int(self.r.shape[0])

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
