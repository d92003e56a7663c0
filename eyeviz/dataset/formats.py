"""What the data set files are, shared by the writers (:mod:`eyeviz.dataset.io`) and the
readers (:mod:`eyeviz.dataset.reader`): the format names, the CSV's byte codes, the NPZ's
row dtype, and the checks every row passes, read or written (issue 13: a writer refuses
what its reader would refuse).

A leaf of the package: neither io nor reader imports the other for these, so the two
modules form no import cycle (issue 20).
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from eyeviz import EyevizError
from eyeviz.core.bounds import MAX_DATA_PHI, MAX_DATA_R

__all__ = [
    "COMMA",
    "FORMATS",
    "NEWLINE",
    "NPZ_VERSION",
    "ONE",
    "ZERO",
    "check_floats",
    "check_rows",
    "format_of",
    "npz_dtype",
]

FORMATS = ("csv", "npz")
NPZ_VERSION = 1
#: ASCII codes of a CSV row: the bits ``0`` / ``1``, the separator, the line end.
ZERO, ONE, COMMA, NEWLINE = 48, 49, 44, 10


def format_of(path: str | os.PathLike) -> str:
    """``"csv"`` or ``"npz"`` from the file name's suffix."""
    suffix = Path(path).suffix.lower().lstrip(".")
    if suffix not in FORMATS:
        raise EyevizError(f"output must end in .csv or .npz, got {str(path)!r}")
    return suffix


def npz_dtype(m: int) -> np.dtype:
    """One NPZ row: the packed bitmaps of both eyes (m/2 bits each), then r, phi, g."""
    nb = (m // 2 + 7) // 8
    return np.dtype(
        [
            ("omega_a", np.uint8, (nb,)),
            ("omega_b", np.uint8, (nb,)),
            ("r", "<f8"),
            ("phi", "<f8"),
            ("g", "<f8"),
        ]
    )


def check_floats(path: Path, start: int, r, phi, g, unit: str) -> None:
    """0 <= r <= MAX_DATA_R, |phi| <= MAX_DATA_PHI, 0 <= g <= MAX_DATA_R (or g NaN: a CSV
    without g). Beyond these no bitmap can describe the row, and sums of squares of r
    overflow in the metrics (r = 1e308). ``unit`` ("line", "row") names the first bad one,
    counted from ``start + 1``."""
    R = MAX_DATA_R
    with np.errstate(invalid="ignore"):
        ok_g = ((g >= 0) & (g <= R)) | np.isnan(g)
        bad = ~((r >= 0) & (r <= R) & (np.abs(phi) <= MAX_DATA_PHI) & ok_g)
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise EyevizError(
            f"{path}: {unit} {start + i + 1}: r, phi, g = {float(r[i])!r}, {float(phi[i])!r}, "
            f"{float(g[i])!r} "
            f"(need 0 <= r <= {R:g}, |phi| <= {MAX_DATA_PHI:g} rad, 0 <= g <= {R:g})"
        )


def check_rows(omega_a, omega_b, r, phi, g, m: int) -> None:
    """What a writer refuses to write: anything the reader would refuse."""
    w = m // 2
    n = np.shape(r)[0] if np.ndim(r) else -1
    for name, a in (("omega_a", omega_a), ("omega_b", omega_b)):
        a = np.asarray(a)
        if a.ndim != 2 or a.shape != (n, w):
            raise EyevizError(f"{name} must have shape ({n}, {w}), got {a.shape}")
        if a.dtype != bool:
            bad = (a != 0) & (a != 1)
            if bad.any():
                i, j = (int(v[0]) for v in np.nonzero(bad))
                raise EyevizError(f"{name} row {i + 1}, bit {j}: {a[i, j].item()!r} is not 0 or 1")
    for name, a in (("phi", phi), ("g", g)):
        if np.shape(a) != (n,):
            raise EyevizError(f"{name} must have shape ({n},), got {np.shape(a)}")
    r, phi, g = (np.asarray(a, dtype=np.float64) for a in (r, phi, g))
    fin = np.isfinite(g)
    if n and not (fin.all() or np.isnan(g).all()):
        i = int(np.flatnonzero(~fin)[0])
        raise EyevizError(
            f"row {i + 1}: g = {float(g[i])!r} (g must be finite, or NaN in every row)"
        )
    check_floats(Path("data set"), 0, r, phi, g, "row")
