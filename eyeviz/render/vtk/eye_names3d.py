"""The close-up's eye names (eyeviz.render.vtk.scene3d): where a name reads as its own
eye's, and names centred under their eyes where no free place is near them."""

from __future__ import annotations

import numpy as np

from eyeviz.model.labels3d import _covers as covers
from eyeviz.model.labels3d import gap_for

__all__ = ["EYE_NAMES", "SHORT_NAMES", "misplaced", "names_under", "over_discs", "unclear"]

EYE_NAMES = ("eye A", "eye B")  # as eyeviz.render.vtk.eyes3d names them
SHORT_NAMES = ("A", "B")  # where the whole names read as neither eye's
UNCLEAR = 0.75  # a name's middle farther than this times its distance to another eye


def over_discs(boxes: np.ndarray, at: np.ndarray, rad: np.ndarray) -> bool:
    """Whether a box (rows of ``boxes``: x0, y0, x1, y1) reaches into a disc (centres
    ``at``, radii ``rad``, pixels)."""
    for x0, y0, x1, y1 in np.asarray(boxes, float).reshape(-1, 4):
        near = np.column_stack([np.clip(at[:, 0], x0, x1), np.clip(at[:, 1], y0, y1)])
        if (np.linalg.norm(near - at, axis=1) < rad).any():
            return True
    return False


def _middle_distances(boxes: np.ndarray, at: np.ndarray):
    """(d, centres): d[k, j] the distance from the middle of name box k to disc centre j,
    over the rows where both are finite; None when fewer than two are."""
    ok = np.isfinite(boxes).all(axis=1) & np.isfinite(at).all(axis=1)
    if ok.sum() < 2:
        return None
    b, a = boxes[ok], at[ok]
    mid = np.column_stack([b[:, 0] + b[:, 2], b[:, 1] + b[:, 3]]) / 2
    return np.linalg.norm(mid[:, None, :] - a[None, :, :], axis=2), a


def unclear(boxes: np.ndarray, at: np.ndarray) -> bool:
    """Whether a name's box (row k of ``boxes``) has its middle not clearly nearer its
    own disc's centre (row k of ``at``) than another's: over UNCLEAR times the distance to
    the nearest other."""
    found = _middle_distances(boxes, at)
    if found is None:
        return False
    d, _ = found
    own = np.diag(d).copy()
    np.fill_diagonal(d, np.inf)
    return bool((own > UNCLEAR * d.min(axis=1)).any())


def misplaced(boxes: np.ndarray, at: np.ndarray) -> bool:
    """Whether a name's box (row k of ``boxes``) has its middle clearly nearer another
    disc's centre (rows of ``at``, the same order) than its own: by over a fifth of the
    two centres' distance (discs seen one behind the other, as from the side, tell their
    names apart by nothing)."""
    found = _middle_distances(boxes, at)
    if found is None:
        return False
    d, a = found
    k = np.arange(len(a))
    j = d.argmin(axis=1)
    apart = np.linalg.norm(a[k] - a[j], axis=1)
    return bool(((j != k) & (d[k, k] - d[k, j] > 0.2 * apart)).any())


def names_under(
    at: np.ndarray, rad: np.ndarray, sizes: np.ndarray, width: float, height: float = np.inf
) -> np.ndarray:
    """Boxes (as :func:`eyeviz.model.labels3d.place_boxes`') of names centred under their
    discs (``at``, ``rad``), moved sideways into [2, width - 2] px where they would leave
    it; where two of them cross, the name of the higher disc goes over it instead (the
    close-up at F11 + F5 + 175 % in 1280 x 720, step 8: a 305 x 234 px pane, the two
    names under their eyes crossed), if it fits under ``height``."""
    w, h = np.asarray(sizes, float).T
    x0 = np.clip(at[:, 0] - w / 2, 2.0, np.maximum(width - 2.0 - w, 2.0))
    gap = np.array([gap_for(v) for v in h])
    y1 = at[:, 1] - rad - gap
    out = np.column_stack([x0, y1 - h, x0 + w, y1])
    for i in range(len(out)):
        for j in range(i + 1, len(out)):
            if not covers(out[i : i + 1], out[j : j + 1]):
                continue
            k = i if at[i, 1] > at[j, 1] else j  # the higher disc's name over it
            y0 = at[k, 1] + rad[k] + gap[k]
            if y0 + h[k] <= height - 2.0:
                out[k, 1], out[k, 3] = y0, y0 + h[k]
    return out
