"""Frames and units of measured eye files (docs/eye_files.md).

eyeviz's frame: x towards eye B, y forward, z up (eye A on the left, at -x), millimetres.
A file's frame is given as the file's axes that become eyeviz's x, y and z, each with a
sign: ``"x,-z,y"`` reads "eyeviz x = file x, eyeviz y = file -z, eyeviz z = file y".
Only signed permutations are allowed, and only proper rotations (determinant +1: a
reflection would swap the left and right eyes): they are exact in floating point, so a
file written and read back through the same frame is equal to the last bit.

Named frames:

- ``"compoundray"`` = ``"x,-z,y"``: CompoundRay's (a camera's local frame: x right,
  y up, looking along -z), the frame of the shipped ``.eye`` files;
- ``"gltf"`` = ``"-x,z,y"``: glTF's asset frame (+y up, +z forward, -x right), the
  default of OCES files;
- ``"eyeviz"`` = ``"x,y,z"``.
"""

from __future__ import annotations

import math
import warnings

import numpy as np

from eyeviz import EyevizError

__all__ = [
    "EyeSizeWarning",
    "FRAMES",
    "UNITS",
    "Frame",
    "check_units",
    "parse_frame",
    "warn_if_implausible",
]

FRAMES = {"compoundray": "x,-z,y", "gltf": "-x,z,y", "eyeviz": "x,y,z"}
#: millimetres per unit
UNITS = {"mm": 1.0, "m": 1000.0, "um": 1e-3}
#: The size check: the largest distance of a lens from the mean of all lenses, in mm.
#: Insect heads are about 0.1 to 10 mm across; eyeviz's own designs are tens of mm.
PLAUSIBLE_MM = (1e-2, 1e3)


class EyeSizeWarning(UserWarning):
    """A measured eye file's size looks wrong for its units (metres read as mm?)."""


class Frame:
    """A signed permutation from a file's axes to eyeviz's (see the module doc)."""

    def __init__(self, perm: tuple[int, int, int], sign: tuple[float, float, float], text: str):
        self.perm = perm
        self.sign = np.array(sign, dtype=np.float64)
        self.text = text

    def to_eyeviz(self, v: np.ndarray) -> np.ndarray:
        """(n, 3) file coordinates -> eyeviz's (exact: a copy with signs flipped)."""
        return v[:, list(self.perm)] * self.sign

    def from_eyeviz(self, v: np.ndarray) -> np.ndarray:
        """(n, 3) eyeviz coordinates -> the file's (exact inverse of :meth:`to_eyeviz`)."""
        out = np.empty_like(v)
        out[:, list(self.perm)] = v * self.sign
        return out

    def __repr__(self) -> str:
        return f"Frame({self.text!r})"


def parse_frame(frame) -> Frame:
    """A :class:`Frame` from a name in :data:`FRAMES`, a ``"x,-z,y"`` string or a Frame."""
    if isinstance(frame, Frame):
        return frame
    if not isinstance(frame, str):
        raise EyevizError(f"frame must be a string such as 'x,-z,y' or one of {sorted(FRAMES)}")
    text = FRAMES.get(frame.strip().lower(), frame)
    parts = [t.strip().lower() for t in text.split(",")]
    perm: list[int] = []
    sign: list[float] = []
    for t in parts:
        s = -1.0 if t.startswith("-") else 1.0
        ax = t.lstrip("+-")
        if ax not in ("x", "y", "z") or t.count("-") + t.count("+") > 1:
            perm = []
            break
        perm.append("xyz".index(ax))
        sign.append(s)
    if len(parts) != 3 or len(perm) != 3 or sorted(perm) != [0, 1, 2]:
        raise EyevizError(
            f"frame {frame!r}: give the file's axes that become eyeviz's x, y, z, each "
            f"once with a sign (e.g. 'x,-z,y'), or one of {sorted(FRAMES)}"
        )
    m = np.zeros((3, 3))
    for row, (c, s) in enumerate(zip(perm, sign, strict=True)):
        m[row, c] = s
    if round(float(np.linalg.det(m))) != 1:
        raise EyevizError(
            f"frame {frame!r} is a reflection, not a rotation: it would swap the left and "
            "right eyes (flip the sign of one axis)"
        )
    return Frame((perm[0], perm[1], perm[2]), (sign[0], sign[1], sign[2]), ",".join(parts))


def check_units(units) -> float:
    """Millimetres per unit for ``"mm"``, ``"m"`` or ``"um"``."""
    if not isinstance(units, str) or units not in UNITS:
        raise EyevizError(f"units must be one of {sorted(UNITS)}, got {units!r}")
    return UNITS[units]


def warn_if_implausible(positions_mm: np.ndarray, units: str, what: str) -> None:
    """Warn (:class:`EyeSizeWarning`) when the lenses span less than 0.01 mm or more than
    1 m: a file in metres read as millimetres (one published ant file is), or the other
    way round."""
    if positions_mm.size == 0:
        return
    c = positions_mm.mean(axis=0)
    size = float(np.sqrt(((positions_mm - c) ** 2).sum(axis=1)).max())
    lo, hi = PLAUSIBLE_MM
    if lo <= size <= hi or not math.isfinite(size):
        return
    hint = [u for u in UNITS if lo <= size * UNITS[u] / UNITS[units] <= hi and u != units]
    guess = f": is it in {hint[0]!r}? pass units={hint[0]!r}" if hint else ""
    warnings.warn(
        f"{what}: the lenses span {size:.3g} mm with units={units!r}, outside the "
        f"plausible {lo:g} to {hi:g} mm{guess}",
        EyeSizeWarning,
        stacklevel=3,
    )
