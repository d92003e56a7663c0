"""Case classes of balls for the spherical eyes' stability report and exactness tests.

Each generator returns a :class:`CaseSet3D` of float64 balls (x, y, z, g) with the eyes they
are meant for. The adversarial classes put the cap's rim exactly on facet boundaries (the
equator's vertices at longitude k gamma, where the planar ties live), centre caps exactly on
a pole or on a base cell's vertex, graze an eye centre, or stretch the scales
(docs/spherical.md lists the tie classes). The eyes are small (nside 4 to 16) so that the
independent reference (:mod:`eyeviz.reference.healpix_reference`), which visits every facet,
stays affordable.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from eyeviz.core import paper
from eyeviz.core.geometry import EyePair
from eyeviz.core.geometry3d import EyePair3D
from eyeviz.reference import stability_cases as planar

__all__ = ["CLASSES", "CaseSet3D", "make"]


@dataclass(frozen=True)
class CaseSet3D:
    name: str
    description: str
    eyes: EyePair3D
    x: np.ndarray
    y: np.ndarray
    z: np.ndarray
    g: np.ndarray


def paper_regime(n: int, rng: np.random.Generator) -> CaseSet3D:
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
    a = planar.resting_on_ground(n - n // 2, rng, flat)
    b = planar.touching_vertical(n // 2, rng, flat)
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


def grazing(n: int, rng: np.random.Generator) -> CaseSet3D:
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


def extreme_scales(n: int, rng: np.random.Generator) -> CaseSet3D:
    """Distances up to 1e15 and radii down to 1e-6 (nside 8)."""
    eyes = EyePair3D(paper.H, paper.L, 8)
    r = 10 ** rng.uniform(2, 15, n)
    v = rng.normal(size=(3, n))
    v /= np.linalg.norm(v, axis=0)
    g = np.minimum(10 ** rng.uniform(-6, 6, n), 0.5 * r)
    x, y, z = r * v
    return CaseSet3D("extreme scales", "r up to 1e15, g down to 1e-6, nside 8", eyes, x, y, z, g)


CLASSES: dict[str, Callable[[int, np.random.Generator], CaseSet3D]] = {
    "paper": paper_regime,
    "plane": resting_on_plane,
    "equator_ties": equator_ties,
    "poles": poles,
    "base_vertices": base_vertices,
    "grazing": grazing,
    "extreme": extreme_scales,
}


def make(name: str, n: int, seed: int = 0) -> CaseSet3D:
    return CLASSES[name](n, np.random.default_rng(seed))
