"""Predictions, ambiguity and trajectory accuracy for the app (Qt-free, VTK-free).

:class:`Predictor` lives in :mod:`eyeviz.model.predictor` (shared with the vector export).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from eyeviz.core.geometry import EyePair, intervals_to_bitmap
from eyeviz.model.predictor import Predictor
from eyeviz.model.scene import Trajectory

__all__ = [
    "Predictor",
    "TrajectoryPath",
    "ambiguity_of",
    "errors",
    "trajectory_path",
]


def errors(r: float, phi: float, r_hat: float, phi_hat: float) -> tuple[float, float, float]:
    """(delta r, delta r in % of r, delta phi in degrees wrapped to (-180, 180])."""
    dr = r_hat - r
    dphi = math.degrees(math.remainder(phi_hat - phi, 2 * math.pi))
    return dr, 100.0 * dr / r, dphi


def ambiguity_of(pair: EyePair, x: float, y: float, g: float, box) -> dict | None:
    """The ambiguity region of one feature (eyeviz.core.ambiguity) with its ranges, or None
    when the feature covers an eye centre (no polygon then)."""
    from eyeviz.core.ambiguity import ambiguity_radius_range, ambiguity_region

    try:
        reg = ambiguity_region(pair, x, y, g, box=box)
        g_range = ambiguity_radius_range(pair, x, y, g, box=box)
    except ValueError:
        return None
    return {
        "polygon": reg.polygon,
        "bounded": reg.bounded,
        "r_range": reg.distance_range(),
        "phi_range": reg.azimuth_range(),
        "g_range": g_range,
    }


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


def trajectory_path(
    pair: EyePair,
    traj: Trajectory,
    estimators: list[str],
    predictor: Predictor | None,
    n: int = 240,
    stop: float = 6000.0,
) -> TrajectoryPath:
    """Points along ``traj`` (eyeviz.model.trajectories) where the feature is in the BFV, with
    AD and DD accuracy (100 % - APE, Section 6, Figure 15) per estimator at each point.
    ValueError (one line) when the trajectory never enters the BFV."""
    from eyeviz.model import trajectories as tr

    if traj.kind == "horizontal":
        x, y = tr.horizontal(traj.distance, traj.g, n, h=pair.h, l=pair.l)
        axis, label = x, f"x along y = {traj.distance:g}"
    elif traj.kind == "circular":
        x, y = tr.circular(traj.distance, traj.g, n, h=pair.h, l=pair.l)
        axis, label = np.degrees(np.arctan2(y, x)), f"φ (°) on r = {traj.distance:g}"
    elif traj.kind == "vertical":
        x, y = tr.vertical(
            traj.g, n, start=traj.distance, stop=max(stop, 2 * traj.distance), h=pair.h, l=pair.l
        )
        axis, label = y, "y along x = 0"
    else:
        raise ValueError(
            f"trajectory kind must be horizontal, circular or vertical, got {traj.kind!r}"
        )
    acc: dict[str, tuple[np.ndarray, np.ndarray] | str] = {}
    if predictor is not None and estimators:
        m = pair.m
        LA, RA, LB, RB = pair.intervals(x, y, np.full_like(x, traj.g))
        oa = intervals_to_bitmap(LA, RA, m, m // 2)
        ob = intervals_to_bitmap(LB, RB, m, m // 2)
        r, phi = np.hypot(x, y), np.arctan2(y, x)
        for name in estimators:
            res = predictor.predict_bitmaps(name, oa, ob)
            if isinstance(res, str):
                acc[name] = res
                continue
            r_hat, phi_hat = res
            ad = 100.0 - 100.0 * np.abs(phi_hat - phi) / phi
            dd = 100.0 - 100.0 * np.abs(r_hat - r) / r
            acc[name] = (ad, dd)
    return TrajectoryPath(traj.kind, x, y, float(traj.g), np.asarray(axis), label, acc)
