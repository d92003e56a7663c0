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

A measured pair (docs/measured.md) is triangulated the same way from its own rays: per
eye, from the lit facets' mean lens position along the centre of the cap fitted to the
lit set's inner boundary (:func:`estimate_measured`); the rays and the closest approach are
:mod:`eyeviz.estimators.triangulation`'s, which the limit and learned estimators read too.
"""

from __future__ import annotations

import numpy as np

from eyeviz.core.domain import PAPER_DOMAIN3D, Domain3D
from eyeviz.estimators.base import Estimator3D, LitCSR
from eyeviz.estimators.triangulation import (
    boundary_rays,
    cap_estimates,
    facet_neighbours,
    triangulate,
    triangulate_rays,
)

__all__ = [
    "Analytic3DEstimator",
    "cap_estimates",
    "ESTIMATES",
    "estimate",
    "estimate_healpix",
    "estimate_measured",
    "load",
    "triangulate",
]


def estimate(
    domain: Domain3D, lit_a: LitCSR, lit_b: LitCSR
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(r, azimuth, elevation, flagged) for rows that light at least one facet per eye:
    the public form of the analytic estimate other estimators (limit3d's fallback and
    proposal) build on, the eye model's own (:data:`ESTIMATES`)."""
    return ESTIMATES[domain.kind](domain, lit_a, lit_b)


def estimate_healpix(
    domain: Domain3D, lit_a: LitCSR, lit_b: LitCSR
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The estimate for HEALPix eyes: per eye the centre of the lit cap (its facets'
    mean direction, :func:`cap_estimates`), the two rays from the eye centres
    triangulated (:func:`triangulate`); rays that do not meet are flagged and answered
    at r_max along the mean of the two directions."""
    u, _ = cap_estimates(domain.nside, lit_a)
    v, _ = cap_estimates(domain.nside, lit_b)
    p, ok = triangulate(u, v, domain.h)
    # overflow and 0/0 (opposite caps, a design near the float range) give inf/NaN rows,
    # which are flagged; numpy's RuntimeWarnings on stderr said nothing more (issue 36)
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        mean_dir = u + v
        mean_dir /= np.linalg.norm(mean_dir, axis=1, keepdims=True)
        p = np.where(ok[:, None], p, domain.r_max * mean_dir)
        rho = np.linalg.norm(p, axis=1)
        r = np.clip(rho, domain.r_min, domain.r_max)
        az = np.arctan2(p[:, 1], p[:, 0])
        el = np.arcsin(np.clip(p[:, 2] / rho, -1.0, 1.0))
    return r, az, el, ~ok


def estimate_measured(
    domain: Domain3D, lit_a: LitCSR, lit_b: LitCSR
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The same for a measured pair: per eye the ray from the lit facets' mean lens
    position along the centre of the cap fitted to the lit set's inner boundary
    (:func:`.triangulation.boundary_rays`; the mean axis where none fits), the
    midpoint of the two rays' closest approach, and (r, azimuth, elevation) of it about
    the domain's origin (the midpoint of the two lens centroids). Rays that do not meet in
    front of both eyes are flagged and answered at r_max along the mean of the two axes."""
    eyes = domain.eyes
    pos_a, axes_a, _ = eyes.facets("A")
    pos_b, axes_b, _ = eyes.facets("B")
    oa, u, _ = boundary_rays(pos_a, axes_a, lit_a, _neighbours(eyes, "A"))
    ob, v, _ = boundary_rays(pos_b, axes_b, lit_b, _neighbours(eyes, "B"))
    p, ok = triangulate_rays(oa, u, ob, v)
    o = np.asarray(domain.origin)
    mean_dir = u + v
    mean_dir /= np.linalg.norm(mean_dir, axis=1, keepdims=True)
    q = np.where(ok[:, None], p - o, domain.r_max * mean_dir)
    rho = np.linalg.norm(q, axis=1)
    r = np.clip(rho, domain.r_min, domain.r_max)
    az = np.arctan2(q[:, 1], q[:, 0])
    el = np.arcsin(np.clip(q[:, 2] / rho, -1.0, 1.0))
    return r, az, el, ~ok


#: each eye model's (``domain.kind``) analytic estimate: a new model adds a row
ESTIMATES = {"spherical": estimate_healpix, "measured": estimate_measured}

_NEIGHBOURS: dict[tuple[str, str], np.ndarray] = {}


def _neighbours(eyes, which: str) -> np.ndarray:
    """:func:`.triangulation.facet_neighbours` of one eye, cached by the pair's fingerprint."""
    key = (eyes.fingerprint, which)
    if key not in _NEIGHBOURS:
        if len(_NEIGHBOURS) > 8:
            _NEIGHBOURS.clear()
        _NEIGHBOURS[key] = facet_neighbours(eyes.facets(which)[1])
    return _NEIGHBOURS[key]


class Analytic3DEstimator(Estimator3D):
    """Closest-approach triangulation of the two lit caps' centres (HEALPix) or of the lit
    sets' boundary-fitted rays (measured eyes); 0 weights."""

    name = "analytic3d"
    kinds = ("spherical", "measured")

    def __init__(self, domain: Domain3D = PAPER_DOMAIN3D) -> None:
        super().__init__(domain, {"n_weights": 0, "train_seconds": 0.0})

    def _predict_csr(self, lit_a: LitCSR, lit_b: LitCSR):
        return estimate(self.domain, lit_a, lit_b)


def load(domain: Domain3D | None = None) -> Analytic3DEstimator:
    """The analytic estimator for ``domain`` (default the paper's design at nside 180)."""
    return Analytic3DEstimator(PAPER_DOMAIN3D if domain is None else domain)
