"""Each eye's constraining facets of a chunk of keys of a measured pair, as the measured
proposal of the spherical limit reads them (:mod:`.limit3d_measured`, steps 1 and 3):
the facets' tables per eye, the key's lit facets and the unlit ones near them padded to
(N, K), their cone distances, and each eye's best direction at infinity."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from eyeviz.core import kernels
from eyeviz.estimators.base import LitCSR
from eyeviz.estimators.limit3d_exact import exact_hits
from eyeviz.estimators.limit3d_proposal import _frame
from eyeviz.estimators.triangulation import facet_neighbours

__all__ = ["RINGS", "both_columns", "key_hits", "_Edges", "_Facets", "_direction", "_facets"]


#: rings of axis neighbours of the lit facets whose unlit facets constrain
RINGS = 2
#: _Edges' constraining facets found by one compiled call (the same facets in the same
#: order as the numpy sets' way, which the tests compare with it)
EDGES_KERNEL = True


class _Facets:
    """One eye's facets as the proposal reads them: lens positions, unit axes, half
    acceptance angles and each facet's axis neighbours."""

    def __init__(self, eyes, which: str) -> None:
        pos, axes, acc = eyes.facets(which)
        self.pos = np.asarray(pos, np.float64)
        self.ax = np.asarray(eyes.eye(which).unit_axes, np.float64)
        self.half = np.asarray(acc, np.float64) / 2
        self.nb = facet_neighbours(np.asarray(axes, np.float64))
        self.centre = np.asarray(eyes.eye(which).centroid, np.float64)
        self.ax_cols = tuple(np.ascontiguousarray(self.ax[:, j]) for j in range(3))


_FACETS: dict[tuple[str, str], _Facets] = {}


def _facets(eyes, which: str) -> _Facets:
    key = (str(eyes.fingerprint), which)
    if key not in _FACETS:
        if len(_FACETS) > 8:
            _FACETS.clear()
        _FACETS[key] = _Facets(eyes, which)
    return _FACETS[key]


#: a padded facet's values in each of _Edges' tables
_PADS = {"pos": 0.0, "ax": (1.0, 0.0, 0.0), "half": 0.0, "lit": False, "pad": True, "pa": 0.0,
         "pp": 0.0}  # fmt: skip


class _Edges:
    """The constraining facets of one eye for a chunk of keys, padded to (N, K):
    positions, axes, half-angles, ``lit`` (must be seen) and ``pad``."""

    #: both eyes' table (:func:`both_columns`), kept with the columns it was made from
    _both: Any = None

    def __init__(self, f: _Facets, lit: LitCSR) -> None:
        ptr, ind = lit
        n, nf = ptr.size - 1, f.pos.shape[0]
        if EDGES_KERNEL and RINGS == 2 and kernels.use(ind.size * f.nb.shape[1] ** 2):
            from eyeviz.core.kernels.limit3d_region import constraining_kernel

            per = np.minimum(np.diff(ptr) * (1 + f.nb.shape[1] * (1 + f.nb.shape[1])), nf)
            i_all = np.empty(int(per.sum()), np.int64)
            is_lit = np.empty(i_all.size, np.bool_)
            cnt = np.empty(n, np.int64)
            constraining_kernel(kernels.arg(ptr, np.int64), kernels.arg(ind, np.int64),
                                kernels.arg(f.nb, np.int64), np.full(nf, -1, np.int64),
                                i_all, is_lit, cnt)  # fmt: skip
            i_all, is_lit = i_all[: cnt.sum()], is_lit[: cnt.sum()]
            r_all = np.repeat(np.arange(n), cnt)
        else:
            rows = np.repeat(np.arange(n), np.diff(ptr))
            lit_codes = rows * nf + ind
            ring = lit_codes
            near = [lit_codes]
            for _ in range(RINGS):
                r_, i_ = np.divmod(ring, nf)
                ring = np.repeat(r_, f.nb.shape[1]) * nf + f.nb[i_].ravel()
                near.append(ring)
            allc = np.unique(np.concatenate(near))
            unlit = allc[~np.isin(allc, lit_codes, assume_unique=True)]
            codes = np.concatenate([lit_codes, unlit])
            is_lit = np.concatenate([np.ones(lit_codes.size, bool), np.zeros(unlit.size, bool)])
            r_all, i_all = np.divmod(codes, nf)
            order = np.argsort(r_all, kind="stable")
            r_all, i_all, is_lit = r_all[order], i_all[order], is_lit[order]
            cnt = np.bincount(r_all, minlength=n)
        k = max(1, int(cnt.max()) if cnt.size else 1)
        slot = np.arange(r_all.size) - np.repeat(np.cumsum(cnt) - cnt, cnt)
        self.pos = np.zeros((n, k, 3))
        self.ax = np.zeros((n, k, 3))
        self.ax[..., 0] = 1.0
        self.half = np.zeros((n, k))
        self.lit = np.zeros((n, k), bool)
        self.pad = np.ones((n, k), bool)
        self.pos[r_all, slot] = f.pos[i_all]
        self.ax[r_all, slot] = f.ax[i_all]
        self.half[r_all, slot] = f.half[i_all]
        self.lit[r_all, slot] = is_lit
        self.pad[r_all, slot] = False
        self.pa = np.einsum("nkj,nkj->nk", self.pos, self.ax)[..., None]
        self.pp = np.einsum("nkj,nkj->nk", self.pos, self.pos)[..., None]
        self._cols: tuple[np.ndarray, ...] | None = None

    def prune(self, c: np.ndarray, keep_lit: float = 0.5, keep_unlit: float = 2.0) -> None:
        """Keep the facets that may bind near the centres c (N, 3): lit ones whose cone
        lies at least ``keep_lit`` times lo from c, unlit ones within ``keep_unlit`` times
        hi. (Dropping a constraint only enlarges the region: the exact check decides.)"""
        dist, _ = self._dist(c[:, None, :])
        dist = dist[..., 0]
        live = ~self.pad
        lo = np.where(self.lit & live, dist, -np.inf).max(axis=1, keepdims=True)
        hi = np.where(~self.lit & live, dist, np.inf).min(axis=1, keepdims=True)
        keep = live & np.where(self.lit, dist >= keep_lit * lo, dist <= keep_unlit * hi)
        k = max(1, int(keep.sum(axis=1).max()))
        order = np.argsort(~keep, axis=1, kind="stable")[:, :k]
        rows = np.arange(order.shape[0])[:, None]  # (a gather: np.take_along_axis's values)
        for name in ("pos", "ax", "half", "lit", "pa", "pp"):
            setattr(self, name, getattr(self, name)[rows, order])
        self.pad = ~keep[rows, order]
        self._cols = None

    def take(self, rows: np.ndarray) -> _Edges:
        """The keys ``rows`` of the chunk alone."""
        out = object.__new__(_Edges)
        for name in ("pos", "ax", "half", "lit", "pad", "pa", "pp"):
            setattr(out, name, getattr(self, name)[rows])
        out._cols = None if self._cols is None else tuple(v[rows] for v in self._cols)
        return out

    def put(self, rows: np.ndarray, other: _Edges) -> None:
        """The keys ``rows`` replaced by ``other``'s (both padded to the wider)."""
        k = max(self.pos.shape[1], other.pos.shape[1])
        for e in (self, other):
            extra = k - e.pos.shape[1]
            for name, fill in _PADS.items():
                v = getattr(e, name)
                if extra:
                    block = np.empty((v.shape[0], extra) + v.shape[2:], v.dtype)
                    block[...] = fill
                    setattr(e, name, np.concatenate([v, block], axis=1))
            e._cols = None
        for name in _PADS:
            getattr(self, name)[rows] = getattr(other, name)

    def _dist(self, c: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(dist(c, K_i), |c - p_i|) (N, K, G) at centres c (N, G, 3)."""
        ct = np.swapaxes(c, 1, 2)  # (N, 3, G)
        s = np.matmul(self.ax, ct) - self.pa  # v . a
        v2 = np.matmul(self.pos, ct) * -2.0 + self.pp + np.einsum("ngj,ngj->ng", c, c)[:, None]
        v2 = np.maximum(v2, 0.0)
        q = np.sqrt(np.maximum(v2 - s * s, 0.0))
        vn = np.sqrt(v2)
        ex = np.arctan2(q, s) - self.half[..., None]
        dist = np.where(ex <= 0.0, 0.0, np.where(ex < math.pi / 2, vn * np.sin(ex), vn))
        return dist, vn

    def bounds(self, c: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(lo, hi) (N, G) at centres c (N, G, 3): the largest distance of a lit cone and
        the smallest of an unlit cone or of a lit lens (module docstring). Compiled
        (to a few units in the last place the same) unless ``EYEVIZ_JIT=0``."""
        if kernels.use(c.shape[0] * c.shape[1]):
            from eyeviz.core.kernels.limit3d_region import cone_bounds_kernel

            lo = np.empty(c.shape[:2])
            hi = np.empty(c.shape[:2])
            pos, ax, ch, sh, lit, pad = self.columns()
            cone_bounds_kernel(pos, ax, ch, sh, lit, pad, kernels.arg(c, np.float64), lo, hi)
            return lo, hi
        return self._bounds_ref(c)

    def columns(self) -> tuple[np.ndarray, ...]:
        """What the compiled kernels read: positions, axes, cos and sin of the half
        acceptance angles, ``lit``, ``pad``."""
        if self._cols is None:
            self._cols = (self.pos, self.ax, np.cos(self.half), np.sin(self.half), self.lit,
                          self.pad)  # fmt: skip
        return self._cols

    def _bounds_ref(self, c: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`bounds` in numpy (the reference)."""
        dist, vn = self._dist(c)
        lit = (self.lit & ~self.pad)[..., None]
        unl = (~self.lit & ~self.pad)[..., None]
        lo = np.where(lit, dist, -np.inf).max(axis=1)
        hi = np.minimum(
            np.where(unl, dist, np.inf).min(axis=1), np.where(lit, vn, np.inf).min(axis=1)
        )
        return lo, hi


def both_columns(ea: _Edges, eb: _Edges) -> tuple[np.ndarray, ...]:
    """Both eyes' constraining facets of each key as one table of its live facets, what
    the measured region test and draws walk (kernels.measured_limit): positions, axes, cos
    and sin of the half acceptance angles, ``lit`` (N, K_A + K_B, ...), A's live facets
    then B's in index order, then padding, and the live count per key (N,). A walk over
    its first count facets folds the same facets in the same order as one over both
    eyes' tables with their padding skipped. Kept on ``ea`` while both eyes' columns are
    the same objects (:meth:`_Edges.prune` and :meth:`_Edges.put` renew them)."""
    ca, cb = ea.columns(), eb.columns()
    kept = getattr(ea, "_both", None)
    if kept is not None and kept[0] is ca and kept[1] is cb:
        return kept[2]
    pad = np.concatenate([ca[5], cb[5]], axis=1)
    order = np.argsort(pad, axis=1, kind="stable")  # the live facets first, in order
    rows = np.arange(order.shape[0])[:, None]
    out = [np.concatenate([x, y], axis=1)[rows, order] for x, y in zip(ca[:5], cb[:5], strict=True)]
    both = (*out, (~pad).sum(axis=1).astype(np.int64))
    ea._both = (ca, cb, both)
    return both


def _direction(e: _Edges, grid: int, levels: int = 6) -> np.ndarray:
    """Per key (N, 3): the direction u maximising G(u) = min over unlit facets of
    (angle(a_j, u) - alpha_j) - max over lit ones of (angle(a_i, u) - alpha_i), the eye's
    feasible region at infinity (lens offsets ignored), on zooming grids about the lit
    facets' mean axis, first as wide as the lit axes' spread and the widest cone.
    Compiled (kernels.measured_limit.direction_kernel: the same grids, a point given up
    once its G falls to the best so far) unless ``EYEVIZ_JIT=0``; its arccos and dot
    products round differently, so a near tie may pick another grid point."""
    n = e.pos.shape[0]
    lit = e.lit & ~e.pad
    unl = ~e.lit & ~e.pad
    c = np.where(lit[..., None], e.ax, 0.0).sum(axis=1)
    c = c / np.linalg.norm(c, axis=1, keepdims=True)
    spread = np.where(lit, np.arccos(np.clip(np.einsum("nkj,nj->nk", e.ax, c), -1, 1)), 0.0)
    half = np.tan(np.minimum(spread.max(axis=1) + e.half.max(axis=1), 1.2))
    if kernels.use(n * grid * grid):
        from eyeviz.core.kernels.measured_limit import direction_kernel

        c = kernels.arg(c, np.float64)
        direction_kernel(kernels.arg(e.ax, np.float64), kernels.arg(e.half, np.float64),
                         kernels.arg(e.lit), kernels.arg(e.pad), c,
                         kernels.arg(half, np.float64), int(grid), int(levels))  # fmt: skip
        return c
    t = (np.arange(grid) + 0.5) / grid * 2 - 1
    g2 = np.stack(np.meshgrid(t, t, indexing="ij"), axis=-1).reshape(-1, 2)
    for _ in range(levels):
        e1, e2 = _frame(c)
        dd = g2[None] * half[:, None, None]
        v = c[:, None] + dd[..., :1] * e1[:, None] + dd[..., 1:] * e2[:, None]
        v = v / np.linalg.norm(v, axis=2, keepdims=True)
        ang = np.arccos(np.clip(np.matmul(e.ax, np.swapaxes(v, 1, 2)), -1, 1)) - e.half[..., None]
        gv = np.where(unl[..., None], ang, np.inf).min(axis=1)
        gv = gv - np.where(lit[..., None], ang, -np.inf).max(axis=1)
        c = v[np.arange(n), np.argmax(gv, axis=1)]
        half = half / 2.5
    return c


def key_hits(domain, p: np.ndarray, g: np.ndarray, row: np.ndarray, lit_a: LitCSR,
             lit_b: LitCSR) -> np.ndarray:  # fmt: skip
    """:func:`.limit3d_exact.exact_hits` of a measured pair's draws (centres p (D, 3),
    radii g, keys ``row`` (D,) non-decreasing): per key, a bound over its draws rules
    most facets out at once and a bound per draw most of the rest; the few left get the
    certified test (kernels.measured_lit.key_check_kernel); the draws it leaves go to
    ``exact_hits``. The same answer, exactly (tests/estimators/test_limit3d_measured.py);
    without the kernels (``EYEVIZ_JIT=0``) ``exact_hits`` alone."""
    if not (row.size and kernels.use(row.size)):
        return exact_hits(domain, p, g, row, lit_a, lit_b)
    from eyeviz.core.kernels import measured_lit

    # Any: the kernel takes 24 arrays and numbers (numba's Dispatcher stub types fewer)
    check: Any = measured_lit.key_check_kernel
    eyes = domain.eyes
    f64 = np.float64
    xs, ys, zs = (kernels.arg(p[:, j], f64) for j in range(3))
    gs = kernels.arg(g, f64)
    n = lit_a[0].size - 1
    bounds = np.searchsorted(row, np.arange(n + 1)).astype(np.int64)
    res = np.ones(row.size, np.int64)
    for which, (kp, ki) in (("A", lit_a), ("B", lit_b)):
        t, ix = eyes._prepared(which)
        f = _facets(eyes, which)
        rows = np.repeat(np.arange(n), np.diff(kp))
        ki = kernels.arg(np.asarray(ki)[np.lexsort((ki, rows))], np.int64)
        check(xs, ys, zs, gs, bounds, t.px, t.py, t.pz, t.ax, t.ay, t.az, t.nrm, t.cos, t.sin,
              t.exact_only, *f.ax_cols, f.half, kernels.arg(ix.centre, f64), float(ix.lens),
              kernels.arg(kp, np.int64), ki, res)  # fmt: skip
    # a measured pair's field (limit3d_exact.exact_hits): each eye lights two facets or more
    ka, kb = (np.diff(k[0])[row] >= 2 for k in (lit_a, lit_b))
    hit = (res == 1) & ka & kb
    left = np.flatnonzero(res == 2)
    if left.size:
        hit[left] = exact_hits(domain, p[left], g[left], row[left], lit_a, lit_b)
    return hit
