"""The computed state of a scene: what every view (VTK app, vector export) draws from.

``compute_state(scene)`` runs the geometry core (:class:`eyeviz.core.geometry.EyePair`) once for
all features, vectorised: the lit intervals of Prop. 2, visibility (Definition 1), BFV
membership (Prop. 4), overlap with the eyes, polar coordinates about the origin and each
eye centre, and per-eye ownership of every ommatidium. Only what the scene's layers need
is computed; fields a scene does not need are ``None``.

``update_state(state, scene, rows)`` is the same state after the features ``rows`` moved
(a drag frame): those rows through the one-feature path of :mod:`eyeviz.core.single`,
equal field by field to ``compute_state(scene)``.

Pure numpy; no Qt, VTK or torch.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from eyeviz.core import single
from eyeviz.core.geometry import EyePair, intervals_to_bitmap
from eyeviz.model.layers import needs_of
from eyeviz.model.scene import Scene

__all__ = ["SceneState", "compute_state", "owners", "update_state"]


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


def _needs(layers) -> tuple[bool, bool, bool]:
    """Whether ``layers`` need the intervals, the owner arrays, the readout (each layer's
    ``needs`` in the layer table, :mod:`eyeviz.model.layers`)."""
    need = needs_of(layers)
    return "intervals" in need, "owners" in need, "readout" in need


def compute_state(scene: Scene, layers=None) -> SceneState:
    """State of ``scene`` for its layers (or for ``layers`` when given)."""
    pair = scene.eyes.pair()
    need_iv, need_own, need_read = _needs(scene.layers if layers is None else layers)
    fs = scene.features
    x = np.array([f.x for f in fs], dtype=np.float64)
    y = np.array([f.y for f in fs], dtype=np.float64)
    g = np.array([f.g for f in fs], dtype=np.float64)
    st = SceneState(pair, x, y, g)
    if need_iv:
        st.LA, st.RA, st.LB, st.RB = pair.intervals(x, y, g)
        st.vis_a, st.vis_b = st.RA > st.LA, st.RB > st.LB
    if need_own:
        LA, RA, LB, RB = st.intervals()
        st.owner_a = owners(LA, RA, pair.m)
        st.owner_b = owners(LB, RB, pair.m)
    if need_read:
        st.in_bfv = pair.in_bfv(x, y, g)
        st.overlap_a, st.overlap_b = pair.overlaps_eye(x, y, g)
        st.r, st.phi = _polar(x, y, 0.0)
        st.rA, st.phiA = pair.eye_polar(x, y, "A")
        st.rB, st.phiB = pair.eye_polar(x, y, "B")
    return st


#: More moved rows than this: one vectorised pass is cheaper than the rows one by one.
_ROWS_MAX = 8


def _polar_row(x: float, y: float, cx: float) -> tuple[float, float, float]:
    """(r, phi as :func:`_polar` gives it, phi as ``EyePair.eye_polar`` gives it) about
    (cx, 0): the same numpy ufuncs (the same inner loops) on 0-d values."""
    dx = np.float64(x) - cx
    yy = np.float64(y)
    r = np.hypot(dx, yy)
    phi = np.arctan2(yy, dx)
    phi_o = np.mod(phi, 2.0 * math.pi)
    phi_e = phi + 2 * math.pi if phi < 0 else phi
    phi_e = np.minimum(phi_e, np.nextafter(2 * math.pi, 0))
    return float(r), float(phi_o), float(phi_e)


def update_state(state: SceneState, scene: Scene, rows) -> SceneState:
    """``compute_state(scene)`` where only the features ``rows`` moved (x, y or g) since
    ``state`` was computed for the same eyes and layers; a new state, ``state`` is kept.

    Each moved row goes through :mod:`eyeviz.core.single` (Prop. 2, 4 in Python floats,
    ~20 µs a row against ~300 µs for a vectorised pass) and, where its rounding bound does
    not clear the intervals, through ``EyePair.intervals`` on that row. Falls back to
    :func:`compute_state` when the feature count, the eyes or the needed fields differ, or
    when more than a few rows moved.
    """
    fs = scene.features
    rows = sorted(set(rows))
    pair = scene.eyes.pair()
    need_iv, need_own, need_read = _needs(scene.layers)
    same = (
        len(fs) == state.n
        and pair == state.pair
        and need_iv == (state.LA is not None)
        and need_own == (state.owner_a is not None)
        and need_read == (state.r is not None)
        and all(0 <= i < state.n for i in rows)
    )
    if not same or len(rows) > _ROWS_MAX:
        return compute_state(scene)
    st = SceneState(pair, state.x.copy(), state.y.copy(), state.g.copy())
    for name in (
        "LA", "RA", "LB", "RB", "vis_a", "vis_b", "in_bfv", "overlap_a", "overlap_b",
        "r", "phi", "rA", "phiA", "rB", "phiB",
    ):  # fmt: skip
        v = getattr(state, name)
        setattr(st, name, None if v is None else v.copy())
    lit_changed = False
    for i in rows:
        f = fs[i]
        x, y, g = float(f.x), float(f.y), float(f.g)
        if not single.valid_feature(x, y, g):
            return compute_state(scene)  # refuses it with the core's own message
        st.x[i], st.y[i], st.g[i] = x, y, g
        if need_iv:
            LA, RA, LB, RB = st.intervals()
            iv = single.intervals_one(pair, x, y, g)
            if iv is None:  # near a boundary (or invalid): the vectorised, exact path
                la, ra, lb, rb = pair.intervals(st.x[i : i + 1], st.y[i : i + 1], st.g[i : i + 1])
                iv = (int(la[0]), int(ra[0]), int(lb[0]), int(rb[0]))
            lit_changed = lit_changed or iv != (int(LA[i]), int(RA[i]), int(LB[i]), int(RB[i]))
            LA[i], RA[i], LB[i], RB[i] = iv
            assert st.vis_a is not None and st.vis_b is not None
            st.vis_a[i], st.vis_b[i] = iv[1] > iv[0], iv[3] > iv[2]
        if need_read:
            assert st.in_bfv is not None and st.overlap_a is not None
            assert st.overlap_b is not None and st.r is not None and st.phi is not None
            assert st.rA is not None and st.phiA is not None
            assert st.rB is not None and st.phiB is not None
            st.in_bfv[i] = single.in_bfv_one(pair, x, y, g)
            st.overlap_a[i], st.overlap_b[i] = single.overlaps_one(pair, x, y, g)
            st.r[i], st.phi[i], _ = _polar_row(x, y, 0.0)
            st.rA[i], _, st.phiA[i] = _polar_row(x, y, -pair.h)
            st.rB[i], _, st.phiB[i] = _polar_row(x, y, pair.h)
    if need_own and lit_changed:
        LA, RA, LB, RB = st.intervals()
        st.owner_a = owners(LA, RA, pair.m)
        st.owner_b = owners(LB, RB, pair.m)
    elif need_own:  # the same lit cells: the same (never written) arrays, so views skip them
        st.owner_a, st.owner_b = state.owner_a, state.owner_b
    return st
