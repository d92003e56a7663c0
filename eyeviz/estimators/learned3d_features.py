"""The learned 3D estimator's input: features of both eyes' lit-set summaries.

The per-eye summaries (count, sum of facet centres, edge longitudes, z-extent, bounds on
the cap centre's longitude) are :mod:`eyeviz.estimators.healpix_summaries`'s, which the
analytic and limit estimators read too; the triangulation of the two mean directions is
:mod:`eyeviz.estimators.triangulation`'s. :func:`features` turns both eyes' summaries
into the network's input and the triangulation it corrects. Imports numpy only.
"""

from __future__ import annotations

import math

import numpy as np

from eyeviz.estimators.healpix_summaries import N_BOUNDS, EyeSummary, eye_summaries
from eyeviz.estimators.triangulation import triangulate_xyz as triangulate

__all__ = ["N_FEATURES", "EyeSummary", "eye_summaries", "features", "triangulate"]

N_FEATURES = 20 + 2 * N_BOUNDS


def features(
    sa: EyeSummary, sb: EyeSummary, h: float, nside: int, r_min: float, r_max: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(X float32 (n, N_FEATURES), log r0, azimuth0, elevation0, valid, flagged).

    r0, azimuth0, elevation0 are the triangulation of the two mean directions, r0 clipped
    to [r_min, r_max] (where the rays do not meet: r_max); the network corrects them.
    Columns: per eye the mean direction's longitude and z, the angular radius of the
    lit cap from the count (count * 4 pi / npix = 2 pi (1 - cos alpha)) and from the
    mean vector's length ((1 + cos alpha) / 2 for a uniform cap), the west and east edge
    longitudes about the mean, the z-extent about the mean and the centre longitude's
    bounds (:func:`_bounds`); then the disparities of the mean longitudes and of the two
    edges, the triangulation, its 1 / disparity and the difference of the cap radii.
    ``valid`` is False where an eye lit nothing (the features are then NaN);
    ``flagged`` where the rays do not meet in front of both eyes."""
    npix = 12 * nside * nside
    omega = 4.0 * math.pi / npix
    cols = []
    dirs = []
    for s in (sa, sb):
        cnt = s.count.astype(np.float64)
        with np.errstate(divide="ignore", invalid="ignore"):
            norm = np.linalg.norm(s.sum_xyz, axis=1)
            u = s.sum_xyz / norm[:, None]
            lon = np.arctan2(u[:, 1], u[:, 0]) % (2.0 * math.pi)
            cos_a_count = 1.0 - cnt * omega / (2.0 * math.pi)
            alpha_count = np.arccos(np.clip(cos_a_count, -1.0, 1.0))
            cos_a_mean = np.clip(2.0 * norm / cnt - 1.0, -1.0, 1.0)
            alpha_mean = np.arccos(cos_a_mean)
        dirs.append((u, lon, alpha_count))
        cols += [
            lon - 0.5 * math.pi,
            u[:, 2],
            alpha_count,
            alpha_mean - alpha_count,
            (lon - s.lon_w) - alpha_count,
            (s.lon_e - lon) - alpha_count,
            0.5 * (s.z_top + s.z_bottom) - u[:, 2],
            *s.bounds.T,
        ]
    (u, lon_a, al_a), (v, lon_b, al_b) = dirs
    x, y, z, ok = triangulate(u, v, h)
    rho = np.sqrt(x * x + y * y + z * z)
    r0 = np.where(ok, np.clip(rho, r_min, r_max), r_max)
    mean_dir = u + v
    with np.errstate(invalid="ignore", divide="ignore"):
        mean_dir /= np.linalg.norm(mean_dir, axis=1, keepdims=True)
        az0 = np.where(ok, np.arctan2(y, x), np.arctan2(mean_dir[:, 1], mean_dir[:, 0]))
        el0 = np.where(ok, np.arcsin(np.clip(z / rho, -1.0, 1.0)), np.arcsin(mean_dir[:, 2]))
    disp = lon_b - lon_a
    log_r0 = np.log(r0)
    gamma = 2.0 * math.pi / (4 * nside)
    cols += [
        disp / gamma,
        (sb.lon_w - sa.lon_w) / gamma,
        (sb.lon_e - sa.lon_e) / gamma,
        log_r0 - 0.5 * math.log(r_min * r_max),
        1.0 / (np.abs(disp) / gamma + 1.0),
        al_a - al_b,
    ]
    X = np.stack(cols, axis=1).astype(np.float32)
    valid = (sa.count > 0) & (sb.count > 0) & np.isfinite(X).all(axis=1)
    return X, log_r0, az0, el0, valid, ~ok
