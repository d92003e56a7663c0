"""The ambiguity region: every centre that gives the same two bitmaps as a feature.

The eyes see a circular feature only through its lit intervals (LA, RA, LB, RB) of
Prop. 2: ommatidium L_E holds the lower tangent direction phi_E - arcsin(g/r_E) and R_E
the upper one phi_E + arcsin(g/r_E) (Eq. 11-12, Figure 3b). For a fixed radius g each of
these four facts is a pair of half-plane constraints on the centre p. With
d_E(beta, p) the signed distance of p from the line through the eye centre E at angle
beta (positive to the left of the direction beta):

    lower tangent in sector L:   d_E(L*gamma) >= g        and  d_E((L+1)*gamma) <  g
    upper tangent in sector R:   d_E(R*gamma) >= -g       and  d_E((R+1)*gamma) < -g

(the first says the disc lies left of the ray at L*gamma, the second that it does not
lie wholly left of the next boundary; the upper tangent likewise with the disc on the
right). Together they imply the lower tangent falls in [L*gamma, (L+1)*gamma) and the
upper in [R*gamma, (R+1)*gamma), so every point of the region reproduces the intervals;
conversely a centre reproducing them satisfies the constraints unless it lies in the
thin annulus g < r_E < g / cos(gamma/2) about an eye, where the disc nearly covers the eye.

So the region is the convex polygon cut by 8 half-planes (4 per eye); it is unbounded
when the eyes' constraints do not close it (far features whose disparity is below one
ommatidium). The constraints are linear in (p, g) jointly, so the radii g for which some
centre reproduces the intervals form an interval, found as the extreme vertices of a
3-D polyhedron.

Everything reported (vertices, boundedness, the r, phi and g ranges) is computed from the
half-planes alone, never from the caller's view: ``box`` only clips the polygon handed
back for drawing. Boundedness is decided by the recession cone of the half-planes.

The annulus (issue 13). Every point of the polygon reproduces the intervals, but when the
disc nearly covers an eye (g < r_E < g / cos(gamma/2)) the half-planes of that eye exclude
centres that do reproduce them (the tangent directions are then more than pi - gamma
apart and a line constraint is no longer equivalent to a sector constraint). A centre
in that annulus of eye E lights R_E - L_E >= m/2 - 1 ommatidia of E, so when both eyes
light fewer the polygon is exact; otherwise :attr:`AmbiguityRegion.exact` is False, the
region is "unknown in the annulus" (:attr:`AmbiguityRegion.annuli` names them) and the
polygon is only the part of the region outside it (possibly empty, possibly without the
feature's own centre); the radius range then always holds the feature's own g.

Pure numpy; no Qt, VTK or torch.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, field

import numpy as np

from eyeviz.core.geometry import EyePair, validate_features

__all__ = [
    "AmbiguityRegion",
    "ambiguity_polygon",
    "ambiguity_radius_range",
    "ambiguity_region",
    "clip_halfplanes",
    "halfplanes",
]


@dataclass(frozen=True)
class AmbiguityRegion:
    """Centres with radius ``g`` that light exactly ``intervals`` in both eyes.

    ``polygon``: the region clipped to ``box`` (for drawing; counter-clockwise, empty when
    none). ``vertices``: the region's own corners (independent of any box); ``rays``:
    unit directions along which it runs off to infinity (empty when ``bounded``).
    ``exact``: False when the region may also hold centres in ``annuli`` (eye, x of its
    centre, inner and outer radius) that the polygon leaves out (module docstring).
    """

    intervals: tuple[int, int, int, int]  # (LA, RA, LB, RB)
    g: float
    polygon: np.ndarray  # (k, 2) vertices, counter-clockwise; empty when infeasible
    bounded: bool  # False: the region runs off to infinity (decided without any box)
    box: tuple[float, float, float, float]  # (xmin, xmax, ymin, ymax) used for clipping
    vertices: np.ndarray = field(default_factory=lambda: np.empty((0, 2)))
    rays: np.ndarray = field(default_factory=lambda: np.empty((0, 2)))
    exact: bool = True
    annuli: tuple[tuple[str, float, float, float], ...] = ()
    hull: np.ndarray | None = None  # the region clipped to a box made from itself only

    @property
    def area(self) -> float:
        """Area of the drawn (clipped) polygon."""
        p = self.polygon
        if len(p) < 3:
            return 0.0
        x, y = p[:, 0], p[:, 1]
        return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))

    def distance_range(self) -> tuple[float, float]:
        """(min, max) distance r from the origin over the region: the DD uncertainty.

        Independent of ``box``; max is inf when the region is unbounded. NaN when the
        polygon is empty (possible only when not ``exact``)."""
        p = self.polygon if self.hull is None else self.hull
        if len(p) == 0:
            return (math.nan, math.nan)
        if self.bounded and len(self.vertices):
            rmax = float(np.hypot(self.vertices[:, 0], self.vertices[:, 1]).max())
        elif self.bounded:
            rmax = float(np.hypot(p[:, 0], p[:, 1]).max())
        else:
            rmax = math.inf
        if len(p) >= 3 and _contains(p, 0.0, 0.0):
            return (0.0, rmax)
        a, b = p, np.roll(p, -1, axis=0)
        ab = b - a
        t = np.clip(-(a * ab).sum(1) / np.maximum((ab * ab).sum(1), 1e-300), 0.0, 1.0)
        near = a + t[:, None] * ab
        return (float(np.hypot(near[:, 0], near[:, 1]).min()), rmax)

    def azimuth_range(self) -> tuple[float, float]:
        """(min, max) azimuth phi (radians) over the region (a convex set off the origin),
        the directions of its rays included when it is unbounded; independent of ``box``."""
        pts = self.vertices if len(self.vertices) else self.polygon
        if len(pts) == 0:
            return (math.nan, math.nan)
        phi = np.arctan2(pts[:, 1], pts[:, 0])
        if len(self.rays):
            phi = np.concatenate([phi, np.arctan2(self.rays[:, 1], self.rays[:, 0])])
        return (float(phi.min()), float(phi.max()))


def _contains(poly: np.ndarray, x: float, y: float) -> bool:
    a, b = poly, np.roll(poly, -1, axis=0)
    cross = (b[:, 0] - a[:, 0]) * (y - a[:, 1]) - (b[:, 1] - a[:, 1]) * (x - a[:, 0])
    return bool(np.all(cross >= 0))


def halfplanes(pair: EyePair, intervals) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The 8 constraints ``a . p + b * g >= c`` (``>`` where ``strict``) of the region.

    Returns (a (8, 2), b (8,), c (8,), strict (8,) bool): rows 0-3 eye A, 4-7 eye B, each
    eye as (lower >= , lower <, upper >=, upper <) of the module docstring.
    """
    gam = pair.gamma
    rows_a, rows_b, rows_c, strict = [], [], [], []
    for (cx, _), (L, R) in zip(
        pair.centers, ((intervals[0], intervals[1]), (intervals[2], intervals[3])), strict=True
    ):
        # d(beta, p) = n(beta) . p + k(beta), n = (-sin beta, cos beta), k = cx sin beta
        for idx, sign_g, flip, is_strict in (
            (L, 1.0, 1.0, False),  # d(L) - g >= 0
            (L + 1, 1.0, -1.0, True),  # g - d(L+1) > 0
            (R, -1.0, 1.0, False),  # d(R) + g >= 0
            (R + 1, -1.0, -1.0, True),  # -g - d(R+1) > 0
        ):
            beta = (int(idx) % pair.m) * gam
            s, c = math.sin(beta), math.cos(beta)
            n = np.array([-s, c])
            k = cx * s
            # flip * (n.p + k - sign_g * g) >= 0  ->  flip n . p - flip sign_g g >= -flip k
            rows_a.append(flip * n)
            rows_b.append(-flip * sign_g)
            rows_c.append(-flip * k)
            strict.append(is_strict)
    return np.array(rows_a), np.array(rows_b), np.array(rows_c), np.array(strict)


def clip_halfplanes(poly: np.ndarray, a: np.ndarray, c: np.ndarray) -> np.ndarray:
    """Clip a convex polygon (k, 2) by the half-planes ``a[i] . p >= c[i]`` (Sutherland-Hodgman)."""
    for ai, ci in zip(a, c, strict=True):
        if len(poly) == 0:
            break
        s = poly @ ai - ci
        out = []
        k = len(poly)
        for i in range(k):
            j = (i + 1) % k
            if s[i] >= 0:
                out.append(poly[i])
            if (s[i] >= 0) != (s[j] >= 0):
                t = s[i] / (s[i] - s[j])
                out.append(poly[i] + t * (poly[j] - poly[i]))
        poly = np.array(out).reshape(-1, 2)
    return poly


def _default_box(x: float, y: float, g: float, h: float) -> tuple[float, float, float, float]:
    half = 100.0 * (math.hypot(x, y) + g + h)
    return (-half, half, -half, half)


def _checked(pair: EyePair, x, y, g) -> tuple[float, float, float, tuple[int, int, int, int]]:
    xa, ya, ga = validate_features(x, y, g)
    if xa.ndim != 0:
        raise ValueError("ambiguity_region takes one feature (scalars x, y, g)")
    x, y, g = float(xa), float(ya), float(ga)
    for name, (cx, _) in zip("AB", pair.centers, strict=True):
        if math.hypot(x - cx, y) <= g:
            raise ValueError(
                f"the feature covers eye {name}'s centre: that eye sees it everywhere, "
                "so its ambiguity region is not a polygon"
            )
    la, ra, lb, rb = (int(v) for v in pair.intervals(x, y, g))
    return x, y, g, (la, ra, lb, rb)


def _corners(a: np.ndarray, c: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Vertices and extreme rays of {p : a[i] . p >= c[i]} without any box.

    Vertices: intersections of two boundary lines satisfying every constraint (to a
    relative tolerance); rays: the directions +-perp(a[i]) in the recession cone
    {d : a . d >= 0}. Exact up to rounding of the 2x2 solves."""
    n = len(a)
    verts = []
    scale = np.abs(a).sum(1)
    for i, j in itertools.combinations(range(n), 2):
        det = a[i, 0] * a[j, 1] - a[i, 1] * a[j, 0]
        if abs(det) < 1e-14:
            continue
        px = (c[i] * a[j, 1] - a[i, 1] * c[j]) / det
        py = (a[i, 0] * c[j] - c[i] * a[j, 0]) / det
        mag = abs(px) + abs(py) + np.abs(c).max()
        if np.all(a @ (px, py) - c >= -1e-9 * scale * mag):
            verts.append((px, py))
    rays = []
    for i in range(n):
        for sgn in (1.0, -1.0):
            d = sgn * np.array([-a[i, 1], a[i, 0]]) / math.hypot(a[i, 0], a[i, 1])
            if np.all(a @ d >= -1e-12 * scale):
                rays.append(d)
    v = np.array(verts).reshape(-1, 2)
    if len(v) > 1:
        v = np.unique(np.round(v, 9), axis=0) if np.all(np.isfinite(v)) else v
    return v, np.array(rays).reshape(-1, 2)


def _annuli(pair: EyePair, iv, g: float) -> tuple[tuple[str, float, float, float], ...]:
    """The eyes whose annulus g < r_E < g / cos(gamma/2) may hold matching centres: those
    lighting at least m/2 - 3 ommatidia beyond L_E (a centre there lights >= m/2 - 1)."""
    out = []
    half = pair.m // 2
    outer = g / math.cos(pair.gamma / 2)
    for name, (cx, _), (L, R) in zip(
        "AB", pair.centers, ((iv[0], iv[1]), (iv[2], iv[3])), strict=True
    ):
        if R - L >= half - 3:
            out.append((name, float(cx), float(g), float(outer)))
    return tuple(out)


def ambiguity_region(pair: EyePair, x, y, g, *, box=None) -> AmbiguityRegion:
    """Centres of radius-g discs lighting the same (LA, RA, LB, RB) as the feature (x, y, g).

    ``box`` (xmin, xmax, ymin, ymax) only clips the returned ``polygon`` for drawing (by
    default a box made from the region itself); every range and ``bounded`` are the same
    whatever the box. The polygon is the closure of the region (its strict edges belong
    to the neighbouring region). See the module docstring for ``exact``.
    """
    x, y, g, iv = _checked(pair, x, y, g)
    a, b, c, _ = halfplanes(pair, iv)
    cg = c - b * g
    verts, rays = _corners(a, cg)
    half = 100.0 * (math.hypot(x, y) + g + pair.h)
    if len(verts):
        half = max(half, 4.0 * float(np.abs(verts).max()))
    own = (-half, half, -half, half)
    hull = ambiguity_polygon(pair, iv, g, own)
    if box is None:
        box, poly = own, hull
    else:
        box = tuple(float(v) for v in box)
        if not all(math.isfinite(v) for v in box) or not (box[0] < box[1] and box[2] < box[3]):
            raise ValueError(f"box must be finite (xmin < xmax, ymin < ymax), got {box!r}")
        poly = ambiguity_polygon(pair, iv, g, box)
    annuli = _annuli(pair, iv, g)
    bounded = bool(len(rays) == 0 and len(verts) > 0)
    return AmbiguityRegion(iv, g, poly, bounded, box, verts, rays, not annuli, annuli, hull)


def ambiguity_polygon(pair: EyePair, intervals, g: float, box) -> np.ndarray:
    """Closure of the centres of radius-g discs lighting ``intervals`` = (LA, RA, LB, RB),
    clipped to ``box`` (xmin, xmax, ymin, ymax): (k, 2) vertices, empty when none."""
    x0, x1, y0, y1 = (float(v) for v in box)
    a, b, c, _ = halfplanes(pair, intervals)
    square = np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]], dtype=np.float64)
    poly = clip_halfplanes(square, a, c - b * float(g))
    return _dedupe(poly, tol=1e-12 * max(abs(v) for v in (x0, x1, y0, y1)))


def _dedupe(poly: np.ndarray, tol: float) -> np.ndarray:
    if len(poly) < 2:
        return poly
    keep = np.linalg.norm(poly - np.roll(poly, 1, axis=0), axis=1) > tol
    out = poly[keep]
    return out if len(out) else poly[:1]


def ambiguity_radius_range(pair: EyePair, x, y, g, *, box=None) -> tuple[float, float]:
    """(g_min, g_max): the radii for which some centre lights the feature's intervals.

    The 8 constraints are linear in (p_x, p_y, g); with g >= 0 they bound a convex
    polyhedron whose extreme g lie at vertices, enumerated exactly (3 planes at a time)
    inside a box made from the feature only (``box`` is accepted for compatibility and
    ignored: the range never depends on a view). The range is closed (strict edges are
    taken as their closure); g_max is inf when it is reached only on that box (the
    polyhedron runs off to infinity). It always holds the feature's own g; when the
    region is not exact (module docstring) it may be wider than reported.
    """
    del box
    x, y, g, iv = _checked(pair, x, y, g)
    x0, x1, y0, y1 = _default_box(x, y, g, pair.h)
    a2, b, c, _ = halfplanes(pair, iv)
    rows = [np.array([*ai, bi]) for ai, bi in zip(a2, b, strict=True)]
    rhs = list(c)
    # g >= 0 and the box
    rows += [np.array([0.0, 0.0, 1.0]), np.array([1.0, 0, 0]), np.array([-1.0, 0, 0]),
             np.array([0, 1.0, 0]), np.array([0, -1.0, 0])]  # fmt: skip
    rhs += [0.0, x0, -x1, y0, -y1]
    A = np.array(rows)
    C = np.array(rhs)
    scale = np.abs(A).sum(1) * x1
    lo, hi, hi_on_box = math.inf, -math.inf, False
    for i, j, k in itertools.combinations(range(len(A)), 3):
        M = A[[i, j, k]]
        if abs(np.linalg.det(M)) < 1e-12:
            continue
        v = np.linalg.solve(M, C[[i, j, k]])
        if np.all(A @ v - C >= -1e-9 * scale):
            on_box = max(i, j, k) >= 9
            if v[2] > hi or (v[2] == hi and not on_box):
                hi, hi_on_box = v[2], on_box
            lo = min(lo, v[2])
    # the feature's own (x, y, g) is feasible: only rounding or the annulus (module
    # docstring) can leave it out; never an error, the range then holds g itself
    lo, hi = min(lo, g), max(hi, g)
    if hi_on_box and hi > g:
        hi = math.inf
    return (max(lo, 0.0), hi)
