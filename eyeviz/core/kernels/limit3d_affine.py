"""The HEALPix proposal's set-up compiled (numba): the linearisation of each edge cell's
distance about a key's centre (:meth:`eyeviz.estimators.limit3d_proposal._Eye.linearise`,
called at every zoom level of the centre search) and the affine forms of the model built
from it (``_Eye._affine``, bit for bit), and the edge cells' boundary samples
(``healpix.boundaries``, to a few ulps).

The linearisation and the boundaries are not bit for bit the numpy reference's
(``EYEVIZ_JIT=0``): numpy's einsum sums its three products in an order of its own, and its
arctan2, sin and cos are not ``math``'s to the last bit. The kernels compute the same
formulas and agree with the reference to a few ulps
(tests/core/test_kernels_limit3d_affine.py). Only where draws are proposed depends on these
numbers (each draw's weight uses the proposal it was drawn from); every draw is still
checked exactly.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

__all__ = ["linearise_kernel", "affine_kernel", "boundaries_kernel", "warm"]

_jit = njit(cache=True, nogil=True)


# long: the nearest sample, its distance and its tangent are one pass over a cell's samples
@_jit
def linearise_kernel(pts, lit, pad, c, e1, e2, s, d, t):
    """_Eye.linearise on the live slots (``pad`` False) of pts (N, K, P, 3) about the unit
    centres c (N, 3) with frames e1, e2 (N, 3): d (N, K) the distance to the nearest
    boundary sample (lit cells: less the sample gap for spacing s, as
    limit3d_proposal._sample_gap), t (N, K, 2) the unit tangent towards it in (e1, e2)
    (0 where the sample is the centre itself). Padding slots get d = 0 and t = 0."""
    q = 0.25 * s * s
    for n in range(pts.shape[0]):
        c0, c1, c2 = c[n, 0], c[n, 1], c[n, 2]
        for k in range(pts.shape[1]):
            if pad[n, k]:
                d[n, k] = 0.0
                t[n, k, 0] = 0.0
                t[n, k, 1] = 0.0
                continue
            best = 0
            bd = -np.inf
            for p in range(pts.shape[2]):
                v = pts[n, k, p, 0] * c0 + pts[n, k, p, 1] * c1 + pts[n, k, p, 2] * c2
                if v > bd:
                    bd = v
                    best = p
            px, py, pz = pts[n, k, best, 0], pts[n, k, best, 1], pts[n, k, best, 2]
            cp = px * c0 + py * c1 + pz * c2
            tx, ty, tz = px - cp * c0, py - cp * c1, pz - cp * c2
            tn = math.sqrt(tx * tx + ty * ty + tz * tz)
            dd = math.atan2(tn, cp)
            if lit[n, k]:
                lo = math.sqrt(max(dd * dd - q, 0.0))
                dd = dd - 1.5 * (math.sqrt(lo * lo + q) - lo)
            d[n, k] = dd
            if tn > 0.0:
                t[n, k, 0] = (tx * e1[n, 0] + ty * e1[n, 1] + tz * e1[n, 2]) / tn
                t[n, k, 1] = (tx * e2[n, 0] + ty * e2[n, 1] + tz * e2[n, 2]) / tn
            else:
                t[n, k, 0] = 0.0
                t[n, k, 1] = 0.0


@_jit
def affine_kernel(d, t, lit, pad, a_lit, t_lit, a_unl, t_unl, l_a, l_t, nl, u_a, u_t, nu):
    """_Eye._affine: the affine forms of the model from d (N, K), t (N, K, 2): a_lit,
    t_lit (lit live cells: d and t; else -inf and 0), a_unl, t_unl (unlit live cells: d d
    and 2 d t; else +inf and 0), and the same forms of each kind alone, in slot order
    (l_a, l_t, nl for the lit cells, u_a, u_t, nu for the unlit ones; beyond a row's
    count the slots are left as they were). The same operations as numpy's, elementwise:
    the reference's bits."""
    for n in range(d.shape[0]):
        il = 0
        iu = 0
        for k in range(d.shape[1]):
            dk = d[n, k]
            live = not pad[n, k]
            if live and lit[n, k]:
                a_lit[n, k] = dk
                t_lit[n, k, 0] = t[n, k, 0]
                t_lit[n, k, 1] = t[n, k, 1]
                l_a[n, il] = dk
                l_t[n, il, 0] = t[n, k, 0]
                l_t[n, il, 1] = t[n, k, 1]
                il += 1
            else:
                a_lit[n, k] = -np.inf
                t_lit[n, k, 0] = 0.0
                t_lit[n, k, 1] = 0.0
            if live and not lit[n, k]:
                a_unl[n, k] = dk * dk
                t_unl[n, k, 0] = 2.0 * dk * t[n, k, 0]
                t_unl[n, k, 1] = 2.0 * dk * t[n, k, 1]
                u_a[n, iu] = a_unl[n, k]
                u_t[n, iu, 0] = t_unl[n, k, 0]
                u_t[n, iu, 1] = t_unl[n, k, 1]
                iu += 1
            else:
                a_unl[n, k] = np.inf
                t_unl[n, k, 0] = 0.0
                t_unl[n, k, 1] = 0.0
        nl[n] = il
        nu[n] = iu


@_jit
def boundaries_kernel(nside, ix, iy, face, rows, slot, dx, dy, jrll, jpll, out):
    """healpix.boundaries of the cells (ix, iy, face) (T,) at the face offsets dx, dy (P,),
    written to out[rows[i], slot[i]] (out (N, K, P, 3)): healpix.xyf2vec's formulas point
    by point (``math``'s sin and cos, which may differ from numpy's in the last bit)."""
    n = float(nside)
    for i in range(ix.size):
        f = face[i]
        for p in range(dx.size):
            fx = (ix[i] + dx[p]) / n
            fy = (iy[i] + dy[p]) / n
            jr = jrll[f] - fx - fy
            if jr < 1:
                nr = jr
                z = 1.0 - jr * jr / 3.0
            elif jr > 3:
                nr = 4.0 - jr
                z = (4.0 - jr) ** 2 / 3.0 - 1.0
            else:
                nr = 1.0
                z = (2.0 - jr) * (2.0 / 3.0)
            if jr < 1 or jr > 3:
                sth = nr * math.sqrt(max(2.0 - nr * nr / 3.0, 0.0) / 3.0)
            else:
                sth = math.sqrt(1.0 - z * z)
            phi = 0.0
            if nr > 0:
                phi = (0.25 * math.pi) * (jpll[f] * nr + fx - fy) / nr
            o = out[rows[i], slot[i], p]
            o[0] = sth * math.cos(phi)
            o[1] = sth * math.sin(phi)
            o[2] = z


def warm() -> None:
    """Compile (or load from the cache) the kernels for their one signature each."""
    pts = np.ones((1, 1, 2, 3))
    b = np.zeros((1, 1), np.bool_)
    c = np.ones((1, 3))
    d, t = np.empty((1, 1)), np.empty((1, 1, 2))
    linearise_kernel(pts, b, b.copy(), c, c, c, 0.01, d, t)
    n1 = np.zeros(1, np.int64)
    f12 = np.zeros(12, np.int64)
    boundaries_kernel(2, n1, n1, n1, n1, n1, np.zeros(2), np.zeros(2), f12, f12, pts)
    affine_kernel(d, t, b, b.copy(), d.copy(), t.copy(), d.copy(), t.copy(), d.copy(), t.copy(),
                  n1, d.copy(), t.copy(), n1.copy())  # fmt: skip
