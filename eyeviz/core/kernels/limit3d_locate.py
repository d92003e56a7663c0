"""The HEALPix proposal's centre search compiled (numba): :func:`eyeviz.estimators.
limit3d_proposal._locate`, its zooming grids, the move of each key's centre to the grid's
best point and the model linearised there, as one kernel per eye and chunk of keys
instead of four rounds of numpy calls (docs/limit3d.md, "Fewer calls").

It calls :mod:`.limit3d_affine`'s kernels (the model's evaluation, the linearisation and
the affine forms), so its numba cache is stamped with that module's source as well
(:func:`.healpix_boundary.stamp_with`). The centre, its frame and the model are the
numpy reference's (``EYEVIZ_JIT=0``) formulas in the same order: the same values
(tests/core/test_kernels_limit3d_affine.py compares them).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from eyeviz.core.kernels import limit3d_affine
from eyeviz.core.kernels.healpix_boundary import stamp_with
from eyeviz.core.kernels.limit3d_affine import (
    _affine_lists,
    _affine_points,
    affine_kernel,
    linearise_kernel,
)

# before the first kernel: its cache carries the source of the module it calls as well
stamp_with(__file__, limit3d_affine.__file__)

__all__ = ["locate_kernel", "warm"]


# long: a level's grid, its best point, the new centre and frame, then the model again
@njit(cache=True, nogil=True)
def locate_kernel(pts, lit, pad, s, g0, half, levels, c, e1, e2, d, t, a_lit, t_lit, a_unl,
                  t_unl, lists, vals):  # fmt: skip
    """``levels`` times: each key's model G = min_unlit - max_lit on the grid g0 (G, 2)
    times ``half`` about its centre, the centre moved to the best point (numpy's argmax:
    the first maximum, a NaN before any number) as _Eye.direction then _Eye.linearise
    normalise it, its frame as limit3d_eye._frame, the model linearised there
    (linearise_kernel, affine_kernel), and the grid a third as wide. c, e1, e2 (N, 3), d,
    t and the affine forms and lists are updated in place (their counts do not change:
    the cells stay). vals (G,): work."""
    ng = g0.shape[0]
    gx, gy, lo_, hi_ = np.empty(ng), np.empty(ng), np.empty(ng), np.empty(ng)
    for _ in range(levels):
        for n in range(c.shape[0]):
            if math.isfinite(half):  # the grid's points at once (the same bits)
                for j in range(ng):
                    gx[j] = g0[j, 0] * half
                    gy[j] = g0[j, 1] * half
                _affine_points(lists, n, gx, gy, ng, lo_, hi_)
                for j in range(ng):
                    vals[j] = hi_[j] - lo_[j]
            else:
                for j in range(ng):
                    lo, hi = _affine_lists(a_lit, t_lit, a_unl, t_unl, lists, n,
                                           g0[j, 0] * half, g0[j, 1] * half)  # fmt: skip
                    vals[j] = hi - lo
            best = 0
            for j in range(ng):
                vb = vals[best]
                if vb == vb and (vals[j] != vals[j] or vals[j] > vb):
                    best = j
            dx, dy = g0[best, 0] * half, g0[best, 1] * half
            vx = c[n, 0] + dx * e1[n, 0] + dy * e2[n, 0]
            vy = c[n, 1] + dx * e1[n, 1] + dy * e2[n, 1]
            vz = c[n, 2] + dx * e1[n, 2] + dy * e2[n, 2]
            nv = math.sqrt(vx * vx + vy * vy + vz * vz)
            vx, vy, vz = vx / nv, vy / nv, vz / nv
            nv = math.sqrt(vx * vx + vy * vy + vz * vz)  # linearise's own normalisation
            cx, cy, cz = vx / nv, vy / nv, vz / nv
            ex, ey = -cy, cx
            n1 = math.sqrt(ex * ex + ey * ey + 0.0)
            if n1 > 1e-12:
                n1 = max(n1, 1e-300)
                ex, ey, ez = ex / n1, ey / n1, 0.0 / n1
            else:
                ex, ey, ez = 1.0, 0.0, 0.0
            c[n, 0], c[n, 1], c[n, 2] = cx, cy, cz
            e1[n, 0], e1[n, 1], e1[n, 2] = ex, ey, ez
            e2[n, 0] = cy * ez - cz * ey
            e2[n, 1] = cz * ex - cx * ez
            e2[n, 2] = cx * ey - cy * ex
        linearise_kernel(pts, lit, pad, c, e1, e2, s, d, t)
        l_a, l_t, nl, u_a, u_t, nu = lists
        affine_kernel(d, t, lit, pad, a_lit, t_lit, a_unl, t_unl, l_a, l_t, nl, u_a, u_t, nu)
        half = half / 3.0


def warm() -> None:
    """Compile (or load from the cache) the kernel for its one signature."""
    pts = np.ones((1, 1, 2, 3))
    b = np.zeros((1, 1), np.bool_)
    c = np.array([[0.0, 0.6, 0.8]])
    d, t = np.zeros((1, 1)), np.zeros((1, 1, 2))
    n1 = np.ones(1, np.int64)
    lists = (d.copy(), t.copy(), n1, d.copy(), t.copy(), n1.copy())
    locate_kernel(pts, b, b.copy(), 0.01, np.zeros((4, 2)), 0.1, 2, c, c.copy(), c.copy(), d, t,
                  d.copy(), t.copy(), d.copy(), t.copy(), lists, np.empty(4))  # fmt: skip
