"""The analytic estimator: triangulate the two eyes' lines of sight, no learning.

Eye E lights ommatidia L_E..R_E, so the feature's two tangent directions lie in sectors
L_E and R_E (Prop. 2, Eq. 11) and its centre direction phi_E is near the mid-angle
c_E = (L_E + R_E + 1) * gamma / 2 (the midpoint of the two edge sectors' middles).
The centre rays from A and B meet at the feature centre (law of sines in triangle ABP;
Eq. 22-25 read backwards). Their disparity c_B - c_A is quantised to half a sector, so
a disparity of zero or less (a far feature) is raised to a quarter sector.
"""

from __future__ import annotations

import math

import numpy as np

from eyeviz.estimators.base import PAPER_DOMAIN, Domain, Estimator, triangulate

__all__ = ["AnalyticEstimator", "load", "centre_angles", "estimate"]


def centre_angles(LA, RA, LB, RB, m: int) -> tuple[np.ndarray, np.ndarray]:
    """Mid-angles c_A, c_B of the lit intervals (radians, counter-clockwise from +x)."""
    half_gamma = math.pi / m
    return (LA + RA + 1) * half_gamma, (LB + RB + 1) * half_gamma


def estimate(
    LA, RA, LB, RB, domain: Domain = PAPER_DOMAIN, min_disparity: float = 0.25
) -> tuple[np.ndarray, np.ndarray]:
    """(r, phi) from valid interval arrays by centre-ray triangulation (Eq. 22-25 read
    backwards); ``min_disparity`` in sectors. The public form of the analytic estimate
    that other estimators (bayes' fallback, compact's baseline) build on."""
    m = domain.m
    ca, cb = centre_angles(LA, RA, LB, RB, m)
    return triangulate(ca, cb, domain.h, min_disparity * 2 * math.pi / m)


class AnalyticEstimator(Estimator):
    """Centre-ray triangulation from both eyes; 0 weights, no data needed."""

    name = "analytic"

    def __init__(self, domain: Domain = PAPER_DOMAIN, min_disparity: float = 0.25) -> None:
        super().__init__(domain, {"n_weights": 0, "train_seconds": 0.0})
        self.min_disparity = float(min_disparity)

    def _predict_intervals(self, LA, RA, LB, RB):
        return estimate(LA, RA, LB, RB, self.domain, self.min_disparity)


def load(domain: Domain = PAPER_DOMAIN, **kw) -> AnalyticEstimator:
    return AnalyticEstimator(domain, **kw)
