"""Rays from each eye's lit facets, and the point where two rays come closest.

The estimators of the spherical side (analytic, limit, learned) all read a ball's position
from two rays, one per eye, and their closest approach: the 3D form of the planar
triangulation (Eqs. 20-25 read backwards). What a ray is depends on the eye model only
through the facets' geometry:

- **HEALPix eyes** (docs/spherical.md): the origin is the eye centre, (-h, 0, 0) or
  (h, 0, 0); the direction is the normalised sum of the lit cells' centre directions
  (:func:`cap_estimates`, from :func:`eyeviz.estimators.healpix_summaries.eye_summaries`:
  equal solid angles, so the plain mean is the solid-angle-weighted one);
- **measured eyes** (docs/measured.md): the origin is the mean lens position of the lit
  facets (:func:`lens_rays`) and the direction the centre of the cap fitted to the lit
  set's inner boundary (:func:`boundary_rays`); the lit facets' mean unit axis where no
  cap fits.

The midpoint of the shortest segment between
A + s u and B + t v is the estimate; rays that do not meet in front of both eyes (s or
t <= 0, or parallel) are not triangulated (``ok`` False). Imports numpy only.
"""

from __future__ import annotations

import math

import numpy as np

from eyeviz.estimators.healpix_summaries import eye_summaries

__all__ = [
    "boundary_rays",
    "cap_estimates",
    "closest_approach",
    "lens_rays",
    "triangulate",
    "triangulate_rays",
    "triangulate_xyz",
]

#: One eye's lit sets as CSR rows: (indptr int (n + 1,), indices int (nnz,)).
LitCSR = tuple[np.ndarray, np.ndarray]


def closest_approach(
    u: np.ndarray, v: np.ndarray, d: np.ndarray, e: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(s, t, ok) of the closest approach of A + s u and B + t v (unit directions (n, 3)),
    given d = u . (A - B) and e = v . (A - B); ``ok`` is False where the rays do not meet
    in front of both origins (s or t <= 0, parallel, or not finite)."""
    # eyes near the float range overflow to inf (flagged), not a RuntimeWarning (issue 36)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        b = np.einsum("ij,ij->i", u, v)
        den = 1.0 - b * b
        s = (b * e - d) / den
        t = (e - b * d) / den
    ok = (den > 1e-15) & (s > 0) & (t > 0) & np.isfinite(s) & np.isfinite(t)
    return s, t, ok


def triangulate(u: np.ndarray, v: np.ndarray, h: float) -> tuple[np.ndarray, np.ndarray]:
    """(p (n, 3), ok): the midpoint of the closest approach of A + s u and B + t v
    (A = (-h, 0, 0), B = (h, 0, 0), unit directions (n, 3)); ``ok`` False where they do
    not meet in front of both eyes (s or t <= 0, or parallel); p is NaN there."""
    with np.errstate(over="ignore", invalid="ignore"):
        s, t, ok = closest_approach(u, v, -2.0 * h * u[:, 0], -2.0 * h * v[:, 0])
        s = np.where(ok, s, np.nan)
        t = np.where(ok, t, np.nan)
        p = 0.5 * (s[:, None] * u + t[:, None] * v)
    ok &= np.isfinite(p).all(axis=1)
    return np.where(ok[:, None], p, np.nan), ok


def triangulate_xyz(
    u: np.ndarray, v: np.ndarray, h: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(x, y, z, ok): :func:`triangulate`'s point by coordinate; where ``ok`` is False the
    point is (u + v) / 2 (s = t = 1), finite, for the learned features to correct."""
    s, t, ok = closest_approach(u, v, -2.0 * h * u[:, 0], -2.0 * h * v[:, 0])
    s = np.where(ok, s, 1.0)
    t = np.where(ok, t, 1.0)
    x = 0.5 * (s * u[:, 0] + t * v[:, 0])
    y = 0.5 * (s * u[:, 1] + t * v[:, 1])
    z = 0.5 * (s * u[:, 2] + t * v[:, 2])
    return x, y, z, ok


def triangulate_rays(
    oa: np.ndarray, u: np.ndarray, ob: np.ndarray, v: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """(p (n, 3), ok): the midpoint of the closest approach of oa + s u and ob + t v for
    origins per row (n, 3) (or one (3,) each); NaN where ``ok`` is False."""
    w = np.broadcast_to(np.asarray(oa, np.float64) - np.asarray(ob, np.float64), u.shape)
    s, t, ok = closest_approach(u, v, np.einsum("ij,ij->i", u, w), np.einsum("ij,ij->i", v, w))
    s = np.where(ok, s, np.nan)
    t = np.where(ok, t, np.nan)
    p = 0.5 * ((oa + s[:, None] * u) + (ob + t[:, None] * v))
    return p, ok


def cap_estimates(nside: int, lit: LitCSR) -> tuple[np.ndarray, np.ndarray]:
    """HEALPix: (u (n, 3), alpha (n,)): each row's cap centre, the normalised mean of its
    lit facets' centres, and its angular radius from the lit solid angle, 2 pi (1 - cos a)
    = count 4 pi / npix, less 0.635 facet widths (the boundary facets are only partly
    covered; the mean overhang measured at nside 180). Rows lighting nothing get NaN."""
    s = eye_summaries(nside, lit[0], lit[1], bounds=False)  # the count and the sum alone
    norm = np.linalg.norm(s.sum_xyz, axis=1, keepdims=True)
    with np.errstate(divide="ignore", invalid="ignore"):
        u = s.sum_xyz / norm
    npix = 12 * nside * nside
    cos_a = np.clip(1.0 - 2.0 * s.count / npix, -1.0, 1.0)
    alpha = np.arccos(cos_a) - 0.635 * math.sqrt(4 * math.pi / npix)
    alpha = np.where(s.count > 0, np.maximum(alpha, 0.5 * math.sqrt(4 * math.pi / npix)), np.nan)
    return u, alpha


def lens_rays(
    positions: np.ndarray, axes: np.ndarray, lit: LitCSR
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Measured eye: (origin (n, 3), direction (n, 3), count (n,)) per CSR row: the mean
    lens position of the row's lit facets and the normalised mean of their unit axes.
    Rows lighting nothing get NaN origin and direction."""
    ptr = np.asarray(lit[0], np.int64)
    idx = np.asarray(lit[1], np.int64)
    n = ptr.size - 1
    count = np.diff(ptr)
    unit = axes / np.linalg.norm(axes, axis=1, keepdims=True)
    row = np.repeat(np.arange(n), count)
    pos_sum = np.empty((n, 3))
    ax_sum = np.empty((n, 3))
    for j in range(3):
        pos_sum[:, j] = np.bincount(row, weights=positions[idx, j], minlength=n)
        ax_sum[:, j] = np.bincount(row, weights=unit[idx, j], minlength=n)
    with np.errstate(divide="ignore", invalid="ignore"):
        origin = pos_sum / count[:, None]
        direction = ax_sum / np.linalg.norm(ax_sum, axis=1, keepdims=True)
    return origin, direction, count


#: Neighbours per facet that define the lit set's boundary (a hexagonal lattice has 6).
BOUNDARY_NEIGHBOURS = 6
#: A fitted cap centre further than this from the lit facets' mean axis is not trusted.
BOUNDARY_MAX_TURN = math.radians(20.0)


def facet_neighbours(axes: np.ndarray, k: int = BOUNDARY_NEIGHBOURS) -> np.ndarray:
    """(n, k) int: each facet's k nearest facets by the angle between their unit axes."""
    from scipy.spatial import cKDTree

    unit = axes / np.linalg.norm(axes, axis=1, keepdims=True)
    k = min(k, unit.shape[0] - 1)
    return np.asarray(cKDTree(unit).query(unit, k=k + 1)[1][:, 1:], np.int64).reshape(-1, k)


def boundary_rays(
    positions: np.ndarray, axes: np.ndarray, lit: LitCSR, neighbours: np.ndarray | None = None
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Measured eye: (origin (n, 3), direction (n, 3), fitted (n,)) per CSR row.

    A ball lights the facets whose axes lie within a cap about its direction (to the lens
    offsets), but an eye's field ends: a ball in the binocular field sits at the rim of
    each eye's field, its lit set is the cap cut off on the midline side, and the lit
    axes' mean leans away from the ball (docs/measured.md). The cap's edge where it lies
    inside the eye's field is still seen: the midpoints x_j of (lit facet, unlit
    neighbour) axis pairs lie on it, x_j . d = cos R. The direction is the normalised
    least-squares w of x_j . w = 1 (w = d / cos R), which the rim does not bias. The
    origin is :func:`lens_rays`' mean lens position. A row keeps the mean axis
    (``fitted`` False) where fewer than 3 boundary points exist, the 3x3 system is
    ill-conditioned (eigenvalue ratio below 1e-6), or the fit turns more than 20 degrees
    from the mean axis."""
    origin, mean_dir, count = lens_rays(positions, axes, lit)
    nb = facet_neighbours(axes) if neighbours is None else neighbours
    ptr = np.asarray(lit[0], np.int64)
    idx = np.asarray(lit[1], np.int64)
    n, nfac, k = ptr.size - 1, axes.shape[0], nb.shape[1]
    row = np.repeat(np.arange(n), count)
    keys = row * nfac + idx  # sorted: CSR rows in order, each row's indices sorted
    rr = np.repeat(row, k)
    ii = np.repeat(idx, k)
    jj = nb[idx].ravel()
    want = rr * nfac + jj
    at = np.minimum(np.searchsorted(keys, want), max(keys.size - 1, 0))
    unlit = keys[at] != want if keys.size else np.ones(want.shape, bool)
    rr, ii, jj = rr[unlit], ii[unlit], jj[unlit]
    ai, aj = axes[ii], axes[jj]  # only the boundary pairs' axes are normalised
    x = ai / np.linalg.norm(ai, axis=1, keepdims=True) + aj / np.linalg.norm(aj, axis=1)[:, None]
    x /= np.linalg.norm(x, axis=1, keepdims=True)
    m = np.empty((n, 3, 3))
    b = np.empty((n, 3))
    for i in range(3):
        b[:, i] = np.bincount(rr, x[:, i], minlength=n)
        for j in range(3):
            m[:, i, j] = np.bincount(rr, x[:, i] * x[:, j], minlength=n)
    ev = np.linalg.eigvalsh(m)
    fitted = (np.bincount(rr, minlength=n) >= 3) & (ev[:, 0] > 1e-6 * ev[:, 2])
    w = np.linalg.solve(np.where(fitted[:, None, None], m, np.eye(3)), b[..., None])[..., 0]
    with np.errstate(divide="ignore", invalid="ignore"):
        d = w / np.linalg.norm(w, axis=1, keepdims=True)
        fitted &= np.einsum("ij,ij->i", d, mean_dir) > math.cos(BOUNDARY_MAX_TURN)
    return origin, np.where(fitted[:, None], d, mean_dir), fitted
