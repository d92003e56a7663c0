"""Add an eye model to eyeviz: implement the EyeModel protocol of ``eyeviz.core.eyes``.

Run it: ``python examples/add_an_eye_model.py``. It builds ``DamagedEyes``: the paper's
planar eyes with a band of dead ommatidia in eye B (a scratch on the cornea, say). Dead
ommatidia never light, so a feature seen only through them is invisible to B (Definition 1
asks for at least two lit ommatidia). The protocol asks for the design, the number of
facets and the four per-feature predicates; everything written against the seam (here a
visibility count, in the package the data sets, domains and reports that take any
``EyeModel``) then runs on the new model unchanged.

A real second model is ``eyeviz.core.geometry3d.EyePair3D``, the spherical eyes
(docs/spherical.md); docs/extending.md walks through what else a model touches.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from eyeviz.core.eyes import EyeModel
from eyeviz.core.geometry import EyePair


@dataclass(frozen=True)
class DamagedEyes:
    """Planar eyes whose eye B has ommatidia ``dead_from .. dead_to - 1`` dead."""

    h: float = 40.0
    l: float = 20.0  # noqa: E741  (the paper's name)
    m: int = 720
    dead_from: int = 60
    dead_to: int = 120

    @property
    def _pair(self) -> EyePair:
        return EyePair(self.h, self.l, self.m)

    kind = "planar-damaged"
    dims = 2

    @property
    def facet_counts(self) -> tuple[int, int]:
        return (self.m, self.m)

    @property
    def design(self) -> dict[str, float | int]:
        return {**self._pair.design, "dead_from": self.dead_from, "dead_to": self.dead_to}

    def bitmaps(self, x, y, g) -> tuple[np.ndarray, np.ndarray]:
        oa, ob = self._pair.bitmaps(x, y, g)
        ob = ob.copy()
        ob[..., self.dead_from : self.dead_to] = False
        return oa, ob

    def visible(self, x, y, g) -> tuple[np.ndarray, np.ndarray]:
        oa, ob = self.bitmaps(x, y, g)
        return oa.sum(axis=-1) >= 2, ob.sum(axis=-1) >= 2

    def in_bfv(self, x, y, g) -> np.ndarray:
        return self._pair.in_bfv(x, y, g)

    def overlaps_eye(self, x, y, g) -> tuple[np.ndarray, np.ndarray]:
        return self._pair.overlaps_eye(x, y, g)


def seen_by_both(eyes: EyeModel, n: int = 3000, seed: int = 0) -> float:
    """Share of random features in the BFV that both eyes see: written against the seam."""
    rng = np.random.default_rng(seed)
    r, phi = rng.uniform(1000, 5000, n), rng.uniform(np.pi / 6, 5 * np.pi / 6, n)
    x, y, g = r * np.cos(phi), r * np.sin(phi), rng.uniform(5, 500, n)
    keep = eyes.in_bfv(x, y, g)
    va, vb = eyes.visible(x, y, g)
    return float((va & vb)[keep].mean())


def main() -> None:
    healthy, damaged = EyePair(40.0, 20.0, 720), DamagedEyes()
    assert isinstance(damaged, EyeModel)
    a, b = seen_by_both(healthy), seen_by_both(damaged)
    print(f"seen by both eyes: healthy {a:.1%}, eye B with ommatidia 60-119 dead {b:.1%}")
    assert b < a, "dead ommatidia must hide some features"


if __name__ == "__main__":
    main()
