"""Case classes for the numerical-stability report and the exactness tests.

Each generator returns a :class:`CaseSet` of float64 features (x, y, g) with the eyes
they are meant for. Adversarial classes put tangent directions exactly on (or within
rounding of) ommatidium boundaries, graze an eye centre, or stretch scales and m.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from eyeviz.core import paper
from eyeviz.core.geometry import EyePair

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


def make(name: str, n: int, seed: int = 0) -> CaseSet:
    return CLASSES[name](n, np.random.default_rng(seed))
