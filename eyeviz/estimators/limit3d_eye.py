"""One eye's edge-cell model of the spherical limit's HEALPix proposal
(:mod:`eyeviz.estimators.limit3d_proposal`, whose searches use it): for a chunk of keys,
the cells where the cap's edge can lie (the key's lit cells a cap ``EDGE`` facet widths
smaller does not light, and the unlit ones as much larger lights), their boundary samples
(``STEP`` a side), the linearisation of their distances about each key's centre, the
model's affine forms and its evaluation, the pruning of cells that cannot bind, and the
exact check's band (limit3d module docstring, step 1)."""

from __future__ import annotations

import math

import numpy as np

from eyeviz.core import healpix, kernels
from eyeviz.core.domain import Domain3D
from eyeviz.core.geometry3d import lit_csr_eye
from eyeviz.estimators.analytic3d import cap_estimates
from eyeviz.estimators.base import LitCSR

#: facet widths inside and outside the estimated cap where the cap's edge is looked for
EDGE = 1.25


#: boundary points per cell edge for the nearest point of a cell
STEP = 6


def _frame(c: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """East and north unit vectors (N, 3) at unit vectors c (N, 3)."""
    e1 = np.stack([-c[:, 1], c[:, 0], np.zeros(len(c))], axis=1)
    n1 = np.linalg.norm(e1, axis=1, keepdims=True)
    e1 = np.where(n1 > 1e-12, e1 / np.maximum(n1, 1e-300), [1.0, 0.0, 0.0])
    # np.cross(c, e1) written out (the same products and differences, so the same bits):
    # np.cross costs more than the rest of the frame
    c0, c1, c2 = c[:, 0], c[:, 1], c[:, 2]
    f0, f1, f2 = e1[:, 0], e1[:, 1], e1[:, 2]
    e2 = np.stack([c1 * f2 - c2 * f1, c2 * f0 - c0 * f2, c0 * f1 - c1 * f0], axis=1)
    return e1, e2


def _rings(nside: int, pix: np.ndarray) -> np.ndarray:
    """The ring of each RING pixel ``pix`` (int64, 1 .. 4 nside - 1: the row of the ring
    tables, healpix_fast._ring_info_tables, as the kernels take it): first[ring] <= pix <
    first[ring] + pixels[ring]."""
    from eyeviz.core.healpix_fast import _ring_info_tables

    first = _ring_info_tables(nside)[0]
    return np.searchsorted(first[1 : 4 * nside], pix, side="right").astype(np.int64)


def _sample_gap(s: float, d: np.ndarray) -> np.ndarray:
    """How much farther than a cell's closure its nearest boundary sample can be, given
    that sample's distance d: samples are s = 1.5 fw / STEP apart along edges (edges are
    at most 1.5 facet widths fw long), so the nearest sample to the closure's nearest
    point q lies within s / 2 of q along the edge: d <= sqrt(D^2 + s^2 / 4) with D the
    true distance, hence D >= D_lo = sqrt(d^2 - s^2 / 4) and d - D <= sqrt(D_lo^2 +
    s^2 / 4) - D_lo (s: ``_Eye.step``). Times 1.5 for the edges' curvature."""
    d_lo = np.sqrt(np.maximum(d * d - 0.25 * s * s, 0.0))
    return 1.5 * (np.sqrt(d_lo * d_lo + 0.25 * s * s) - d_lo)


def _codes(ptr: np.ndarray, ind: np.ndarray, npix: int) -> np.ndarray:
    rows = np.repeat(np.arange(ptr.size - 1, dtype=np.int64), np.diff(ptr))
    return rows * npix + ind


class _Eye:
    """The edge cells of one eye for a chunk of keys: their boundary points, padded to
    (N, K, P, 3), with ``lit`` (N, K) (True: must stay lit), ``pad`` (N, K)."""

    def __init__(
        self,
        domain: Domain3D,
        lit: LitCSR,
        centre: np.ndarray,
        eye: int,
        reach: np.ndarray | None = None,
    ):
        """The edge cells of the keys ``lit`` in eye ``eye`` (at ``centre``), linearised
        at each key's cap estimate. With ``reach`` (N,), the reach of the first
        :meth:`prune` the caller makes: the cells that prune surely drops get no boundary
        samples (compiled only: :meth:`_candidates`; the same cells survive it)."""
        self.nside = domain.nside
        npix = domain.npix
        u, alpha = cap_estimates(domain.nside, lit)
        self.u0 = u
        self.alpha0 = alpha
        fw = math.sqrt(4 * math.pi / npix)
        n = u.shape[0]
        dist = 1000.0
        a_in = np.maximum(alpha - EDGE * fw, 0.5 * fw)
        a_out = np.minimum(alpha + EDGE * fw, math.pi / 2 - 1e-6)
        gs = dist * np.sin(np.concatenate([a_in, a_out]))
        pos = np.asarray(centre) + dist * np.concatenate([u, u])
        # this eye's lit sets only (the other eye's would be thrown away)
        ptr, ind = lit_csr_eye(domain.eyes, eye, pos[:, 0], pos[:, 1], pos[:, 2], gs)
        inner = (ptr[: n + 1], ind[: ptr[n]])
        outer = (ptr[n:] - ptr[n], ind[ptr[n] :])
        # a key too small for an inner cap of half a facet: every lit cell is an edge cell
        # (a cap of 1e-9 rad would send its cells to the exact fallback, ~10 ms each)
        small = alpha - EDGE * fw < 0.5 * fw
        codes, is_lit, rows = _band_cells(lit, inner, outer, small, npix)
        # for the exact check of the band alone (:meth:`band`): the inner and outer caps
        # as lit_csr saw them (centre, half-angle of each ball) and the edge cells (all of
        # them, before any pruning): key - inner and outer - key
        v = pos - np.asarray(centre)
        dv = np.linalg.norm(v, axis=1)
        self.u_io = v[:n] / dv[:n, None]
        with np.errstate(invalid="ignore"):
            half = np.arcsin(np.minimum(gs / dv, 1.0))
        self.b_in = np.where(small, -np.inf, half[:n])
        self.b_out = half[n:].copy()
        self._band = (np.bincount(rows, minlength=n), codes % npix, is_lit)
        self.n_lit_edge = np.bincount(rows[is_lit], minlength=n)
        self.n_unlit = np.bincount(rows[~is_lit], minlength=n)
        self._ring: np.ndarray | None = None  # the band cells' rings, if known
        # the band cells' vertices (T, 4, 3), once _candidates has computed them
        self._verts: np.ndarray | None = None
        ring = None
        if reach is not None and kernels.use(codes.size):
            keep = self._candidates(u, rows, reach)  # sets _ring: the band cells' rings
            codes, is_lit, rows = codes[keep], is_lit[keep], rows[keep]
            ring = None if self._ring is None else self._ring[keep]
        cnt = np.bincount(rows, minlength=n)
        kmax = max(1, int(cnt.max()) if cnt.size else 1)
        slot = np.arange(codes.size) - np.repeat(np.cumsum(cnt) - cnt, cnt)
        self.pts = _boundaries(self.nside, codes % npix, rows, slot, (n, kmax), ring)
        self.lit = np.zeros((n, kmax), bool)
        self.lit[rows, slot] = is_lit
        self.pad = np.ones((n, kmax), bool)
        self.pad[rows, slot] = False
        self.centre = np.asarray(centre, float)
        self.a = np.zeros(3)  # the other eye's centre relative to this one (set by the caller)
        self.linearise(u)

    def _candidates(self, u: np.ndarray, rows: np.ndarray, reach: np.ndarray) -> np.ndarray:
        """The edge cells (bool, in ``_band``'s order; ``rows`` their keys) that
        :meth:`prune` with ``reach`` after the first :meth:`linearise` (at c = u / |u|) may
        keep: it surely drops the others.

        Proof. At c, linearise gives each cell the distance d_s of its nearest boundary
        sample (lit cells: d_s - gap(d_s), :func:`_sample_gap`). The samples lie on the
        cell's boundary and include its four vertices, so dist(c, closure) <= d_s <=
        the nearest vertex's distance; kernels.healpix_match.band_bounds_kernel bounds both
        about c (``far`` below the first, less 1e-12 rad beyond its rounding bounds;
        ``near`` above the second, plus 1e-12). x - gap(x) is increasing (for x >= s / 2
        it is 1.5 sqrt(x^2 - s^2 / 4) - x / 2, slope >= 1; below, x - 0.75 s), so each
        cell's d lies in [L, U] = [f(far), f(near)] (f: x - gap(x) for lit cells, x for
        unlit ones). prune keeps a lit cell iff d >= max_lit - m and an unlit one iff
        d <= min_unlit + m (m = 2.2 reach); max_lit >= max of the lit cells' L and
        min_unlit <= min of the unlit cells' U. So a lit cell with U < max L - m - 1e-9,
        or an unlit one with L > min U + m + 1e-9, is dropped (the 1e-9 rad far above the
        rounding of d, L and U). The cell that attains max_lit (min_unlit) is never among
        them (its U >= d = max_lit >= max L), so prune's max_lit and min_unlit, and hence
        every verdict, are the same on the candidates as on all cells; and the candidates
        keep their slot order, so the kept cells are the same, in the same order, with
        the same samples and linearisation (tests/core/test_kernels_limit3d_affine.py)."""
        from eyeviz.core.healpix_fast import _ring_info_tables, _ring_tables
        from eyeviz.core.kernels.healpix_match import band_bounds_kernel

        _, pix, lit = self._band
        n = self.nside
        first, _, shifted = _ring_info_tables(n)[:3]
        ring = _rings(n, pix)
        self._ring = ring  # band() takes them again
        c = u / np.linalg.norm(u, axis=1, keepdims=True)  # as linearise normalises it
        near, far = np.empty(pix.size), np.empty(pix.size)
        self._verts = np.empty((pix.size, 4, 3))  # band() reads them again
        band_bounds_kernel(n, kernels.arg(pix, np.int64), ring, kernels.arg(rows, np.int64),
                           kernels.arg(c, np.float64), *_ring_tables(n), first, shifted,
                           self._verts, False, near, far)  # fmt: skip
        if kernels.use(pix.size):  # the same verdicts, compiled
            from eyeviz.core.kernels.limit3d_affine import candidates_kernel

            keep = np.empty(pix.size, np.bool_)
            candidates_kernel(kernels.arg(lit, np.bool_), kernels.arg(rows, np.int64), near, far,
                              self.step, kernels.arg(reach, np.float64), u.shape[0],
                              keep)  # fmt: skip
            return keep
        s = self.step
        lo = np.where(lit, far - _sample_gap(s, far), far)
        hi = np.where(lit, near - _sample_gap(s, near), near)
        m = 2.2 * np.asarray(reach, np.float64)[rows] + 1e-9
        lo_lit = np.full(u.shape[0], -np.inf)
        np.maximum.at(lo_lit, rows[lit], lo[lit])
        hi_unl = np.full(u.shape[0], np.inf)
        np.minimum.at(hi_unl, rows[~lit], hi[~lit])
        return np.where(lit, hi >= lo_lit[rows] - m, lo <= hi_unl[rows] + m)

    def band(self) -> tuple[np.ndarray, ...]:
        """The arguments of kernels.healpix_match.edge_match_kernel for this eye's keys, from
        u_io to far: the band cells' bounds about the current centres ``c`` (call after
        the centre search, whose centres the draws lie near), each key's lit cells first
        by ``near`` from the largest, then its unlit ones by ``far`` from the smallest
        (``bl``: where each key's unlit cells start), the order in which the kernel can
        stop at the first cell its bounds settle."""
        from eyeviz.core.healpix_fast import _ring_info_tables, _ring_tables
        from eyeviz.core.kernels.healpix_match import band_bounds_kernel, band_order_kernel

        cnt, pix, lit = self._band
        n = self.nside
        first = _ring_info_tables(n)[0]
        ring = _rings(n, pix) if self._ring is None else self._ring
        bp = np.zeros(cnt.size + 1, np.int64)
        np.cumsum(cnt, out=bp[1:])
        key = np.repeat(np.arange(cnt.size, dtype=np.int64), cnt)
        near, far = np.empty(pix.size), np.empty(pix.size)
        u0 = kernels.arg(self.c, np.float64)
        pix = kernels.arg(pix, np.int64)
        have = self._verts is not None  # the same cells' vertices, from _candidates
        verts = self._verts if self._verts is not None else np.empty((pix.size, 4, 3))
        band_bounds_kernel(n, pix, ring, key, u0, *_ring_tables(n), first,
                           _ring_info_tables(n)[2], verts, have, near, far)  # fmt: skip
        # per key: lit cells (near descending), then unlit ones (far ascending); the band
        # check's _decide_fs reads the vertices in that order too (edge_match_kernel)
        pix, ring, lit, near, far, verts, bl = band_order_kernel(
            bp, pix, ring, kernels.arg(lit, np.bool_), near, far, verts)  # fmt: skip
        u_io = kernels.arg(self.u_io, np.float64)
        return u_io, self.b_in, self.b_out, u0, bp, bl, pix, ring, lit, near, far, verts

    @property
    def step(self) -> float:  # the boundary samples' spacing (edges <= 1.5 fw long)
        return 1.5 * math.sqrt(4 * math.pi / (12 * self.nside**2)) / STEP

    def linearise(self, c: np.ndarray) -> None:
        """Distances d (N, K) and gradients t (N, K, 2) of every edge cell at centres c.
        Compiled unless ``EYEVIZ_JIT=0`` (kernels.limit3d_affine.linearise_kernel: the same
        formulas, to a few ulps; padding slots 0 there)."""
        self.c = c / np.linalg.norm(c, axis=1, keepdims=True)
        self.e1, self.e2 = _frame(self.c)
        if kernels.use(self.pts.shape[0] * self.pts.shape[1]):
            from eyeviz.core.kernels.limit3d_affine import linearise_kernel

            self.d = np.empty(self.pts.shape[:2])
            self.t = np.empty((*self.pts.shape[:2], 2))
            linearise_kernel(kernels.arg(self.pts), kernels.arg(self.lit), kernels.arg(self.pad),
                             kernels.arg(self.c), kernels.arg(self.e1), kernels.arg(self.e2),
                             self.step, self.d, self.t)  # fmt: skip
        else:
            self._linearise_ref()
        self._affine()

    def _linearise_ref(self) -> None:
        """:meth:`linearise`'s d and t in numpy (the reference)."""
        dots = np.einsum("nkpj,nj->nkp", self.pts, self.c)
        best = np.argmax(dots, axis=2)
        p = np.take_along_axis(self.pts, best[:, :, None, None], 2)[:, :, 0]
        cp = np.einsum("nkj,nj->nk", p, self.c)
        tang = p - cp[..., None] * self.c[:, None, :]
        tn = np.linalg.norm(tang, axis=2)
        d = np.arctan2(tn, cp)
        # the nearest boundary sample is farther than the cell by at most _sample_gap:
        # lit cells' distances are lowered by that much, so the linearised region holds
        # the true one; unlit cells' samples lie in the cell's closure
        self.d = np.where(self.lit, d - _sample_gap(self.step, d), d)
        with np.errstate(invalid="ignore", divide="ignore"):
            t1 = np.einsum("nkj,nj->nk", tang, self.e1) / tn
            t2 = np.einsum("nkj,nj->nk", tang, self.e2) / tn
        self.t = np.stack([np.nan_to_num(t1), np.nan_to_num(t2)], axis=-1)

    def prune(self, reach: np.ndarray) -> None:
        """Drop the edge cells that cannot bind anywhere within ``reach`` (N,) of the
        centre: a lit cell's modelled distance moves by at most |delta| and an unlit
        one's by at most |delta| + |delta|^2 / (2 d), so a lit cell below max_lit - 2.2
        reach or an unlit one above min_unlit + 2.2 reach never decides. (Dropping
        constraints only loosens the model: the exact check decides.) The dropped cells
        are dropped whether or not the arrays get narrower, so the cells kept do not depend
        on the other keys of the chunk (nor on which cells got samples: _candidates)."""
        live = ~self.pad
        lo0 = np.where(self.lit & live, self.d, -np.inf).max(axis=1)
        hi0 = np.where(~self.lit & live, self.d, np.inf).min(axis=1)
        m = 2.2 * reach[:, None]
        keep = live & np.where(self.lit, self.d >= lo0[:, None] - m, self.d <= hi0[:, None] + m)
        cnt = keep.sum(axis=1)
        kmax = max(1, int(cnt.max()) if cnt.size else 1)
        if kmax >= keep.shape[1]:  # no narrower: the dropped cells become padding in place
            if not (keep == live).all():
                self.pad = ~keep
                self._affine()
            return
        if kernels.use(keep.size):  # the same copies, compiled
            from eyeviz.core.kernels.limit3d_affine import compact_kernel

            n = keep.shape[0]
            o_pts = np.empty((n, kmax, *self.pts.shape[2:]))
            o_lit, o_pad = np.empty((n, kmax), bool), np.empty((n, kmax), bool)
            o_d, o_t = np.empty((n, kmax)), np.empty((n, kmax, 2))
            compact_kernel(kernels.arg(keep), kernels.arg(self.pts), kernels.arg(self.lit),
                           kernels.arg(self.d), kernels.arg(self.t), o_pts, o_lit, o_pad, o_d,
                           o_t)  # fmt: skip
            self.pts, self.lit, self.pad, self.d, self.t = o_pts, o_lit, o_pad, o_d, o_t
            self._affine()
            return
        order = np.argsort(~keep, axis=1, kind="stable")[:, :kmax]
        rows = np.arange(keep.shape[0])[:, None]
        self.pts = self.pts[rows, order]
        self.lit = self.lit[rows, order]
        self.pad = ~keep[rows, order]
        self.d = self.d[rows, order]
        self.t = self.t[rows, order]
        self._affine()

    def _affine(self) -> None:
        """The model as affine forms in delta: a lit cell's distance is d - t . delta, an
        unlit one's squared distance is d^2 - 2 d t . delta + |delta|^2 (the same value as
        (d - t . delta)^2 + |delta_perp|^2, |t| = 1), so max_lit and min_unlit are one
        matrix product and one reduction each (padding: -inf / +inf, zero slope).
        Compiled unless ``EYEVIZ_JIT=0`` (kernels.limit3d_affine.affine_kernel, the same
        bits; the packed lists' slots beyond a row's count hold zeros there)."""
        if kernels.use(self.lit.size):
            from eyeviz.core.kernels.limit3d_affine import affine_forms_kernel

            self.a_lit, self.t_lit, self.a_unl, self.t_unl, self.lists = affine_forms_kernel(
                kernels.arg(self.d, np.float64), kernels.arg(self.t, np.float64),
                kernels.arg(self.lit), kernels.arg(self.pad))  # fmt: skip
            return
        lit = self.lit & ~self.pad
        unl = ~self.lit & ~self.pad
        self.a_lit = np.where(lit, self.d, -np.inf)
        self.t_lit = np.where(lit[..., None], self.t, 0.0)
        self.a_unl = np.where(unl, self.d * self.d, np.inf)
        self.t_unl = np.where(unl[..., None], 2.0 * self.d[..., None] * self.t, 0.0)
        # the same forms of the lit cells alone and of the unlit ones alone, in slot order
        # (the kernels' loops skip the others' -inf / +inf slots: _affine_lists)
        self.lists = (*_packed(lit, self.a_lit, self.t_lit), *_packed(unl, self.a_unl, self.t_unl))

    def box_lists(self, ext: np.ndarray) -> tuple[np.ndarray, ...]:
        """The model's packed forms (``lists``) less those that never give its value on
        each key's box |delta_k| <= ext[:, k] (N, 2): a form another one exceeds (lit;
        unlit: undercuts) everywhere there by more than both values' rounding. Wherever
        the draws evaluate the model (inside the boxes: A's draws are tested against A's
        box first, B's search and draw lie on the ray's interval inside B's box, up to
        rounding, which the box's widening covers) its values are the same bits with
        these lists, with about a quarter of the forms at nside 180. Compiled unless
        ``EYEVIZ_JIT=0`` (kernels.limit3d_affine.box_lists_kernel, its proof there;
        :meth:`_box_lists_ref` the reference)."""
        if kernels.use(ext.shape[0]):
            from eyeviz.core.kernels.limit3d_affine import box_lists_kernel

            out = tuple(np.zeros_like(x) for x in self.lists)
            box_lists_kernel(self.lists, kernels.arg(ext, np.float64), out)
            return out
        return self._box_lists_ref(ext)

    def _box_lists_ref(self, ext: np.ndarray) -> tuple[np.ndarray, ...]:
        """:meth:`box_lists` in numpy (the reference; the slots beyond a row's count are
        0)."""
        from eyeviz.core.kernels.limit3d_affine import BOX_ABS, BOX_REL, BOX_TOL

        e = (ext * (1.0 + BOX_REL) + BOX_ABS)[:, None, None, :]  # (N, 1, 1, 2)
        out: list[np.ndarray] = []
        for a, t, cnt, sgn in ((*self.lists[:3], 1.0), (*self.lists[3:], -1.0)):
            k = a.shape[1]
            live = np.arange(k)[None, :] < cnt[:, None]  # (N, K)
            with np.errstate(invalid="ignore", over="ignore"):
                spread = (np.abs(t[:, None, :, :] - t[:, :, None, :]) * e).sum(-1)  # [n, i, j]
                mag = np.abs(a) + (np.abs(t) * e[:, 0]).sum(-1)  # (N, K)
                gap = sgn * (a[:, None, :] - a[:, :, None]) - spread
                tol = BOX_TOL * (1.0 + mag[:, :, None] + mag[:, None, :])
                dom = (gap > tol) & live[:, None, :] & ~np.eye(k, dtype=bool)[None]
            keep = live & ~dom.any(axis=2)
            n_keep = keep.sum(axis=1)
            order = np.argsort(~keep, axis=1, kind="stable")
            slot = np.arange(k)[None, :] < n_keep[:, None]
            oa = np.where(slot, np.take_along_axis(a, order, 1), 0.0)
            ot = np.where(slot[..., None], np.take_along_axis(t, order[..., None], 1), 0.0)
            out += [oa, ot, n_keep.astype(np.int64)]
        return tuple(out)

    def model(self, delta: np.ndarray) -> np.ndarray:
        """Each edge cell's modelled distance (N, K, G) at gnomonic offsets delta (N, G, 2).

        Lit cells: d - t . delta, below the true distance (the distance to an edge is
        linear to first order and to a vertex convex), so their constraint alpha > dist
        is loosened. Unlit cells: the distance to their nearest sample point p,
        sqrt((d - t . delta)^2 + |delta_perp|^2), above the true distance (p lies in the
        cell), so alpha <= dist is loosened too: the modelled region holds the true one.
        (Padding cells: any value; callers mask them with ``pad``.)
        """
        dt = np.swapaxes(delta, 1, 2)  # (N, 2, G)
        td = np.matmul(self.t, dt)
        v = self.d[:, :, None] - td
        sq = np.einsum("ngj,ngj->ng", delta, delta)[:, None, :]
        w = self.d[:, :, None] * (self.d[:, :, None] - 2.0 * td) + sq
        return np.where(self.lit[:, :, None], v, np.sqrt(np.maximum(w, 0.0)))

    def bounds(self, delta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(max over lit edge cells, min over unlit) of :meth:`model` at gnomonic offsets
        delta (N, G, 2): arrays (N, G). Compiled (bit for bit the same) unless
        ``EYEVIZ_JIT=0``."""
        if kernels.use(delta.shape[0] * delta.shape[1]):
            from eyeviz.core.kernels.limit3d_affine import affine_bounds_kernel

            lo = np.empty(delta.shape[:2])
            hi = np.empty(delta.shape[:2])
            affine_bounds_kernel(self.a_lit, self.t_lit, self.a_unl, self.t_unl, self.lists,
                                 kernels.arg(delta, np.float64), lo, hi)  # fmt: skip
            return lo, hi
        return self._bounds_ref(delta)

    def _bounds_ref(self, delta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`bounds` in numpy (the reference)."""
        dx = delta[:, None, :, 0]
        dy = delta[:, None, :, 1]
        v = self.t_lit[..., 0, None] * dx
        v += self.t_lit[..., 1, None] * dy
        lo = (self.a_lit[..., None] - v).max(axis=1)
        v = self.t_unl[..., 0, None] * dx
        v += self.t_unl[..., 1, None] * dy
        hi2 = (self.a_unl[..., None] - v).min(axis=1)
        hi2 += np.einsum("ngj,ngj->ng", delta, delta)
        return lo, np.sqrt(np.maximum(hi2, 0.0))

    def direction(self, delta: np.ndarray) -> np.ndarray:
        """Unit vectors (N, M, 3) at gnomonic offsets delta (N, M, 2)."""
        v = (
            self.c[:, None, :]
            + delta[..., :1] * self.e1[:, None, :]
            + delta[..., 1:] * self.e2[:, None, :]
        )
        return v / np.linalg.norm(v, axis=2, keepdims=True)

    def gnomonic(self, v: np.ndarray) -> np.ndarray:
        """Gnomonic offsets (N, M, 2) of unit vectors v (N, M, 3) about the centre."""
        cc = np.einsum("nmj,nj->nm", v, self.c)
        x, y = np.einsum("nmj,nj->nm", v, self.e1), np.einsum("nmj,nj->nm", v, self.e2)
        with np.errstate(divide="ignore", invalid="ignore"):  # v at 90 deg: inf, no warning
            return np.stack([x / cc, y / cc], axis=-1)


def _band_cells(lit: LitCSR, inner: LitCSR, outer: LitCSR, small: np.ndarray, npix: int):
    """The band cells of each key (codes row * npix + pixel, lit, row), by key, each key's
    lit ones first: key - inner (key where ``small``), then outer - key, each ascending.
    Compiled unless ``EYEVIZ_JIT=0`` (kernels.healpix_match.band_cells_kernel, a merge of
    the sorted rows: the same arrays)."""
    if kernels.use(lit[1].size):
        from eyeviz.core.kernels.healpix_match import band_cells_kernel

        size = lit[1].size + outer[1].size
        pix, is_lit, rows = np.empty(size, np.int64), np.empty(size, bool), np.empty(size, np.int64)
        ar = [kernels.arg(a, np.int64) for a in (*lit, *inner, *outer)]
        m = band_cells_kernel(*ar, kernels.arg(small, np.bool_), pix, is_lit, rows)
        return rows[:m] * npix + pix[:m], is_lit[:m], rows[:m]
    key = _codes(*lit, npix)
    c_in = _codes(*inner, npix)
    c_in = c_in[~small[c_in // npix]]
    c_out = _codes(*outer, npix)
    lit_edge = key[~np.isin(key, c_in, assume_unique=True)]
    unlit = c_out[~np.isin(c_out, key, assume_unique=True)]
    codes = np.concatenate([lit_edge, unlit])
    is_lit = np.concatenate([np.ones(lit_edge.size, bool), np.zeros(unlit.size, bool)])
    rows = codes // npix
    order = np.argsort(rows, kind="stable")
    return codes[order], is_lit[order], rows[order]


def _offsets() -> tuple[np.ndarray, np.ndarray]:
    """The face offsets (dx, dy) of healpix.boundaries' STEP points a side (N, W, S, E)."""
    t = np.arange(STEP) / STEP
    dx = np.concatenate([1 - t, np.zeros(STEP), t, np.ones(STEP)])
    dy = np.concatenate([np.ones(STEP), 1 - t, np.zeros(STEP), t])
    return dx, dy


_OFFSETS = _offsets()  # made once: the kernel only reads them


def _boundaries(nside: int, pix: np.ndarray, rows, slot, shape: tuple[int, int],
                ring=None) -> np.ndarray:  # fmt: skip
    """The boundary samples (healpix.boundaries, STEP a side) of the cells ``pix`` (T,) at
    [rows, slot] of a zero array (*shape, 4 STEP, 3). Compiled unless ``EYEVIZ_JIT=0``
    (kernels.limit3d_affine.boundaries_kernel: the same formulas, to a few ulps; the
    cells' rings ``ring`` (T,) if known)."""
    out = np.zeros((*shape, 4 * STEP, 3))
    if kernels.use(pix.size):
        from eyeviz.core.healpix_fast import _ring_info_tables
        from eyeviz.core.kernels.limit3d_affine import boundaries_kernel

        first = _ring_info_tables(nside)[0]
        if ring is None:
            ring = _rings(nside, pix)
        dx, dy = _OFFSETS
        i64 = np.int64
        boundaries_kernel(nside, kernels.arg(pix, i64), kernels.arg(ring, i64), first,
                          kernels.arg(rows, i64), kernels.arg(slot, i64), dx, dy, healpix.JRLL,
                          healpix.JPLL, out)  # fmt: skip
        return out
    out[rows, slot] = healpix.boundaries(nside, pix, STEP)
    return out


def _packed(sel: np.ndarray, a: np.ndarray, t: np.ndarray):
    """The slots ``sel`` (N, K) of each row first, in slot order: (a (N, KS), t (N, KS, 2),
    counts (N,)), KS >= 1 (beyond a row's count: any of its other slots)."""
    cnt = sel.sum(axis=1)
    ks = max(1, int(cnt.max()) if cnt.size else 1)
    order = np.argsort(~sel, axis=1, kind="stable")[:, :ks]
    return (
        np.ascontiguousarray(np.take_along_axis(a, order, 1)),
        np.ascontiguousarray(np.take_along_axis(t, order[..., None], 1)),
        cnt.astype(np.int64),
    )
