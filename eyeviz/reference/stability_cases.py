"""Case classes for the numerical-stability report and the exactness tests, per eye model.

Each generator returns a set of float64 features with the eyes they are meant for; the
classes of each model are a table (:data:`KINDS`: ``"planar"`` -> :data:`CLASSES`,
``"spherical"`` -> :data:`CLASSES3D`) and :func:`make` draws one of them. Which cases are
adversarial is the model's own geometry:

- planar (:class:`CaseSet`, discs (x, y, g)): tangent directions exactly on (or within
  rounding of) ommatidium boundaries, discs grazing an eye centre, stretched scales and m;
- spherical (:class:`CaseSet3D`, balls (x, y, z, g)): the cap's rim exactly on facet
  boundaries (the equator's vertices at longitude k gamma, where the planar ties live),
  caps centred exactly on a pole or on a base cell's vertex, grazing, stretched scales
  (docs/spherical.md lists the tie classes). The eyes are small (nside 4 to 16) so that
  the independent reference (:mod:`eyeviz.reference.healpix_reference`), which visits
  every facet, stays affordable.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from eyeviz.core import paper
from eyeviz.core.geometry import EyePair
from eyeviz.core.geometry3d import EyePair3D

__all__ = ["CLASSES", "CLASSES3D", "KINDS", "CaseSet", "CaseSet3D", "make"]

PAPER = EyePair(paper.H, paper.L, paper.M)


def _decimal(v: np.ndarray, rng: np.random.Generator, most: int) -> np.ndarray:
    """Round each value to a random number (0..most) of decimals, as people type them."""
    scale = 10.0 ** rng.integers(0, most + 1, v.shape)
    return np.round(v * scale) / scale


@dataclass(frozen=True)
class CaseSet:
    name: str
    description: str
    eyes: EyePair
    x: np.ndarray
    y: np.ndarray
    g: np.ndarray


def paper_regime(n: int, rng: np.random.Generator, eyes: EyePair = PAPER) -> CaseSet:
    """Algorithm 1 steps 7-12 (Tables 3-4): r in [1000, 5000], g in [r sin(gamma/2), 500]."""
    r = rng.uniform(1000, 5000, 4 * n)
    gmin = r * math.sin(eyes.gamma / 2)
    g = rng.uniform(gmin, 500)
    ok = (gmin <= 500) & (g <= r)
    r, g = r[ok][:n], g[ok][:n]
    a = np.arcsin(g / r)
    phi = rng.uniform(eyes.psi + a, math.pi - eyes.psi - a)
    return CaseSet(
        "paper regime",
        "Algorithm 1 sampling, Tables 3-4",
        eyes,
        r * np.cos(phi),
        r * np.sin(phi),
        g,
    )


def anywhere(n: int, rng: np.random.Generator, eyes: EyePair = PAPER) -> CaseSet:
    """Centres anywhere in the plane (log-uniform distance), g log-uniform in [1e-3, 1e3]."""
    d = 10 ** rng.uniform(0, 4, n)
    ang = rng.uniform(0, 2 * math.pi, n)
    base = np.where(rng.random(n) < 0.5, -eyes.h, eyes.h)
    x = base + d * np.cos(ang)
    y = d * np.sin(ang)
    g = 10 ** rng.uniform(-3, 3, n)
    return CaseSet("random anywhere", "any position and size, eyes included", eyes, x, y, g)


def resting_on_ground(n: int, rng: np.random.Generator, eyes: EyePair = PAPER) -> CaseSet:
    """Discs tangent to the line y = 0 from above or below (y = +/-g exactly)."""
    g = _decimal(10 ** rng.uniform(-2, 3, n), rng, 5)
    g = np.where(g > 0, g, 0.5)
    x = _decimal(rng.uniform(-6000, 6000, n), rng, 3)
    y = np.where(rng.random(n) < 0.8, g, -g)
    return CaseSet(
        "resting on y = 0",
        "tangent to the ground line: a tangent on direction 0 or pi",
        eyes,
        x,
        y,
        g,
    )


def touching_vertical(n: int, rng: np.random.Generator, eyes: EyePair = PAPER) -> CaseSet:
    """Discs tangent to the vertical line through an eye centre (x = +/-h +/- g), and
    discs whose tangents fall exactly on 30-degree boundaries (centre at distance 2g on
    an eye's axis lines), both with dyadic and with decimal sizes."""
    g = np.where(
        rng.random(n) < 0.5,
        rng.integers(1, 4000, n) / 8.0,
        _decimal(10 ** rng.uniform(-2, 3, n), rng, 3),
    )
    g = np.where(g > 0, g, 0.25)
    cx = np.where(rng.random(n) < 0.5, -eyes.h, eyes.h)
    side = np.where(rng.random(n) < 0.5, -1.0, 1.0)
    kind = rng.integers(0, 3, n)
    y_free = _decimal(rng.uniform(-3000, 3000, n), rng, 2)
    x = np.where(kind == 0, cx + side * g, np.where(kind == 1, cx, cx + side * 2 * g))
    y = np.where(kind == 0, y_free, np.where(kind == 1, side * 2 * g, 0.0))
    return CaseSet(
        "touching an eye's vertical line",
        "x = +/-h +/- g; 30-degree ties: centre at 2g on an eye's axes",
        eyes,
        x,
        y,
        g,
    )


def grazing(n: int, rng: np.random.Generator, eyes: EyePair = PAPER) -> CaseSet:
    """g / r_E -> 1 from below, down to 1 - 2^-50: the eye centre almost on the rim."""
    cx = np.where(rng.random(n) < 0.5, -eyes.h, eyes.h)
    d = 10 ** rng.uniform(-1, 4, n)
    ang = rng.uniform(0, 2 * math.pi, n)
    x = cx + d * np.cos(ang)
    y = d * np.sin(ang)
    rE = np.hypot(x - cx, y)
    g = rE * (1 - 2.0 ** -rng.integers(1, 51, n))
    return CaseSet("grazing", "g/r_E = 1 - 2^-k, k = 1..50", eyes, x, y, g)


def extreme_scales(n: int, rng: np.random.Generator, eyes: EyePair = PAPER) -> CaseSet:
    """Distances up to 1e15 and radii down to 1e-6."""
    r = 10 ** rng.uniform(2, 15, n)
    ang = rng.uniform(0, 2 * math.pi, n)
    g = np.minimum(10 ** rng.uniform(-6, 6, n), 0.5 * r)
    return CaseSet(
        "extreme scales", "r up to 1e15, g down to 1e-6", eyes, r * np.cos(ang), r * np.sin(ang), g
    )


def huge_m(n: int, rng: np.random.Generator) -> CaseSet:
    """m = 2^20 ommatidia: paper-regime features and discs resting on y = 0."""
    eyes = EyePair(paper.H, paper.L, 2**20)
    a = paper_regime(n - n // 2, rng, eyes)
    b = resting_on_ground(n // 2, rng, eyes)
    return CaseSet(
        "huge m (2^20)",
        "m = 1,048,576: paper regime and ground ties",
        eyes,
        np.concatenate([a.x, b.x]),
        np.concatenate([a.y, b.y]),
        np.concatenate([a.g, b.g]),
    )


def nearly_closed_bfv(n: int, rng: np.random.Generator) -> CaseSet:
    """l -> h: l = h (1 - 2^-k), features inside the thin BFV."""
    k = int(rng.integers(10, 40))
    eyes = EyePair(paper.H, paper.H * (1 - 2.0**-k), paper.M)
    r = rng.uniform(1000, 5000, n)
    half = eyes.theta / 2
    g = r * np.sin(half) * rng.uniform(0.05, 0.95, n)
    a = np.arcsin(g / r)
    phi = rng.uniform(eyes.psi + a, math.pi - eyes.psi - a)
    return CaseSet(
        "nearly closed BFV",
        f"l = h (1 - 2^-{k}), features inside the BFV",
        eyes,
        r * np.cos(phi),
        r * np.sin(phi),
        g,
    )


CLASSES: dict[str, Callable[[int, np.random.Generator], CaseSet]] = {
    "paper": paper_regime,
    "anywhere": anywhere,
    "ground": resting_on_ground,
    "vertical": touching_vertical,
    "grazing": grazing,
    "extreme": extreme_scales,
    "huge_m": huge_m,
    "closed_bfv": nearly_closed_bfv,
}


@dataclass(frozen=True)
class CaseSet3D:
    name: str
    description: str
    eyes: EyePair3D
    x: np.ndarray
    y: np.ndarray
    z: np.ndarray
    g: np.ndarray


def paper_regime3d(n: int, rng: np.random.Generator) -> CaseSet3D:
    """Algorithm 1 in 3D (r in [1000, 5000], g in [r sin(gamma/2), 500], elevation within
    +-30 degrees), at nside 16 (m = 64)."""
    eyes = EyePair3D(paper.H, paper.L, 16)
    r = rng.uniform(1000, 5000, n)
    g = rng.uniform(r * math.sin(math.pi / (4 * 16)), 500.0)
    el = rng.uniform(-math.pi / 6, math.pi / 6, n)
    az = rng.uniform(math.pi / 6, 5 * math.pi / 6, n)
    x, y, z = r * np.cos(el) * np.cos(az), r * np.cos(el) * np.sin(az), r * np.sin(el)
    return CaseSet3D("paper regime", "Algorithm 1 in 3D, nside 16", eyes, x, y, z, g)


def resting_on_plane(n: int, rng: np.random.Generator) -> CaseSet3D:
    """Centres on z = 0: caps symmetric about the equator, so every equatorial facet's
    N-S diagonal is cut at its middle (nside 8)."""
    eyes = EyePair3D(paper.H, paper.L, 8)
    r = 10 ** rng.uniform(1.8, 3.5, n)
    az = rng.uniform(0, 2 * math.pi, n)
    g = r * rng.uniform(0.02, 0.6, n)
    x, y = np.round(r * np.cos(az), 3), np.round(r * np.sin(az), 3)
    return CaseSet3D("on z = 0", "centres on the plane z = 0, nside 8", eyes, x, y, 0 * x, g)


def equator_ties(n: int, rng: np.random.Generator) -> CaseSet3D:
    """The planar tie classes lifted to z = 0: discs resting on y = 0 and touching an eye's
    vertical line, whose tangents fall exactly on longitude k gamma: the cap's rim passes
    exactly through an equatorial vertex of the HEALPix grid (nside 8, m = 32)."""
    eyes = EyePair3D(paper.H, paper.L, 8)
    flat = EyePair(paper.H, paper.L, 32)
    a = resting_on_ground(n - n // 2, rng, flat)
    b = touching_vertical(n // 2, rng, flat)
    x, y, g = (np.concatenate([getattr(a, k), getattr(b, k)]) for k in "xyg")
    return CaseSet3D(
        "equator vertex ties",
        "planar ties on z = 0: the rim through an equatorial vertex, nside 8",
        eyes,
        x,
        y,
        0 * x,
        g,
    )


def poles(n: int, rng: np.random.Generator) -> CaseSet3D:
    """Centres straight above or below an eye centre (the cap centred on a pole, where
    longitude is undefined), and a hair beside it (nside 8)."""
    eyes = EyePair3D(paper.H, paper.L, 8)
    cx = np.where(rng.random(n) < 0.5, -paper.H, paper.H)
    off = np.where(rng.random(n) < 0.5, 0.0, 2.0 ** -rng.integers(20, 60, n).astype(float))
    z = np.where(rng.random(n) < 0.5, 1.0, -1.0) * 10 ** rng.uniform(1.5, 3.5, n)
    g = np.abs(z) * rng.uniform(0.01, 0.9, n)
    return CaseSet3D(
        "over a pole",
        "centres on an eye's polar axis (or 2^-k off it), nside 8",
        eyes,
        cx + off,
        0 * z + off,
        z,
        g,
    )


def base_vertices(n: int, rng: np.random.Generator) -> CaseSet3D:
    """Caps centred exactly on a vertex of the 12 base cells on the equator (longitude
    pi/4 + k pi/2, where four base cells meet), nside 4 and 8."""
    nside = int(rng.choice([4, 8]))
    eyes = EyePair3D(paper.H, paper.L, nside)
    cx = np.where(rng.random(n) < 0.5, -paper.H, paper.H)
    t = np.round(10 ** rng.uniform(1, 3, n), 2)
    sx = np.where(rng.random(n) < 0.5, -1.0, 1.0)
    sy = np.where(rng.random(n) < 0.5, -1.0, 1.0)
    g = t * rng.uniform(0.01, 1.2, n)
    return CaseSet3D(
        "base-cell vertices",
        f"caps centred on an equatorial base vertex, nside {nside}",
        eyes,
        cx + sx * t,
        sy * t,
        0 * t,
        g,
    )


def grazing3d(n: int, rng: np.random.Generator) -> CaseSet3D:
    """g / |d| = 1 - 2^-k, k = 1..50: the eye centre almost on the ball's surface (the cap
    almost a hemisphere), nside 8."""
    eyes = EyePair3D(paper.H, paper.L, 8)
    cx = np.where(rng.random(n) < 0.5, -paper.H, paper.H)
    d = 10 ** rng.uniform(-1, 3, n)
    v = rng.normal(size=(3, n))
    v /= np.linalg.norm(v, axis=0)
    x, y, z = cx + d * v[0], d * v[1], d * v[2]
    dd = np.sqrt((x - cx) ** 2 + y * y + z * z)
    g = dd * (1 - 2.0 ** -rng.integers(1, 51, n))
    return CaseSet3D("grazing", "g/|d| = 1 - 2^-k, k = 1..50, nside 8", eyes, x, y, z, g)


def extreme_scales3d(n: int, rng: np.random.Generator) -> CaseSet3D:
    """Distances up to 1e15 and radii down to 1e-6 (nside 8)."""
    eyes = EyePair3D(paper.H, paper.L, 8)
    r = 10 ** rng.uniform(2, 15, n)
    v = rng.normal(size=(3, n))
    v /= np.linalg.norm(v, axis=0)
    g = np.minimum(10 ** rng.uniform(-6, 6, n), 0.5 * r)
    x, y, z = r * v
    return CaseSet3D("extreme scales", "r up to 1e15, g down to 1e-6, nside 8", eyes, x, y, z, g)


CLASSES3D: dict[str, Callable[[int, np.random.Generator], CaseSet3D]] = {
    "paper": paper_regime3d,
    "plane": resting_on_plane,
    "equator_ties": equator_ties,
    "poles": poles,
    "base_vertices": base_vertices,
    "grazing": grazing3d,
    "extreme": extreme_scales3d,
}

#: The case classes of each eye model.
KINDS: dict[str, dict[str, Callable[[int, np.random.Generator], Any]]] = {
    "planar": CLASSES,
    "spherical": CLASSES3D,
}


def make(name: str, n: int, seed: int = 0, kind: str = "planar") -> Any:
    """``n`` features of the case class ``name`` of the eye model ``kind``, drawn with
    ``seed`` (a :class:`CaseSet` of discs, or a :class:`CaseSet3D` of balls)."""
    return KINDS[kind][name](n, np.random.default_rng(seed))
