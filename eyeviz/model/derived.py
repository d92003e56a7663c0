"""Compatibility alias: the derived quantities now live in :mod:`eyeviz.model.frame`.

``Predictor``, ``TrajectoryPath``, ``ambiguity_of``, ``errors`` and ``trajectory_path`` are
re-exported unchanged so ``eyeviz.app`` keeps importing them from here.
"""

from __future__ import annotations

from eyeviz.model.frame import TrajectoryPath, ambiguity_of, errors, trajectory_path
from eyeviz.model.predictor import Predictor

__all__ = [
    "Predictor",
    "TrajectoryPath",
    "ambiguity_of",
    "errors",
    "trajectory_path",
]
