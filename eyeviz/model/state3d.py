"""The computed state of a spherical-side scene: what the 3D view and the 3D figure draw.

``compute_state3d(scene)`` runs the scene's eye model -- the HEALPix pair
:class:`eyeviz.core.geometry3d.EyePair3D` or a measured pair
:class:`eyeviz.core.measured.MeasuredEyePair`, through the same calls -- once for all
balls, vectorised (docs/spherical.md, docs/measured.md): the lit facets per eye as CSR
(``lit_csr``, the 3D Proposition 2), the facets lit per eye and visibility (Definition 1:
at least two facets, taken from the CSR row lengths, not recomputed), membership of the
3D binocular field of view (Prop. 4 generalised), overlap with each eye, and the polar
coordinates about the origin: r, azimuth (longitude from +x counter-clockwise seen from
above, in [0, 2 pi), the planar phi, docs/conventions.md) and elevation (from the plane
z = 0, in [-pi/2, pi/2]).

Only what the scene's layers need is computed; fields it does not need are ``None``: the
lit sets for eyes, bitmaps or readout; the BFV for bfv or readout; the overlaps for
readout. A scene whose lit sets would be too large (``lit_csr``'s bound) is refused in one
line naming the scene's eyes (their nside, or their file).

:func:`checked_state` is the app model's state function of the spherical side
(:data:`eyeviz.model.app_model.STATE_FUNCTIONS`). Why it is not
:mod:`eyeviz.model.state` (issue 37.2 keeps the two): the planar state is Proposition 2's
four integers per feature, per-ommatidium owners and a one-row update for a drag frame
(:mod:`eyeviz.core.single`); this one is lit sets as CSR over any model's facets, with no
row update (a ball's lit set changes size as it moves).

Pure numpy; no Qt, VTK or matplotlib.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from eyeviz import EyevizError
from eyeviz.core.geometry3d import EyePair3D
from eyeviz.core.measured import MeasuredEyePair
from eyeviz.model.scene import Scene

__all__ = [
    "MAX_VIEW_LIT",
    "Pair3D",
    "SceneState3D",
    "checked_state",
    "compute_state3d",
    "eyes_name",
]

#: The 3D view holds at most this many lit facets (both eyes, all balls; 128 MB of
#: indices): a scene or an edit beyond it is refused in one line, the scene kept.
MAX_VIEW_LIT = 1 << 24

#: The eye models of the spherical side: balls (x, y, z, g), lit sets per eye as CSR.
Pair3D = EyePair3D | MeasuredEyePair

_LIT_LAYERS = frozenset({"eyes", "bitmaps", "readout", "predictions"})
_BFV_LAYERS = frozenset({"bfv", "readout", "predictions"})


@dataclass
class SceneState3D:
    """Per-ball arrays (length n, the scene's feature order) and the lit sets per eye."""

    pair: Pair3D
    x: np.ndarray
    y: np.ndarray
    z: np.ndarray
    g: np.ndarray
    r: np.ndarray
    azimuth: np.ndarray
    elevation: np.ndarray
    #: (indptr, indices) per eye: row i holds ball i's lit facet indices, sorted (HEALPix:
    #: RING indices; measured: the eye's ommatidia in file order)
    lit_a: tuple[np.ndarray, np.ndarray] | None = None
    lit_b: tuple[np.ndarray, np.ndarray] | None = None
    facets_a: np.ndarray | None = None
    facets_b: np.ndarray | None = None
    vis_a: np.ndarray | None = None
    vis_b: np.ndarray | None = None
    in_bfv: np.ndarray | None = None
    overlap_a: np.ndarray | None = None
    overlap_b: np.ndarray | None = None

    @property
    def n(self) -> int:
        return int(self.x.shape[0])

    @property
    def healpix(self) -> EyePair3D:
        """The pair, for what draws HEALPix eyes only (rings, Mollweide cells of an nside);
        EyevizError (one line) for measured eyes."""
        if not isinstance(self.pair, EyePair3D):
            raise EyevizError(f"{eyes_name(self.pair)}: this needs HEALPix eyes ([eyes] nside)")
        return self.pair

    @property
    def facet_counts(self) -> tuple[int, int]:
        """Facets per eye (A, B): 12 nside^2 each, or the measured eyes' ommatidia."""
        return facet_counts(self.pair)

    def lit(self, i: int, eye: str) -> np.ndarray:
        """Ball ``i``'s lit facets on eye ``"A"`` or ``"B"`` (sorted facet indices)."""
        csr = {"A": self.lit_a, "B": self.lit_b}.get(eye, ())
        if csr is None:
            raise EyevizError("the lit sets were not computed (no eyes, bitmaps or readout)")
        if not csr:
            raise EyevizError(f"eye must be 'A' or 'B', got {eye!r}")
        indptr, idx = csr
        return idx[indptr[i] : indptr[i + 1]]


def facet_counts(pair: Pair3D) -> tuple[int, int]:
    """Facets per eye (A, B) of a spherical-side pair."""
    if isinstance(pair, EyePair3D):
        return (pair.npix, pair.npix)
    return pair.facet_counts


def eyes_name(pair: Pair3D) -> str:
    """The eyes in a message: ``nside = 8``, or the measured pair's name."""
    if isinstance(pair, EyePair3D):
        return f"nside = {pair.nside}"
    return f"the eyes {pair.name!r}"


def compute_state3d(scene: Scene) -> SceneState3D:
    """The state of a spherical-side scene (see the module docstring); EyevizError (one
    line) for a planar scene or lit sets beyond ``lit_csr``'s bound."""
    if not scene.in_space:
        raise EyevizError("compute_state3d needs a spherical-side scene ([eyes] nside or file)")
    pair = scene.eyes.model()
    assert isinstance(pair, EyePair3D | MeasuredEyePair)
    f = scene.features
    x, y, z, g = (np.array([getattr(ft, k) for ft in f], dtype=np.float64) for k in "xyzg")
    horiz = np.hypot(x, y)
    st = SceneState3D(
        pair,
        x,
        y,
        z,
        g,
        r=np.hypot(horiz, z),
        azimuth=np.mod(np.arctan2(y, x), 2.0 * np.pi),
        elevation=np.arctan2(z, horiz),
    )
    shown = set(scene.layers)
    if shown & _LIT_LAYERS:
        try:
            st.lit_a, st.lit_b = pair.lit_csr(x, y, z, g)
        except ValueError as exc:
            raise EyevizError(f"{eyes_name(pair)}: {exc}") from None
        st.facets_a = np.diff(st.lit_a[0])
        st.facets_b = np.diff(st.lit_b[0])
        st.vis_a, st.vis_b = st.facets_a >= 2, st.facets_b >= 2
    if shown & _BFV_LAYERS:
        st.in_bfv = pair.in_bfv(x, y, z, g)
    if "readout" in shown:
        st.overlap_a, st.overlap_b = pair.overlaps_eye(x, y, z, g)
    return st


def checked_state(scene: Scene) -> SceneState3D:
    """:func:`compute_state3d`, refused (EyevizError, one line) beyond MAX_VIEW_LIT: the
    app model's state function of the spherical side (``eyeviz.model.app_model``)."""
    st = compute_state3d(scene)
    n = sum(int(c[1].size) for c in (st.lit_a, st.lit_b) if c is not None)
    if n > MAX_VIEW_LIT:
        raise EyevizError(
            f"the balls light {n:,} facets ({eyes_name(st.pair)}); the 3D view draws at "
            f"most {MAX_VIEW_LIT:,} (smaller balls, farther balls or a smaller nside)"
        )
    return st
