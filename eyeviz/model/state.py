"""The computed state of a scene: what every view (VTK app, vector export) draws from.

``compute_state(scene)`` runs the geometry core (:class:`eyeviz.core.geometry.EyePair`) once for
all features, vectorised: the lit intervals of Prop. 2, visibility (Definition 1), BFV
membership (Prop. 4), overlap with the eyes, polar coordinates about the origin and each
eye centre, and per-eye ownership of every ommatidium. Only what the scene's layers need
is computed; fields a scene does not need are ``None``.

Pure numpy; no Qt, VTK or torch.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from eyeviz.core.geometry import EyePair, intervals_to_bitmap
from eyeviz.model.scene import Scene

__all__ = ["SceneState", "compute_state", "owners"]

# Layers that need the lit intervals; the ownership arrays; the per-feature readout.
_NEED_INTERVALS = {"eyes", "bitmaps", "sectors", "readout", "labels", "predictions", "ambiguity"}
_NEED_OWNERS = {"eyes"}
_NEED_READOUT = {"readout", "labels", "predictions", "tangents", "ambiguity", "features", "sectors"}


@dataclass
class SceneState:
    """Per-feature arrays (length n = number of features) and per-eye arrays (length m)."""

    pair: EyePair
    x: np.ndarray
    y: np.ndarray
    g: np.ndarray
    LA: np.ndarray | None = None
    RA: np.ndarray | None = None
    LB: np.ndarray | None = None
    RB: np.ndarray | None = None
    vis_a: np.ndarray | None = None
    vis_b: np.ndarray | None = None
    in_bfv: np.ndarray | None = None
    overlap_a: np.ndarray | None = None
    overlap_b: np.ndarray | None = None
    r: np.ndarray | None = None
    phi: np.ndarray | None = None
    rA: np.ndarray | None = None
    phiA: np.ndarray | None = None
    rB: np.ndarray | None = None
    phiB: np.ndarray | None = None
    owner_a: np.ndarray | None = None
    owner_b: np.ndarray | None = None

    @property
    def n(self) -> int:
        return int(self.x.shape[0])

    @property
    def m(self) -> int:
        return self.pair.m

    def bitmaps(self, i: int, width: int | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Feature i's bitmaps (omega_a, omega_b); width m//2 is the paper's Omega."""
        LA, RA, LB, RB = self.intervals()
        m = self.m
        return (
            intervals_to_bitmap(LA[i], RA[i], m, width),
            intervals_to_bitmap(LB[i], RB[i], m, width),
        )

    def intervals(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """(LA, RA, LB, RB); ValueError when no layer needed them."""
        LA, RA, LB, RB = self.LA, self.RA, self.LB, self.RB
        if LA is None or RA is None or LB is None or RB is None:
            raise ValueError("this state has no intervals (no layer needed them)")
        return LA, RA, LB, RB

    def in_domain(self) -> np.ndarray:
        """Features the networks were trained on: in the BFV and visible to both eyes."""
        in_bfv, vis_a, vis_b = self.in_bfv, self.vis_a, self.vis_b
        if in_bfv is None or vis_a is None or vis_b is None:
            raise ValueError("this state has no BFV or visibility (no layer needed them)")
        return in_bfv & vis_a & vis_b


def owners(L: np.ndarray, R: np.ndarray, m: int) -> np.ndarray:
    """Index of the feature lighting each of the m ommatidia (-1: none; the last one wins)."""
    out = np.full(m, -1, dtype=np.int64)
    for i, (lo, hi) in enumerate(zip(L.tolist(), R.tolist(), strict=True)):
        if hi < m:
            out[lo : hi + 1] = i
        else:
            out[lo:] = i
            out[: hi - m + 1] = i
    return out


def _polar(x: np.ndarray, y: np.ndarray, cx: float) -> tuple[np.ndarray, np.ndarray]:
    dx = x - cx
    return np.hypot(dx, y), np.mod(np.arctan2(y, dx), 2.0 * math.pi)


def compute_state(scene: Scene, layers=None) -> SceneState:
    """State of ``scene`` for its layers (or for ``layers`` when given)."""
    pair = scene.eyes.pair()
    shown = set(scene.layers if layers is None else layers)
    fs = scene.features
    x = np.array([f.x for f in fs], dtype=np.float64)
    y = np.array([f.y for f in fs], dtype=np.float64)
    g = np.array([f.g for f in fs], dtype=np.float64)
    st = SceneState(pair, x, y, g)
    if shown & _NEED_INTERVALS:
        st.LA, st.RA, st.LB, st.RB = pair.intervals(x, y, g)
        st.vis_a, st.vis_b = st.RA > st.LA, st.RB > st.LB
    if shown & _NEED_OWNERS:
        LA, RA, LB, RB = st.intervals()
        st.owner_a = owners(LA, RA, pair.m)
        st.owner_b = owners(LB, RB, pair.m)
    if shown & _NEED_READOUT:
        st.in_bfv = pair.in_bfv(x, y, g)
        st.overlap_a, st.overlap_b = pair.overlaps_eye(x, y, g)
        st.r, st.phi = _polar(x, y, 0.0)
        st.rA, st.phiA = pair.eye_polar(x, y, "A")
        st.rB, st.phiB = pair.eye_polar(x, y, "B")
    return st
