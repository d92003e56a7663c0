"""The analytic estimator of the spherical eyes: triangulate the two lit caps, no learning.

A ball lights, in each eye, the facets its tangent cone meets: a spherical cap about the
direction from the eye centre to the ball (docs/spherical.md, 3D Proposition 2). HEALPix
facets all have the same solid angle, so the solid-angle-weighted mean of the lit facets'
centres is their plain mean; normalised, it is the cap's centre direction to a fraction
of a facet (u from A = (-h, 0, 0), v from B = (h, 0, 0)). The two rays A + s u and
B + t v are intersected at their closest approach (the 3D form of the planar
triangulation, Eqs. 20-25 read backwards) and the ball is its midpoint. Rays that do not
meet in front of both eyes (s or t <= 0, or parallel: a far ball whose disparity is lost
in the facets) are ``flagged``; the answer is then r_max along the mean of u and v.
r is clipped to [r_min, r_max]. Any design, no weights.
"""

from __future__ import annotations

import math

import numpy as np

from eyeviz.core.domain3d import PAPER_DOMAIN3D, Domain3D
from eyeviz.estimators.base3d import Estimator3D, LitCSR
from eyeviz.estimators.learned3d_features import eye_summaries

__all__ = ["Analytic3DEstimator", "cap_estimates", "estimate", "load", "triangulate"]


def triangulate(u: np.ndarray, v: np.ndarray, h: float):
    """(p (n, 3), ok): the midpoint of the closest approach of A + s u and B + t v
    (A = (-h, 0, 0), B = (h, 0, 0), unit directions (n, 3)); ``ok`` False where they do
    not meet in front of both eyes (s or t <= 0, or parallel); p is NaN there."""
    b = np.einsum("ij,ij->i", u, v)
    d = -2.0 * h * u[:, 0]  # u . (A - B)
    e = -2.0 * h * v[:, 0]
    den = 1.0 - b * b
    with np.errstate(divide="ignore", invalid="ignore"):
        s = (b * e - d) / den
        t = (e - b * d) / den
    ok = (den > 1e-15) & (s > 0) & (t > 0) & np.isfinite(s) & np.isfinite(t)
    s = np.where(ok, s, np.nan)
    t = np.where(ok, t, np.nan)
    p = 0.5 * (s[:, None] * u + t[:, None] * v)
    return p, ok


def cap_estimates(nside: int, lit: LitCSR) -> tuple[np.ndarray, np.ndarray]:
    """(u (n, 3), alpha (n,)): each row's cap centre, the normalised mean of its lit facets'
    centres, and its angular radius from the lit solid angle, 2 pi (1 - cos a) = count
    4 pi / npix, less 0.635 facet widths (the boundary facets are only partly covered;
    the mean overhang measured at nside 180). Rows lighting nothing get NaN."""
    s = eye_summaries(nside, lit[0], lit[1])
    norm = np.linalg.norm(s.sum_xyz, axis=1, keepdims=True)
    with np.errstate(divide="ignore", invalid="ignore"):
        u = s.sum_xyz / norm
    npix = 12 * nside * nside
    cos_a = np.clip(1.0 - 2.0 * s.count / npix, -1.0, 1.0)
    alpha = np.arccos(cos_a) - 0.635 * math.sqrt(4 * math.pi / npix)
    alpha = np.where(s.count > 0, np.maximum(alpha, 0.5 * math.sqrt(4 * math.pi / npix)), np.nan)
    return u, alpha


def estimate(
    domain: Domain3D, lit_a: LitCSR, lit_b: LitCSR
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(r, azimuth, elevation, flagged) for rows that light at least one facet per eye:
    the public form of the analytic estimate other estimators (limit3d's fallback and
    proposal) build on."""
    u, _ = cap_estimates(domain.nside, lit_a)
    v, _ = cap_estimates(domain.nside, lit_b)
    p, ok = triangulate(u, v, domain.h)
    mean_dir = u + v
    mean_dir /= np.linalg.norm(mean_dir, axis=1, keepdims=True)
    p = np.where(ok[:, None], p, domain.r_max * mean_dir)
    rho = np.linalg.norm(p, axis=1)
    r = np.clip(rho, domain.r_min, domain.r_max)
    az = np.arctan2(p[:, 1], p[:, 0])
    el = np.arcsin(np.clip(p[:, 2] / rho, -1.0, 1.0))
    return r, az, el, ~ok


class Analytic3DEstimator(Estimator3D):
    """Closest-approach triangulation of the two lit caps' centres; 0 weights."""

    name = "analytic3d"

    def __init__(self, domain: Domain3D = PAPER_DOMAIN3D) -> None:
        super().__init__(domain, {"n_weights": 0, "train_seconds": 0.0})

    def _predict_csr(self, lit_a: LitCSR, lit_b: LitCSR):
        return estimate(self.domain, lit_a, lit_b)


def load(domain: Domain3D | None = None) -> Analytic3DEstimator:
    """The analytic estimator for ``domain`` (default the paper's design at nside 180)."""
    return Analytic3DEstimator(PAPER_DOMAIN3D if domain is None else domain)
