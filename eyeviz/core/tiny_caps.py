"""Lit sets of caps far below a facet, at a bounded cost (docs/spherical.md, "Tiny caps").

A cap whose angular radius is within 1e6 rounding errors of its centre's direction cannot
be placed by the float64 fast path (:mod:`eyeviz.core.geometry3d`): its own cell is not
certain, and every candidate cell would go to :mod:`eyeviz.core.exact3d` at a precision
that grows with log2(|d| / g) (minutes for g = 1e-300). Lit sets are monotone in the
radius (closed caps about one centre are nested), so such a cap's lit set lies inside the
lit set of the concentric cap of radius ``_GROW`` rounding errors, which the fast path
decides exactly. When that larger cap lights one cell, the tiny cap lights that cell and
nothing else (every cap lights the cell its centre maps to). Otherwise the tiny cap's
centre lies near a cell boundary and only the larger cap's cells go to the exact test,
whose precision :func:`eyeviz.core.exact3d.cell_lit` bounds for caps far below a facet.
"""

from __future__ import annotations

from collections.abc import Callable
from fractions import Fraction

import numpy as np

from eyeviz.core import exact3d, healpix

__all__ = ["tiny_mask", "tiny_lit_runs", "run_balls"]

_EPS = 2.0**-52
_TINY = 2e6  # a cap below _TINY rounding errors of its direction takes this path
_GROW = 1e8  # the larger cap: _GROW rounding errors (the fast path places its centre)
_MAX_CELLS = 64  # above this many cells the larger cap is not far below a facet

Runs = tuple[np.ndarray, np.ndarray, np.ndarray]


def _direction_error(x, y, z, g, cx: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(q = g / |d|, |d|, the relative error bound of the float direction), as the fast
    path computes them (two-sum of x - cx, then 8 eps + 4 |err| / |d|)."""
    with np.errstate(over="ignore", under="ignore", invalid="ignore", divide="ignore"):
        dx0 = x - cx
        bv = dx0 - x
        err = (x - (dx0 - bv)) + (-cx - bv)
        big = np.maximum(np.maximum(np.abs(dx0), np.abs(y)), np.maximum(np.abs(z), g))
        ex = np.frexp(big)[1]
        dx, dy, dz, gs = (np.ldexp(v, -ex) for v in (dx0, y, z, g))
        errabs = np.ldexp(np.abs(err) + 2.0**-1070, -ex)
        d = np.sqrt(dx * dx + dy * dy + dz * dz)
        return gs / d, np.ldexp(d, ex), 8 * _EPS + 4 * errabs / d


def tiny_mask(x, y, z, g, cx: float) -> np.ndarray:
    """The balls whose cap is far below the float direction's error (q < 2e6 errors)."""
    q, _, errdir = _direction_error(x, y, z, g, cx)
    return np.asarray((q < _TINY * errdir) & (q < 1e-3))


def run_balls(per_ball: np.ndarray, ln: np.ndarray) -> np.ndarray:
    """The ball of each run, from the runs (sorted by ball) and the facets per ball."""
    return np.searchsorted(np.cumsum(per_ball), np.cumsum(ln) - ln, side="right")


def tiny_lit_runs(n: int, x, y, z, g, cx: float, fast: Callable[..., Runs]) -> Runs:
    """Runs (per ball, starts, lengths) of the tiny balls' lit sets; ``fast`` is the fast
    path for ordinary caps (geometry3d's, called on the larger concentric caps)."""
    _, dist, errdir = _direction_error(x, y, z, g, cx)
    g_big = np.maximum(_GROW * errdir * dist, g)
    per, st, ln = fast(n, x, y, z, g_big, cx)
    nb = x.shape[0]
    starts: list[int] = []
    balls: list[int] = []
    slow = []
    cut = np.searchsorted(run_balls(per, ln), np.arange(nb + 1))
    for b in range(nb):
        sel = slice(cut[b], cut[b + 1])
        cells = np.concatenate(
            [np.arange(s, s + k) for s, k in zip(st[sel], ln[sel], strict=True)]
            + [np.zeros(0, np.int64)]
        )
        if cells.size == 1:
            starts.append(int(cells[0]))
            balls.append(b)
        elif cells.size > _MAX_CELLS:
            slow.append(b)
        else:
            ix, iy, face = healpix.pix2xyf(n, cells)
            X = Fraction(float(x[b])) - Fraction(cx)
            Y, Z, G = Fraction(float(y[b])), Fraction(float(z[b])), Fraction(float(g[b]))
            for p, fx, fy, f in zip(
                cells.tolist(), ix.tolist(), iy.tolist(), face.tolist(), strict=True
            ):
                if exact3d.cell_lit(n, X, Y, Z, G, int(f), int(fx), int(fy), int(p)):
                    starts.append(p)
                    balls.append(b)
    st_t = np.array(starts, np.int64)
    bl_t = np.array(balls, np.int64)
    ln_t = np.ones(st_t.size, np.int64)
    if slow:
        sl = np.array(slow, np.int64)
        p2, s2, l2 = fast(n, x[sl], y[sl], z[sl], g[sl], cx)
        st_t = np.concatenate([st_t, s2])
        ln_t = np.concatenate([ln_t, l2])
        bl_t = np.concatenate([bl_t, sl[run_balls(p2, l2)]])
    order = np.lexsort((st_t, bl_t))
    st_t, ln_t, bl_t = st_t[order], ln_t[order], bl_t[order]
    return np.bincount(bl_t, weights=ln_t, minlength=nb).astype(np.int64), st_t, ln_t
