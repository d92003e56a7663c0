"""The measured proposal's region test compiled (numba): H >= -slack at points (delta,
beta) of the box search and the pilot (:meth:`eyeviz.estimators.limit3d_measured.
MeasuredProposal._hb`), the centre and the walk over both eyes' facets in one loop, the
facet that rules a point out moved to the front (as the draws' walk,
:func:`eyeviz.core.kernels.limit3d_region._walk`).

It calls :mod:`.limit3d_region`'s functions (``bcentre``, ``_cone_fold``), so its numba
cache is stamped with that module's source as well as its own (:class:`_WithRegionSource`,
as healpix_match does for healpix_lit): an edit of either recompiles it."""

from __future__ import annotations

import hashlib
import math
import os

import numpy as np
from numba.core import caching

from eyeviz.core.kernels import limit3d_region
from eyeviz.core.kernels.limit3d_region import _cone_fold, _jit_np, bcentre

__all__ = ["region_kernel", "warm"]


class _WithRegionSource(caching.InTreeCacheLocator):
    """numba's in-tree cache for this module's kernels, its source stamp that of this file
    and of limit3d_region.py together (numba checks only the caller's file)."""

    @classmethod
    def from_function(cls, py_func, py_file):
        if os.path.abspath(py_file) != os.path.abspath(__file__):
            return None
        return super().from_function(py_func, py_file)

    def get_source_stamp(self):
        digest = hashlib.sha256()
        for path in (self._py_file, limit3d_region.__file__):
            with open(path, "rb") as f:
                digest.update(f.read())
        return digest.hexdigest()


_LOCATORS = caching.CacheImpl._locator_classes
if _WithRegionSource not in _LOCATORS:
    _LOCATORS.insert(0, _WithRegionSource)


@_jit_np
def _walk_slack(pos_a, ax_a, ch_a, sh_a, lit_a, pad_a, pos_b, ax_b, ch_b, sh_b, lit_b, pad_b,
                order, n, cx, cy, cz, lo_, hi_, slack):  # fmt: skip
    """limit3d_region._walk with the region test's stop, H = hi - lo < -slack (or NaN):
    both eyes' facets in the key's order ``order[n]``, the facet that stops a point moved
    to the front. Returns (lo, hi): the whole walk's where it does not stop, else the
    partial ones (then H < -slack all the same: lo only grows, hi only shrinks)."""
    ka = pos_a.shape[1]
    if not (hi_ - lo_ >= -slack):
        return lo_, hi_
    for p in range(order.shape[1]):
        k = order[n, p]
        if k < ka:
            if pad_a[n, k]:
                continue
            lo_, hi_ = _cone_fold(pos_a, ax_a, ch_a, sh_a, lit_a, n, k, cx, cy, cz, lo_, hi_)
        else:
            if pad_b[n, k - ka]:
                continue
            lo_, hi_ = _cone_fold(pos_b, ax_b, ch_b, sh_b, lit_b, n, k - ka, cx, cy, cz,
                                  lo_, hi_)  # fmt: skip
        if not (hi_ - lo_ >= -slack):
            for j in range(p, 0, -1):
                order[n, j] = order[n, j - 1]
            order[n, 0] = k
            return lo_, hi_
    return lo_, hi_


@_jit_np
def region_kernel(x, u0, e1, e2, fa, bhat, blen, origin, s_half, g_max, slack,
                  pos_a, ax_a, ch_a, sh_a, lit_a, pad_a, pos_b, ax_b, ch_b, sh_b, lit_b, pad_b,
                  h):  # fmt: skip
    """MeasuredProposal._hb: H (N, G) at the points x (N, G, 3) = (delta_1, delta_2, beta)
    of each key: the centre (``bcentre``; -inf where the rays do not meet in front), then
    g_hi - g_lo over the prior's g range and both eyes' constraining facets, the walk
    stopped once H < -slack (H then some value below -slack)."""
    order = np.empty((x.shape[0], pos_a.shape[1] + pos_b.shape[1]), np.int64)
    for n in range(x.shape[0]):
        for k in range(order.shape[1]):
            order[n, k] = k
        for g in range(x.shape[1]):
            cx, cy, cz, rho, _ = bcentre(u0[n], e1[n], e2[n], x[n, g, 0], x[n, g, 1],
                                         x[n, g, 2], fa, bhat, blen)  # fmt: skip
            if not math.isfinite(rho):
                h[n, g] = -np.inf
                continue
            qx, qy, qz = cx - origin[0], cy - origin[1], cz - origin[2]
            rr = math.sqrt(qx * qx + qy * qy + qz * qz)
            lo_, hi_ = _walk_slack(pos_a, ax_a, ch_a, sh_a, lit_a, pad_a, pos_b, ax_b, ch_b,
                                   sh_b, lit_b, pad_b, order, n, cx, cy, cz, rr * s_half,
                                   min(rr, g_max), slack)  # fmt: skip
            hv = hi_ - lo_
            h[n, g] = hv if math.isfinite(hv) else -np.inf


def warm() -> None:
    """Compile (or load from the cache) the kernel for its one signature."""
    a2 = np.zeros((1, 1))
    p3 = np.ones((1, 1, 3))
    b = np.ones((1, 1), np.bool_)
    cs = (p3, p3, a2 + 0.9, a2 + 0.1, b, ~b)
    c = np.ones((1, 3))
    v3 = np.ones(3)
    region_kernel(p3, c, c, c, v3, v3, 1.0, v3, 0.1, 1.0, 1e-7, *cs, *cs, a2.copy())
