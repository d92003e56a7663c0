"""The eye-model seam: what the layers above the core need from "a pair of eyes".

Three models implement it: the paper's planar :class:`eyeviz.core.geometry.EyePair`
(rings of m ommatidia, features are discs (x, y, g)), the spherical
:class:`eyeviz.core.geometry3d.EyePair3D` (HEALPix facets, features are balls
(x, y, z, g)) and the measured :class:`eyeviz.core.measured.MeasuredEyePair` (lists of
real ommatidia, balls; docs/measured.md). The first two put eye A at (-h, 0[, 0]) and eye
B at (h, 0[, 0]); the plane z = 0 of the spherical model is the planar one
(docs/spherical.md). A measured pair has eye A on the left (-x) too, h and l derived from
its lenses.

What a data set, an estimator's domain, a scene or a report may rely on without knowing
which model it holds is :class:`EyeModel`: the design (the numbers a file must match), the
number of facets of each eye (``facet_counts``: the two eyes of a measured pair may
differ), and the four per-feature predicates of the paper (the bitmaps,
Definition 1, Proposition 4 and overlap with an eye), each taking a feature's centre
coordinates followed by its radius g. Anything model-specific (the planar intervals of
Prop. 2, the spherical lit lists) is reached through the concrete class. See
docs/architecture.md, "The eye-model seam".

>>> from eyeviz.core.eyes import eyes_from_design
>>> eyes = eyes_from_design({"h": 40.0, "l": 20.0, "m": 720})
>>> eyes.kind, eyes.dims, eyes.facet_counts
('planar', 2, (720, 720))
>>> [int(v.sum()) for v in eyes.bitmaps(0.0, 1500.0, 50.0)]
[8, 8]
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, Protocol, runtime_checkable

import numpy as np

from eyeviz import EyevizError
from eyeviz.core import paper

__all__ = ["EyeModel", "KINDS", "design_kind", "eyes_from_design"]

#: The eye models and the key of the design that names each: a design with ``m`` is
#: planar, one with ``nside`` spherical, one with ``eye`` (the sha256 fingerprint of the
#: ommatidia's arrays) measured.
KINDS: dict[str, str] = {"m": "planar", "nside": "spherical", "eye": "measured"}


@runtime_checkable
class EyeModel(Protocol):
    """A pair of compound eyes at A = (-h, 0[, 0]) and B = (h, 0[, 0]), radius l."""

    @property
    def h(self) -> float: ...

    @property
    def l(self) -> float: ...  # noqa: E743  (the paper's name)

    @property
    def kind(self) -> str:
        """``"planar"``, ``"spherical"`` or ``"measured"``."""
        ...

    @property
    def dims(self) -> int:
        """Coordinates of a feature centre: 2 (x, y) or 3 (x, y, z)."""
        ...

    @property
    def facet_counts(self) -> tuple[int, int]:
        """Facets (ommatidia) of eye A and of eye B: (m, m), (12 nside^2, 12 nside^2), or
        a measured pair's (n_A, n_B)."""
        ...

    @property
    def design(self) -> Mapping[str, Any]:
        """What files and estimators match: h, l and m or nside; a measured pair's
        fingerprint (``eye``) and facet counts."""
        ...

    def bitmaps(self, *centre_and_g: Any) -> tuple[np.ndarray, np.ndarray]:
        """(omega_a, omega_b): bool, shapes (..., n_A) and (..., n_B)."""
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
    """``"planar"`` for a design with m, ``"spherical"`` for one with nside,
    ``"measured"`` for one with eye (a fingerprint); EyevizError (one line) for more than
    one or none."""
    keys = [k for k in KINDS if k in design]
    if len(keys) != 1:
        raise EyevizError(
            "an eye design gives exactly one of m (planar eyes), nside (spherical eyes) or "
            f"eye (a measured pair's fingerprint), got {' and '.join(keys) if keys else 'none'}"
        )
    return KINDS[keys[0]]


def eyes_from_design(design: Mapping[str, Any]) -> EyeModel:
    """The eye pair a design names: ``{"h", "l", "m"}`` -> EyePair, ``{"h", "l", "nside"}``
    -> EyePair3D. The model's own checks apply (ValueError naming the parameter). A
    measured design names its eyes by fingerprint only: EyevizError (the arrays come from
    an eye file, :func:`eyeviz.measured.load_eyes`, or a data set that embeds them)."""
    kind = design_kind(design)
    if kind == "measured":
        raise EyevizError(
            "a measured design names its eyes by fingerprint only: load the pair from its "
            "eye file (eyeviz.measured.load_eyes) or from a data set that embeds it"
        )
    h, l = design.get("h", paper.H), design.get("l", paper.L)
    if kind == "planar":
        from eyeviz.core.geometry import EyePair

        return EyePair(h, l, design["m"])
    from eyeviz.core.geometry3d import EyePair3D

    return EyePair3D(h, l, design["nside"])
