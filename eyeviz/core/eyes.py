"""The eye-model seam: what the layers above the core need from "a pair of eyes".

Two models implement it: the paper's planar :class:`eyeviz.core.geometry.EyePair` (rings of
m ommatidia, features are discs (x, y, g)) and the spherical
:class:`eyeviz.core.geometry3d.EyePair3D` (HEALPix facets, features are balls
(x, y, z, g)). Both put eye A at (-h, 0[, 0]) and eye B at (h, 0[, 0]); the plane z = 0 of
the spherical model is the planar one (docs/spherical.md).

What a data set, an estimator's domain, a scene or a report may rely on without knowing
which model it holds is :class:`EyeModel`: the design (the numbers a file must match), the
number of facets per eye, and the four per-feature predicates of the paper (the bitmaps,
Definition 1, Proposition 4 and overlap with an eye), each taking a feature's centre
coordinates followed by its radius g. Anything model-specific (the planar intervals of
Prop. 2, the spherical lit lists) is reached through the concrete class. See
docs/architecture.md, "The eye-model seam".

>>> from eyeviz.core.eyes import eyes_from_design
>>> eyes = eyes_from_design({"h": 40.0, "l": 20.0, "m": 720})
>>> eyes.kind, eyes.dims, eyes.facets
('planar', 2, 720)
>>> [int(v.sum()) for v in eyes.bitmaps(0.0, 1500.0, 50.0)]
[8, 8]
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, Protocol, runtime_checkable

import numpy as np

from eyeviz import EyevizError

__all__ = ["EyeModel", "KINDS", "design_kind", "eyes_from_design"]

#: The eye models and the key of the design that names each: a design with ``m`` is
#: planar, one with ``nside`` spherical.
KINDS: dict[str, str] = {"m": "planar", "nside": "spherical"}


@runtime_checkable
class EyeModel(Protocol):
    """A pair of compound eyes at A = (-h, 0[, 0]) and B = (h, 0[, 0]), radius l."""

    @property
    def h(self) -> float: ...

    @property
    def l(self) -> float: ...  # noqa: E743  (the paper's name)

    @property
    def kind(self) -> str:
        """``"planar"`` or ``"spherical"``."""
        ...

    @property
    def dims(self) -> int:
        """Coordinates of a feature centre: 2 (x, y) or 3 (x, y, z)."""
        ...

    @property
    def facets(self) -> int:
        """Facets (ommatidia) per eye: m, or 12 nside^2."""
        ...

    @property
    def design(self) -> dict[str, float | int]:
        """h, l and the facet parameter (m or nside): what files and estimators match."""
        ...

    def bitmaps(self, *centre_and_g: Any) -> tuple[np.ndarray, np.ndarray]:
        """(omega_a, omega_b): bool, shape (..., facets)."""
        ...

    def visible(self, *centre_and_g: Any) -> tuple[np.ndarray, np.ndarray]:
        """Definition 1 per eye: at least two facets lit."""
        ...

    def in_bfv(self, *centre_and_g: Any) -> np.ndarray:
        """The feature lies in the binocular field of view (Prop. 4; docs/spherical.md)."""
        ...

    def overlaps_eye(self, *centre_and_g: Any) -> tuple[np.ndarray, np.ndarray]:
        """Per eye: the closed feature meets the closed eye of radius l."""
        ...


def design_kind(design: Mapping[str, Any]) -> str:
    """``"planar"`` for a design with m, ``"spherical"`` for one with nside; EyevizError
    (one line) for both or neither."""
    keys = [k for k in KINDS if k in design]
    if len(keys) != 1:
        raise EyevizError(
            "an eye design gives exactly one of m (planar eyes) or nside (spherical eyes), "
            f"got {', '.join(keys) if keys else 'neither'}"
        )
    return KINDS[keys[0]]


def eyes_from_design(design: Mapping[str, Any]) -> EyeModel:
    """The eye pair a design names: ``{"h", "l", "m"}`` -> EyePair, ``{"h", "l", "nside"}``
    -> EyePair3D. The model's own checks apply (ValueError naming the parameter)."""
    kind = design_kind(design)
    h, l = design.get("h", 40.0), design.get("l", 20.0)
    if kind == "planar":
        from eyeviz.core.geometry import EyePair

        return EyePair(h, l, design["m"])
    from eyeviz.core.geometry3d import EyePair3D

    return EyePair3D(h, l, design["nside"])
