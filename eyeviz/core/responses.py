"""Graded responses of every eye model, on its lit sets (docs/responses.md).

``responses`` of each model class delegates here. Per eye it returns a CSR triple
(indptr, indices, values) over the flattened balls: indptr and indices are the model's
lit sets (``lit_csr``; for the planar ring, its intervals), values float64 in [0, 1], the
response of each lit facet. Which kinds apply:

* planar ring (:class:`eyeviz.core.geometry.EyePair`) and HEALPix
  (:class:`eyeviz.core.geometry3d.EyePair3D`): ``cell``, the share of the facet's cell
  (a sector's angle, a HEALPix cell's area) that the feature covers, seen from the eye
  centre; the cell is the facet's acceptance, so ``flat`` and ``gaussian`` are refused;
* measured (:class:`eyeviz.core.measured.MeasuredEyePair`): ``flat`` and ``gaussian``
  (:mod:`eyeviz.core.responses_caps`, from the lens); a measured eye has no cells.
"""

from __future__ import annotations

import math

import numpy as np

from eyeviz import EyevizError
from eyeviz.core.responses_balls import ball_cap
from eyeviz.core.responses_caps import flat_response, gaussian_response

__all__ = [
    "KINDS_BY_MODEL",
    "check_kind",
    "healpix_values",
    "measured_values",
    "planar_responses",
]

#: The kinds each model answers, its default first.
KINDS_BY_MODEL: dict[str, tuple[str, ...]] = {
    "planar": ("cell",),
    "spherical": ("cell",),
    "measured": ("flat", "gaussian"),
}

CSR3 = tuple[np.ndarray, np.ndarray, np.ndarray]


def check_kind(model: str, kind: str | None) -> str:
    """The kind to use (the model's default for None); EyevizError naming the kinds the
    model answers otherwise."""
    kinds = KINDS_BY_MODEL[model]
    if kind is None and kinds:
        return kinds[0]
    if kind not in kinds:
        raise EyevizError(
            f"{model} eyes answer responses of kind {' or '.join(map(repr, kinds))}, not {kind!r}"
        )
    return kind


def _rows(indptr: np.ndarray) -> np.ndarray:
    """The ball (row) of each CSR entry."""
    return np.repeat(np.arange(indptr.size - 1, dtype=np.int64), np.diff(indptr))


def measured_values(
    positions: np.ndarray,
    unit_axes: np.ndarray,
    acceptance: np.ndarray,
    balls: tuple[np.ndarray, ...],
    indptr: np.ndarray,
    indices: np.ndarray,
    kind: str,
    support: str = "cone",
) -> np.ndarray:
    """The responses of one measured eye's lit (ball, facet) pairs: the ball's cap seen
    from the lens (:func:`ball_cap`), its angle theta from the axis (atan2 of |v x a| and
    v . a) and the acceptance cap of half-angle dr / 2."""
    bi = _rows(indptr)
    fi = indices
    cx, cy, cz, g = (v[bi] for v in balls)
    p = positions[fi]
    v, b = ball_cap((cx, cy, cz), (p[:, 0], p[:, 1], p[:, 2]), g)
    ax = unit_axes[fi]
    # v scaled by its largest component: no overflow or underflow in the products
    with np.errstate(divide="ignore", invalid="ignore"):
        big = np.maximum.reduce([np.abs(c) for c in v])
        vs = [np.where(big > 0, c / np.where(big > 0, big, 1.0), 0.0) for c in v]
    crx = vs[1] * ax[:, 2] - vs[2] * ax[:, 1]
    cry = vs[2] * ax[:, 0] - vs[0] * ax[:, 2]
    crz = vs[0] * ax[:, 1] - vs[1] * ax[:, 0]
    dot = vs[0] * ax[:, 0] + vs[1] * ax[:, 1] + vs[2] * ax[:, 2]
    theta = np.arctan2(np.sqrt(crx * crx + cry * cry + crz * crz), dot)
    a = acceptance[fi] / 2
    if kind == "flat":
        return flat_response(a, b, theta)
    return gaussian_response(a, b, theta, support)


def healpix_values(
    nside: int,
    cx: float,
    balls: tuple[np.ndarray, ...],
    indptr: np.ndarray,
    indices: np.ndarray,
) -> np.ndarray:
    """The ``cell`` responses of one HEALPix eye (centre (cx, 0, 0)): each lit cell's
    share of its area inside the ball's cap of directions from the centre
    (:func:`eyeviz.core.responses_cells.cell_fraction`)."""
    from eyeviz.core.responses_cells import cell_fraction

    bi = _rows(indptr)
    x, y, z, g = (v[bi] for v in balls)
    v, b = ball_cap((x, y, z), (np.full(x.size, cx), np.zeros(x.size), np.zeros(x.size)), g)
    theta_c = np.arctan2(np.hypot(v[0], v[1]), v[2])
    phi_c = np.mod(np.arctan2(v[1], v[0]), 2 * math.pi)
    return cell_fraction(nside, indices, theta_c, phi_c, b)


def planar_responses(eyes, xf: np.ndarray, yf: np.ndarray, gf: np.ndarray) -> tuple[CSR3, CSR3]:
    """``cell`` responses of the planar ring (flat, validated float64 features): sector
    k = [k gamma, (k + 1) gamma) of an eye holds the share of its angle inside
    [phi - beta, phi + beta], the directions of the disc seen from the eye centre
    (beta = pi when the centre is inside the disc)."""
    la, ra, lb, rb = (v.reshape(-1) for v in eyes.intervals(xf, yf, gf))
    m = eyes.m
    k = m / (2 * math.pi)
    out = []
    for cx, lo_i, hi_i in ((-eyes.h, la, ra), (eyes.h, lb, rb)):
        counts = hi_i - lo_i + 1
        indptr = np.zeros(counts.size + 1, np.int64)
        np.cumsum(counts, out=indptr[1:])
        bi = _rows(indptr)
        j = lo_i[bi] + (np.arange(indptr[-1]) - indptr[:-1][bi])  # unwrapped sector
        v, beta = ball_cap((xf, yf), (np.full(xf.size, cx), np.zeros(xf.size)), gf)
        phi = np.arctan2(v[1], v[0])
        t_lo = (phi - beta) * k
        t_hi = (phi + beta) * k
        # shift the interval next to sector L (it may have been found at -m)
        shift = m * np.round((t_lo - lo_i) / m)
        t_lo, t_hi = t_lo - shift, t_hi - shift
        vals = np.zeros(j.size)
        tl, th = t_lo[bi], t_hi[bi]
        for s in (-m, 0, m):
            vals += np.clip(np.minimum(th + s, j + 1) - np.maximum(tl + s, j), 0.0, 1.0)
        vals[beta[bi] >= math.pi] = 1.0
        order = np.lexsort((j % m, bi))
        out.append((indptr, (j % m)[order].astype(np.int64), np.clip(vals[order], 0.0, 1.0)))
    return out[0], out[1]
