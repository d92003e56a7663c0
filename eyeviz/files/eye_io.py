"""Reading and writing measured eyes: CompoundRay ``.eye`` (and OCES glTF, to come).

SKELETON: a plain ``.eye`` reader for the shipped files; the hardened readers and
writers replace it (issue: real eyes).
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from eyeviz import EyevizError
from eyeviz.core.measured import MeasuredEye, MeasuredEyePair

__all__ = ["load_eyes", "save_eyes", "shipped_eye"]


def shipped_eye(name: str) -> Path:
    """Path of an eye file shipped in eyeviz's assets (``assets/eyes``)."""
    from importlib.resources import files

    p = Path(str(files("eyeviz") / "assets" / "eyes" / name))
    if not p.is_file():
        raise EyevizError(f"no shipped eye named {name!r}")
    return p


def _from_compoundray_frame(v: np.ndarray) -> np.ndarray:
    # file: x lateral, y up, -z forward  ->  eyeviz: x, y forward, z up
    return np.stack([v[:, 0], -v[:, 2], v[:, 1]], axis=1)


def load_eyes(path: str | os.PathLike, units: str = "mm") -> MeasuredEyePair:
    """Load a measured eye pair (``.eye``): both eyes of the head in one file."""
    p = Path(path)
    rows = np.loadtxt(p, dtype=np.float64, ndmin=2)
    if rows.shape[1] < 7:
        raise EyevizError(f"{p.name}: expected 8 numbers a line, got {rows.shape[1]}")
    scale = {"mm": 1.0, "m": 1000.0, "um": 1e-3}[units]
    pos = _from_compoundray_frame(rows[:, 0:3]) * scale
    ax = _from_compoundray_frame(rows[:, 3:6])
    acc = rows[:, 6]
    fo = rows[:, 7] * scale if rows.shape[1] > 7 else None
    a = pos[:, 0] < 0
    eyes = []
    for sel, nm in ((a, "A"), (~a, "B")):
        eyes.append(
            MeasuredEye(pos[sel], ax[sel], acc[sel], None if fo is None else fo[sel], name=nm)
        )
    return MeasuredEyePair(eyes[0], eyes[1], name=p.stem, source=str(p))


def save_eyes(pair: MeasuredEyePair, path: str | os.PathLike) -> None:
    raise NotImplementedError("save_eyes: to come")
