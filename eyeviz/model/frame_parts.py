"""The parts of a :class:`Frame` (issue 9 item 2) and the small pure helpers they use:
runs of equal values, prediction errors, the view rectangle, an eye's rim (Figure 2, Eq. 6)
and the BFV wedge clipped to a rectangle (Definition 2). Built by
:func:`eyeviz.model.frame.build_frame`; field meanings in :mod:`eyeviz.model.frame`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from eyeviz.core.geometry import EyePair
from eyeviz.model.posterior import Posterior
from eyeviz.model.scene import Scene
from eyeviz.model.state import SceneState

__all__ = [
    "BFVFrame",
    "EyeFrame",
    "Frame",
    "LabelFrame",
    "PredictionFrame",
    "SectorFrame",
    "TangentFrame",
    "TrajectoryPath",
    "EYE_LABEL_DROP",
    "FEATURE_LABEL_OFFSET",
    "WIDE_SECTOR",
    "clip_wedge",
    "errors",
    "rim_points",
    "runs",
    "view_rect",
]

WIDE_SECTOR = 24  # runs this long draw only their two boundary rays
EYE_LABEL_DROP = 1.35  # eye and origin labels sit this many eye radii under the axis
FEATURE_LABEL_OFFSET = 0.75  # a feature's name sits this many radii up-right of its centre


# --- small pure helpers ------------------------------------------------------------------


def runs(values: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Maximal runs of equal values: (starts, stops) with stops exclusive."""
    values = np.asarray(values)
    n = len(values)
    if n == 0:
        return np.zeros(0, np.int64), np.zeros(0, np.int64)
    change = np.flatnonzero(values[1:] != values[:-1]) + 1
    starts = np.concatenate([[0], change])
    stops = np.concatenate([change, [n]])
    return starts.astype(np.int64), stops.astype(np.int64)


def errors(r: float, phi: float, r_hat: float, phi_hat: float) -> tuple[float, float, float]:
    """(delta r, delta r in % of r, delta phi in degrees wrapped to (-180, 180])."""
    dr = r_hat - r
    dphi = math.degrees(math.remainder(phi_hat - phi, 2 * math.pi))
    return dr, 100.0 * dr / r, dphi


def view_rect(scene: Scene, aspect: float = 0.86) -> tuple[float, float, float, float]:
    """The scene's view as (x0, x1, y0, y1) for a canvas of height/width ``aspect``."""
    cx, cy = scene.view.center
    w = scene.view.width
    h = w * aspect
    return (cx - w / 2, cx + w / 2, cy - h / 2, cy + h / 2)


def rim_points(
    center: tuple[float, float], l: float, m: int, starts: np.ndarray | None = None
) -> np.ndarray:
    """(c + 1, 2) points of an eye's rim at j*gamma, gamma = 2 pi / m, for j in ``starts``
    (default 0..m-1) and m (Figure 2, Eq. 6): ommatidium cell i spans rim[i] .. rim[i + 1]."""
    j = np.append(np.arange(m) if starts is None else starts, m).astype(np.float64)
    t = j * (2.0 * math.pi / m)
    return np.column_stack([center[0] + l * np.cos(t), center[1] + l * np.sin(t)])


def _clip_half_plane(
    poly: list[tuple[float, float]], nx: float, ny: float
) -> list[tuple[float, float]]:
    """Sutherland-Hodgman: keep the part of ``poly`` with nx*x + ny*y >= 0."""
    out: list[tuple[float, float]] = []
    n = len(poly)
    for i in range(n):
        p, q = poly[i], poly[(i + 1) % n]
        dp, dq = nx * p[0] + ny * p[1], nx * q[0] + ny * q[1]
        if dp >= 0:
            out.append(p)
        if (dp >= 0) != (dq >= 0):
            t = dp / (dp - dq)
            out.append((p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])))
    return out


def clip_wedge(psi: float, rect: tuple[float, float, float, float]) -> np.ndarray:
    """The BFV wedge {psi <= angle <= pi - psi} (Definition 2) clipped to ``rect``.

    The exact intersection of the rectangle with the two half-planes bounding the wedge,
    so the drawn wedge covers the whole view however far it is from the origin.
    """
    x0, x1, y0, y1 = rect
    poly = [(x0, y0), (x1, y0), (x1, y1), (x0, y1)]
    c, s = math.cos(psi), math.sin(psi)
    # right edge direction (c, s): keep the left side, normal (-s, c);
    # left edge direction (-c, s): keep the right side, normal (s, c)
    poly = _clip_half_plane(poly, -s, c)
    if poly:
        poly = _clip_half_plane(poly, s, c)
    return np.array(poly, dtype=np.float64).reshape(-1, 2)


def _ray_to_rect(
    angle: float, rect: tuple[float, float, float, float]
) -> tuple[float, float, float, float] | None:
    """The part of the ray from the origin at ``angle`` inside ``rect``, or None."""
    x0, x1, y0, y1 = rect
    dx, dy = math.cos(angle), math.sin(angle)
    t0, t1 = 0.0, math.inf
    for d, lo, hi in ((dx, x0, x1), (dy, y0, y1)):
        if abs(d) < 1e-300:
            if not lo <= 0.0 <= hi:
                return None
            continue
        a, b = lo / d, hi / d
        a, b = min(a, b), max(a, b)
        t0, t1 = max(t0, a), min(t1, b)
    if t1 <= t0:
        return None
    return (t0 * dx, t0 * dy, t1 * dx, t1 * dy)


# --- the frame's parts -------------------------------------------------------------------


@dataclass
class EyeFrame:
    """One eye: centre, per-ommatidium owner and colour index, merged colour runs
    (the last two computed when first read: a drag frame of the app reads neither)."""

    name: str
    center: tuple[float, float]
    owner: np.ndarray
    lut: np.ndarray  # owner + 1 -> colour index (0 unlit, else 1 + index into the palette)
    l: float = 0.0
    m: int = 0

    @cached_property
    def color_index(self) -> np.ndarray:
        return self.lut[self.owner + 1]

    @cached_property
    def runs(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(starts, stops exclusive, colour index) of the maximal runs of equal colour."""
        ci = self.color_index
        s, e = runs(ci)
        return s, e, ci[s]

    def starts(self, k: int = 1) -> np.ndarray:
        """First ommatidium of each run of k (the cells of the level of detail k)."""
        return np.arange(0, self.m, max(1, int(k)))

    def rim(self, k: int = 1) -> np.ndarray:
        """(c + 1, 2) rim vertices at j*gamma for j in ``starts(k)`` and m (Figure 2,
        Eq. 6): cell i is the triangle centre, rim[i], rim[i + 1]."""
        return rim_points(self.center, self.l, self.m, self.starts(k))

    def pooled_owner(self, k: int = 1) -> np.ndarray:
        """Owner of each run of k ommatidia: the last feature lighting any of them, or -1."""
        if k <= 1:
            return self.owner
        return np.maximum.reduceat(self.owner, self.starts(k))


@dataclass
class BFVFrame:
    """The BFV wedge (Definition 2, Eq. 15-16) clipped to the view rectangle ``rect``
    (the polygon and the edges computed when first read: the app's per-frame Frame only
    needs psi and theta for its labels)."""

    psi: float
    theta: float
    rect: tuple[float, float, float, float]

    @cached_property
    def polygon(self) -> np.ndarray:
        return clip_wedge(self.psi, self.rect)

    @cached_property
    def edges(self) -> list[tuple[float, float, float, float] | None]:
        """Right (psi) and left (pi - psi) edges from the origin to the rectangle's border."""
        return [_ray_to_rect(self.psi, self.rect), _ray_to_rect(math.pi - self.psi, self.rect)]


@dataclass
class TangentFrame:
    """The tangents from an eye centre to feature i's disc (Prop. 2, Figure 3b)."""

    feature: int
    eye: str
    center: tuple[float, float]
    r_e: float
    phi_e: float
    alpha: float  # asin(g / r_E)
    length: float  # sqrt(r_E^2 - g^2)
    ends: np.ndarray  # (2, 2): the tangent points, angle phi_E - alpha then phi_E + alpha


@dataclass
class SectorFrame:
    """The ommatidium sectors of a lit interval [L, R] (Eq. 8, 11)."""

    feature: int
    eye: str
    center: tuple[float, float]
    L: int
    R: int
    reach: float
    rays: list[int]  # boundary k of the ray at angle k * gamma
    ends: np.ndarray = field(default_factory=lambda: np.zeros((0, 2)))  # (len(rays), 2)


@dataclass
class LabelFrame:
    """A text anchored at (x, y): an eye (A, B), the origin (O) or a feature's name."""

    text: str
    x: float
    y: float
    kind: str  # "eye" (A, B, O) or "feature"
    feature: int | None = None


@dataclass
class PredictionFrame:
    """One estimator's answers per feature (NaN outside the networks' domain)."""

    r_hat: np.ndarray
    phi_hat: np.ndarray
    x_hat: np.ndarray
    y_hat: np.ndarray
    dr: np.ndarray
    dr_pct: np.ndarray
    dphi_deg: np.ndarray


@dataclass
class TrajectoryPath:
    """Points of a Figure 14 trajectory and the estimators' accuracy along it."""

    kind: str
    x: np.ndarray
    y: np.ndarray
    g: float
    axis: np.ndarray  # the abscissa of the accuracy plot
    axis_label: str
    accuracy: dict[str, tuple[np.ndarray, np.ndarray] | str]  # name -> (AD %, DD %) or why not

    @property
    def n(self) -> int:
        return int(self.x.shape[0])


@dataclass
class Frame:
    """Everything a renderer draws for one scene (see the module docstring)."""

    pair: EyePair
    layers: set[str]
    rect: tuple[float, float, float, float]
    state: SceneState
    names: list[str]
    colors: list[str]
    x: np.ndarray
    y: np.ndarray
    g: np.ndarray
    palette: list[str] = field(default_factory=list)
    eyes: list[EyeFrame] = field(default_factory=list)
    intervals: dict[str, tuple[np.ndarray, np.ndarray]] = field(default_factory=dict)
    bfv: BFVFrame | None = None
    tangents: list[TangentFrame] = field(default_factory=list)
    sectors: list[SectorFrame] = field(default_factory=list)
    r: np.ndarray | None = None
    phi: np.ndarray | None = None
    rA: np.ndarray | None = None
    phiA: np.ndarray | None = None
    rB: np.ndarray | None = None
    phiB: np.ndarray | None = None
    in_bfv: np.ndarray | None = None
    vis_a: np.ndarray | None = None
    vis_b: np.ndarray | None = None
    in_domain: np.ndarray | None = None
    out_of_domain: np.ndarray | None = None
    predictions: dict[str, PredictionFrame | str] = field(default_factory=dict)
    ambiguity: dict[int, dict | None] = field(default_factory=dict)
    posterior: dict[int, Posterior | None] = field(default_factory=dict)
    #: features whose ambiguity region and posterior were left out (frame.MAX_REGIONS)
    regions_left_out: int = 0
    trajectory: TrajectoryPath | None = None
    trajectory_error: str | None = None
    labels: list[LabelFrame] = field(default_factory=list)
    #: parts of layers registered outside eyeviz.model.frame, by layer name
    parts: dict[str, object] = field(default_factory=dict)

    @property
    def n(self) -> int:
        return int(self.x.shape[0])
