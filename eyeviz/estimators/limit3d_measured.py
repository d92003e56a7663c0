"""The measured-eye proposal of the spherical limit (:mod:`eyeviz.estimators.limit3d`).

A measured eye (docs/measured.md) is a list of facets, each a lens p_i, a unit axis a_i
and a half acceptance angle alpha_i; facet i sees the ball (c, g) iff the ball meets its
acceptance cone K_i, i.e. iff g >= dist(c, K_i), where with v = c - p_i and theta the angle
between v and a_i

    dist(c, K_i) = 0 (theta <= alpha_i), |v| sin(theta - alpha_i) (theta - alpha_i < pi/2),
                   |v| otherwise.

So for a fixed centre c the radii g whose ball lights exactly the key's set of an eye form
one interval, [max over its lit facets of dist(c, K_i), min over its unlit facets of
dist(c, K_j)), and the ball must contain no lens (g < |c - p_i|). The proposal reads this
**feasible region** of each eye from the facets' cones, as the HEALPix proposal reads it
from the cells (:mod:`.limit3d_healpix`), here without a linearisation:

1. Per eye, the constraining facets of a key: its lit facets and the unlit facets within
   two rings of axis neighbours of them (:func:`eyeviz.estimators.triangulation.
   facet_neighbours`). Dropping the other unlit facets only enlarges the region; the exact
   check decides.
2. H(c) = min(hi_A, hi_B, g_max, r) - max(lo_A, lo_B, r sin(gamma / 2)) (lo, hi the two
   ends of each eye's interval; r about the domain's origin): the centre c is feasible
   iff H(c) > 0.
3. A reference centre: each eye's best direction at infinity (the maximum of min over
   unlit facets of (angle(a_j, u) - alpha_j) - max over lit ones of (angle(a_i, u) -
   alpha_i), zooming grids), the two rays triangulated, then moved to the maximum of H / |c
   - o_A| on zooming grids (o_A: eye A's lens centroid); where that point is not
   feasible, the grids again ``FAR`` times as wide, their point taken if it is;
   facets far from binding there are dropped.
4. Coordinates that make the region close to a box: delta, A's direction in gnomonic
   coordinates about the reference, and beta, the angle at o_B between the baseline and
   the ball (the triangle o_A, o_B, c gives |c - o_A| = |b| sin(beta) / sin(a + beta), a
   the angle at o_A): A's lit set bounds delta and B's bounds beta. The box: bisection
   along 26 directions of H >= -slack, the boundary points' box widened ``WIDEN`` times,
   then widened by half again on each face near which a pilot's feasible draws fall.
5. A draw: (delta, beta) uniform in a box, g uniform on the feasible interval at that
   centre. Each batch's draws come from three boxes in turn, a deterministic mixture:
   where the provable box below holds, the first ``DEFEND`` from it (every draw where the
   bisection found no feasible point); then ``TIGHT`` from the tight box, the last pilot
   round's feasible points' box widened ``TIGHT_WIDEN`` times (where it has
   ``TIGHT_MIN`` points); the rest from the box of step 4 (cut to the provable box).
   Weight: prior x rho^2 (1 + |delta|^2)^(-3/2) |b| sin(a) / sin(a + beta)^2 (d(x, y,
   z) / d(delta, beta)) x the interval's length / the mixture's density in (delta, beta)
   (the sum over the boxes holding the draw of share / volume). Every draw with a weight
   is checked exactly (:func:`.limit3d_cones.key_hits`: a bound per key and per draw
   leaves a few facets to the certified test; else :func:`.limit3d_exact.exact_hits`,
   the pair's own ``lit_csr``, then ``in_bfv``).

Where the provable box holds, the mixture's density is positive on all of it, so the
estimate is unbiased whatever the box of step 4 or the tight box covers (a part the box
misses is found by the defensive draws, at a weight as large as the two boxes' volumes
are apart: the pilot keeps such parts small; a part the tight box misses is drawn from
the box, at the box's share). Elsewhere the proposal covers the posterior when the region
is close to convex about the reference (the widening and the pilot are the margin). The
tests compare the answers with brute-force rejection sampling from the prior on a small
measured eye, and check that every brute-force posterior sample lies in the provable box.

The provable box and its proof: :mod:`.limit3d_provable`."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from eyeviz.core import kernels
from eyeviz.core.domain import Domain3D
from eyeviz.estimators import limit3d_provable
from eyeviz.estimators.analytic3d import estimate
from eyeviz.estimators.base import LitCSR, take_rows
from eyeviz.estimators.limit3d_cones import (
    RINGS,
    _direction,
    _Edges,
    _Facets,
    _facets,
    both_columns,
)
from eyeviz.estimators.limit3d_measured_draws import MeasuredDraws, _uniforms
from eyeviz.estimators.limit3d_proposal import _frame
from eyeviz.estimators.triangulation import triangulate_rays

__all__ = ["MeasuredProposal"]

#: bisection steps
ITERS = 12
#: widening of the bisection's box, and the pilot draws and rounds that widen it further
WIDEN = 2.0
PILOT = 2048
PILOT_ROUNDS = 4
#: zoom levels of the centre search (each grid 1 / 2.5 as wide) and its points per axis
LEVELS = 6
LOCATE = 5
#: the centre search's first half-width in directions, in facet spacings (about each eye's
#: best direction at infinity, triangulated), and the reach of the box's bisection
SEARCH = 1.5
REACH = 6.0
#: keys whose reference search found no feasible centre search again, ``FAR`` times as
#: wide with ``FAR_LEVELS`` more levels (the first pass's misses lie 3-9 facet spacings
#: from the rays' triangulation on the honeybee: docs/limit3d.md, "bee33c")
FAR = 5.0
FAR_LEVELS = 2
#: the retries of keys with nothing accepted (limit3d._retries): of limit3d.RETRY's three
#: stages only the second, 24 batches with a window 2.5 times wider, its stream 2 as
#: there. On 400 fresh honeybee keys (seeds 20261207-8) the first (8 batches, the same
#: window as the first pass) and the third (96 batches) found no key the second had not;
#: the second found 14 of 21; they took 9 % of the run time
RETRIES = ((2, 2.5, 24),)
#: a key with nothing accepted in its first batch is not topped up but retried at once
#: (limit3d._tops_up): on the bench's 160 honeybee keys and three fresh sets, such a key's
#: next 15 batches found nothing, or a few draws, on every key (docs/limit3d.md, "bee33d")
RETRY_EMPTY = True
#: :meth:`MeasuredProposal._around`'s box search and pilot as one compiled call (the same
#: boxes as its numpy loops, which the tests compare with it)
BOX_KERNEL = True
#: :meth:`MeasuredProposal._search`'s grids as one compiled call (the same points as its
#: numpy loop with the compiled step, which the tests compare with it)
SEARCH_KERNEL = True
#: the share of each batch's draws from the provable box where it holds
DEFEND = 0.0625
#: the tight box: the pilot's feasible points' box widened ``TIGHT_WIDEN`` times about its
#: centre (cut to the box), its share of each batch's draws, and the feasible points it
#: needs (fewer: no tight box)
TIGHT_WIDEN = 1.5
TIGHT = 0.6875
TIGHT_MIN = 16


_DIRS3 = np.array(
    [
        (i, j, k)
        for i in (-1, 0, 1)
        for j in (-1, 0, 1)
        for k in (-1, 0, 1)
        if (i, j, k) != (0, 0, 0)
    ],
    float,
)
_DIRS3 /= np.linalg.norm(_DIRS3, axis=1, keepdims=True)
# the constraining facets (limit3d_cones), read here and by the tests under these names
_CONES = (RINGS, _Edges, _Facets, _facets)


class MeasuredProposal(MeasuredDraws):
    """Importance draws for keys of a measured pair (module docstring): :meth:`setup`
    once per chunk, then :meth:`sample` per batch of ``samples`` draws."""

    def __init__(self, domain: Domain3D, prior: str, samples: int, grid: int) -> None:
        self.domain, self.prior, self.samples, self.grid = domain, prior, samples, grid
        self.retries = RETRIES
        self.retry_empty = RETRY_EMPTY
        self.fa = _facets(domain.eyes, "A")
        self.fb = _facets(domain.eyes, "B")
        self.origin = np.asarray(domain.origin, np.float64)
        off = float(np.linalg.norm(self.fa.centre - self.origin))
        self.w_min = 1.0 / (domain.r_max + off)
        self.w_max = 1.0 / max(domain.r_min - off, 1e-3 * domain.r_min)
        self.s_half = math.sin(domain.gamma / 2)
        b = self.fb.centre - self.fa.centre
        self.blen = float(np.linalg.norm(b))
        self.bhat = b / self.blen

    # --- the region ----------------------------------------------------------------------
    def _h(self, st: dict, c: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(g_lo, g_hi) (N, G) of centres c (N, G, 3): the radii whose ball lights exactly
        the key's sets of the constraining facets, within the prior's g range."""
        d = self.domain
        lo_a, hi_a = st["ea"].bounds(c)
        lo_b, hi_b = st["eb"].bounds(c)
        r = np.linalg.norm(c - self.origin, axis=2)
        g_lo = np.maximum(np.maximum(lo_a, lo_b), r * self.s_half)
        g_hi = np.minimum(np.minimum(hi_a, hi_b), np.minimum(r, d.g_max))
        return g_lo, g_hi

    def _locate(self, st: dict, c: np.ndarray, ww: np.ndarray) -> np.ndarray:
        """Per key the first of the centres c (N, G, 3) of largest H x ww (H / distance:
        an angle), the reference search's step. Compiled with an early exit
        (kernels.measured_limit.locate_kernel, the same point) unless ``EYEVIZ_JIT=0``."""
        if kernels.use(c.shape[0] * c.shape[1]):
            from eyeviz.core.kernels import measured_limit

            # Any: the kernel takes 18 arrays and numbers (numba's Dispatcher stub types fewer)
            locate: Any = measured_limit.locate_kernel
            r = np.linalg.norm(c - self.origin, axis=2)
            best = np.empty(c.shape[0], np.int64)
            locate(kernels.arg(c, np.float64), r, kernels.arg(ww, np.float64), self.s_half,
                   float(self.domain.g_max), *st["ea"].columns(), *st["eb"].columns(),
                   best)  # fmt: skip
            return best
        g_lo, g_hi = self._h(st, c)
        return np.argmax((g_hi - g_lo) * ww, axis=1)

    def _centres(self, st: dict, delta: np.ndarray, w: np.ndarray) -> np.ndarray:
        """Centres (N, G, 3) at gnomonic offsets delta (N, G, 2) about the reference and
        w = 1 / distance from o_A (N, G)."""
        v = st["u0"][:, None, :] + delta[..., :1] * st["e1"][:, None, :]
        v = v + delta[..., 1:] * st["e2"][:, None, :]
        v = v / np.linalg.norm(v, axis=2, keepdims=True)
        return self.fa.centre + v / w[..., None]

    def _bcentres(self, st: dict, delta: np.ndarray, beta: np.ndarray):
        """(centres (N, G, 3), distance from o_A, d distance / d beta) at gnomonic offsets
        delta (N, G, 2) of A's direction and angles beta (N, G) at o_B between the
        baseline and the ball (the triangle o_A, o_B, c: rho = |b| sin(beta) / sin(a +
        beta), a the angle at o_A). NaN where the rays do not meet in front."""
        v = st["u0"][:, None, :] + delta[..., :1] * st["e1"][:, None, :]
        v = v + delta[..., 1:] * st["e2"][:, None, :]
        v = v / np.linalg.norm(v, axis=2, keepdims=True)
        a = np.arccos(np.clip(v @ self.bhat, -1.0, 1.0))
        with np.errstate(divide="ignore", invalid="ignore"):
            s_ab = np.sin(a + beta)
            ok = (beta > 0) & (a + beta < math.pi)
            rho = np.where(ok, self.blen * np.sin(beta) / s_ab, np.nan)
            drho = np.where(ok, self.blen * np.sin(a) / (s_ab * s_ab), np.nan)
        return self.fa.centre + v * rho[..., None], rho, drho

    def _search(self, st: dict, wc: np.ndarray, wh: np.ndarray, half: float, levels: int):
        """The reference search (module docstring, step 3): zooming grids of ``LOCATE``^3
        points over (delta, w) about (0, wc), half-widths ``half`` and wh (each level
        1 / 2.5 as wide), to the first point of largest H x w. Returns (delta (N, 2), w
        (N,), H x w there)."""
        n = wc.size
        t = (np.arange(LOCATE) + 0.5) / LOCATE * 2 - 1
        g3 = np.stack(np.meshgrid(t, t, t, indexing="ij"), axis=-1).reshape(-1, 3)
        dc = np.zeros((n, 2))
        if SEARCH_KERNEL and kernels.use(n * g3.shape[0]):
            from eyeviz.core.kernels import measured_limit

            # Any: the kernel takes 28 arrays and numbers (numba's Dispatcher stub types fewer)
            search: Any = measured_limit.search_kernel
            f64 = np.float64
            wr = np.empty(n)
            search(kernels.arg(st["u0"], f64), kernels.arg(st["e1"], f64),
                   kernels.arg(st["e2"], f64), kernels.arg(self.fa.centre, f64),
                   kernels.arg(self.origin, f64), kernels.arg(wc, f64), kernels.arg(wh, f64),
                   float(half), int(levels), g3, self.w_min, self.w_max, self.s_half,
                   float(self.domain.g_max), *st["ea"].columns(), *st["eb"].columns(), dc,
                   wr)  # fmt: skip
            wc = wr
        else:
            for _ in range(levels):
                dd = dc[:, None, :] + g3[None, :, :2] * half
                ww = np.clip(wc[:, None] + g3[None, :, 2] * wh[:, None], self.w_min, self.w_max)
                b = self._locate(st, self._centres(st, dd, ww), ww)
                dc = dd[np.arange(n), b]
                wc = ww[np.arange(n), b]
                half, wh = half / 2.5, wh / 2.5
        g_lo, g_hi = self._h(st, self._centres(st, dc[:, None, :], wc[:, None]))
        return dc, wc, (g_hi - g_lo)[:, 0] * wc

    def _hb(self, st: dict, x: np.ndarray) -> np.ndarray:
        """H at points x (N, G, 3) = (delta_1, delta_2, beta) (-inf where undefined);
        compiled, where H < -st["slack"] some value below it (the walk over the facets
        stops there). Callers compare it with -st["slack"] only. Compiled: the centre and
        the walk in one loop (kernels.measured_limit.region_kernel, the facet that rules
        a point out tried first for the next); else numpy (:meth:`_bcentres`, :meth:`_h`)."""
        if kernels.use(x.shape[0] * x.shape[1]):
            from eyeviz.core.kernels import measured_limit

            # Any: the kernel takes 24 arrays and numbers (numba's Dispatcher stub types fewer)
            region_kernel: Any = measured_limit.region_kernel
            f64 = np.float64
            h = np.empty(x.shape[:2])
            region_kernel(kernels.arg(x, f64), kernels.arg(st["u0"], f64),
                          kernels.arg(st["e1"], f64), kernels.arg(st["e2"], f64),
                          kernels.arg(self.fa.centre, f64), kernels.arg(self.bhat, f64),
                          self.blen, kernels.arg(self.origin, f64), self.s_half,
                          float(self.domain.g_max), float(st["slack"]),
                          *both_columns(st["ea"], st["eb"]), h)  # fmt: skip
            return h
        c, _, _ = self._bcentres(st, x[..., :2], x[..., 2])
        with np.errstate(invalid="ignore", over="ignore"):
            cc = np.nan_to_num(c, nan=1e300)
            g_lo, g_hi = self._h(st, cc)
        hv = g_hi - g_lo
        return np.where(np.isfinite(hv), hv, -np.inf)

    def provable_box(self, st: dict) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(lo, hi, proven): per key a box in (delta, beta) holding every ball of the
        posterior's support where ``proven`` (:func:`.limit3d_provable.provable_box`)."""
        return limit3d_provable.provable_box(self, st)

    # --- the proposal ----------------------------------------------------------------------
    def setup(self, lit_a: LitCSR, lit_b: LitCSR, keys: np.ndarray, wide: float) -> dict:
        """Each eye's constraining facets, the reference direction and the box of
        directions for a chunk of keys (module docstring steps 1-4)."""
        d = self.domain
        st: dict = {"ea": _Edges(self.fa, lit_a), "eb": _Edges(self.fb, lit_b)}
        st["lit_a"], st["lit_b"] = lit_a, lit_b
        n = lit_a[0].size - 1
        # a first centre: each eye's best direction at infinity, triangulated (or the
        # triangulation estimate where those rays do not meet in front: computed for
        # those keys alone, each key's estimate its own)
        ua, ub = _direction(st["ea"], self.grid), _direction(st["eb"], self.grid)
        p0, ok = triangulate_rays(self.fa.centre, ua, self.fb.centre, ub)
        miss = np.flatnonzero(~ok)
        if miss.size:
            r0, az0, el0, _ = estimate(d, take_rows(*lit_a, miss), take_rows(*lit_b, miss))
            p0[miss] = self.origin + r0[:, None] * np.stack(
                [np.cos(el0) * np.cos(az0), np.cos(el0) * np.sin(az0), np.sin(el0)], axis=1
            )
        u0 = p0 - self.fa.centre
        st["u0"] = u0 / np.linalg.norm(u0, axis=1, keepdims=True)
        st["e1"], st["e2"] = _frame(st["u0"])
        slack = 1e-7 * d.g_max
        st["slack"] = slack
        # the reference: zooming grids over (delta, w) to the maximum of H
        wc = np.clip(1.0 / np.linalg.norm(u0, axis=1), self.w_min, self.w_max)
        wc = np.where(np.isfinite(wc), wc, 0.5 * (self.w_min + self.w_max))
        wh = np.full(n, 0.5 * (self.w_max - self.w_min))
        dc, wr, top = self._search(st, wc, wh, wide * SEARCH * d.gamma, LEVELS)
        bad = np.flatnonzero(~(top >= 0.0))
        pre = self._keys(st, bad) if bad.size and FAR > 0 else None  # facets not yet pruned
        box_lo, box_hi, tight = self._around(st, keys, dc, wr, wide)
        # keys whose reference is not feasible (H < 0 there) and whose box holds no
        # feasible pilot point: the search again, FAR times as wide, and where its point
        # is feasible the box about it (module docstring, step 3)
        if pre is not None:
            lost = np.flatnonzero(tight[2][bad] == 0)
            if lost.size:
                sub = self._keys(pre, lost)
                far = FAR * wide * SEARCH * d.gamma
                dc_f, wc_f, top_f = self._search(sub, wc[bad[lost]], wh[bad[lost]], far,
                                                 LEVELS + FAR_LEVELS)  # fmt: skip
                ok = np.flatnonzero(top_f >= 0.0)
                if ok.size:
                    sub = self._keys(sub, ok)
                    rows = bad[lost[ok]]
                    b_lo, b_hi, t = self._around(sub, keys[rows], dc_f[ok], wc_f[ok], wide)
                    self._put(st, rows, sub)
                    box_lo[rows], box_hi[rows] = b_lo, b_hi
                    for whole, part in zip(tight, t, strict=True):
                        whole[rows] = part
        lo_p, hi_p, proven = self.provable_box(st)
        st["box_lo"], st["box_hi"] = box_lo, box_hi
        self._defend(st, lo_p, hi_p, proven)
        self._mixture(st, *tight)
        return st

    def _around(self, st: dict, keys: np.ndarray, dc: np.ndarray, wc: np.ndarray, wide: float):
        """About the reference (gnomonic offset dc (N, 2) about u0, w = 1 / distance wc):
        the facets pruned there and the box in (delta, beta) (module docstring, steps 3-4),
        as :meth:`_pilot` returns it; sets ``st``'s reference and frame."""
        d, n, slack = self.domain, dc.shape[0], st["slack"]
        ref = self._centres(st, dc[:, None, :], wc[:, None])[:, 0]
        st["ref"] = ref
        st["ea"].prune(ref)
        st["eb"].prune(ref)
        v = ref - self.fa.centre
        st["u0"] = v / np.linalg.norm(v, axis=1, keepdims=True)
        st["e1"], st["e2"] = _frame(st["u0"])
        # the box in (delta, beta): bisection along 26 directions of H >= -slack, the
        # boundary points' box widened, then widened again where a pilot's feasible
        # draws come near a face
        cs = st["u0"] / wc[:, None] - (self.fb.centre - self.fa.centre)
        cb = np.einsum("nj,j->n", cs, -self.bhat) / np.linalg.norm(cs, axis=1)
        st["beta0"] = np.arccos(np.clip(cb, -1.0, 1.0))
        floor = 1e-9 * d.gamma
        if BOX_KERNEL and kernels.use(n * PILOT):
            return self._box_compiled(st, keys, wide * REACH * d.gamma, floor)
        centre = np.stack([np.zeros(n), np.zeros(n), st["beta0"]], axis=1)
        lo = np.zeros((n, _DIRS3.shape[0]))
        hi = np.full((n, _DIRS3.shape[0]), wide * REACH * d.gamma)
        for _ in range(ITERS):
            mid = 0.5 * (lo + hi)
            x = centre[:, None, :] + mid[..., None] * _DIRS3[None]
            inside = self._hb(st, x) >= -slack
            lo = np.where(inside, mid, lo)
            hi = np.where(inside, hi, mid)
        pts = hi[..., None] * _DIRS3[None]  # (N, 26, 3) about the centre
        box_lo = centre + np.minimum(pts.min(axis=1), 0.0) * WIDEN
        box_hi = centre + np.maximum(pts.max(axis=1), 0.0) * WIDEN
        box_lo, box_hi = np.minimum(box_lo, centre - floor), np.maximum(box_hi, centre + floor)
        # the pilot: the box widened where feasible draws come near a face (the defensive
        # share of the draws keeps the estimate unbiased where it still misses a part of
        # the posterior; the pilot keeps that part, and so the weights' spread, small)
        return self._pilot(st, keys, box_lo, box_hi)

    def _box_compiled(self, st: dict, keys: np.ndarray, reach: float, floor: float):
        """:meth:`_around`'s bisection, widening and :meth:`_pilot` in one call
        (kernels.measured_limit.box_kernel, key by key; the same arithmetic and verdicts
        as the numpy loops with the compiled region test, so the same boxes bit for bit)."""
        from eyeviz.core.kernels import measured_limit

        # Any: the kernel takes 29 arrays and numbers (numba's Dispatcher stub types fewer)
        box_kernel: Any = measured_limit.box_kernel
        n, f64 = keys.size, np.float64
        box_lo, box_hi = np.empty((n, 3)), np.empty((n, 3))
        t_lo, t_hi, t_n = np.empty((n, 3)), np.empty((n, 3)), np.empty(n, np.int64)
        box_kernel(kernels.arg(st["u0"], f64), kernels.arg(st["e1"], f64),
                   kernels.arg(st["e2"], f64), kernels.arg(self.fa.centre, f64),
                   kernels.arg(self.bhat, f64), self.blen, kernels.arg(self.origin, f64),
                   self.s_half, float(self.domain.g_max), float(st["slack"]),
                   *both_columns(st["ea"], st["eb"]), kernels.arg(st["beta0"], f64),
                   float(reach), WIDEN, float(floor), _DIRS3, ITERS,
                   _uniforms(keys, PILOT, 3, 7), PILOT_ROUNDS, box_lo, box_hi, t_lo, t_hi,
                   t_n)  # fmt: skip
        return box_lo, box_hi, (t_lo, t_hi, t_n)

    def _pilot(self, st: dict, keys: np.ndarray, box_lo: np.ndarray, box_hi: np.ndarray):
        """The box widened by half on each face near which a pilot's feasible draws fall,
        ``PILOT`` draws, up to ``PILOT_ROUNDS`` times; and the box of each key's last
        round's feasible draws (lo, hi, their number). A round tries only the keys whose
        box the last one widened (the others' draws and verdicts would be the same)."""
        slack = st["slack"]
        up = _uniforms(keys, PILOT, 3, 7)
        n = box_lo.shape[0]
        box_lo, box_hi = box_lo.copy(), box_hi.copy()
        t_lo, t_hi = np.full((n, 3), np.inf), np.full((n, 3), -np.inf)
        t_n = np.zeros(n, np.int64)
        live = np.arange(n)
        for _ in range(PILOT_ROUNDS):
            lo, hi = box_lo[live], box_hi[live]
            x = lo[:, None] + (hi - lo)[:, None] * up[live]
            sub = st if live.size == n else self._keys(st, live)
            # the feasible points alone (a few per cent of them): their box, number and
            # whether any lies within a tenth of the box's extent of a face
            row, col = np.nonzero(self._hb(sub, x) >= -slack)
            xs = x[row, col]
            m = live.size
            low, high = np.full((m, 3), np.inf), np.full((m, 3), -np.inf)
            np.minimum.at(low, row, xs)
            np.maximum.at(high, row, xs)
            t_lo[live], t_hi[live] = low, high
            t_n[live] = np.bincount(row, minlength=m)
            band = 0.1 * (hi - lo)
            near_lo, near_hi = np.zeros((m, 3), bool), np.zeros((m, 3), bool)
            np.logical_or.at(near_lo, row, xs < (lo + band)[row])
            np.logical_or.at(near_hi, row, xs > (hi - band)[row])
            grow = near_lo.any(axis=1) | near_hi.any(axis=1)
            if not grow.any():
                break
            span = hi - lo
            box_lo[live] = np.where(near_lo, lo - 0.5 * span, lo)
            box_hi[live] = np.where(near_hi, hi + 0.5 * span, hi)
            live = live[grow]
        return box_lo, box_hi, (t_lo, t_hi, t_n)

    def _keys(self, st: dict, idx: np.ndarray) -> dict:
        """The state of the chunk's keys ``idx`` alone."""
        n = st["u0"].shape[0]
        sub = {k: (v.take(idx) if isinstance(v, _Edges) else v[idx] if
                   isinstance(v, np.ndarray) and v.ndim and v.shape[0] == n else v)
               for k, v in st.items()}  # fmt: skip
        for name in ("lit_a", "lit_b"):
            if name in st:
                ptr, ind = st[name]
                sub[name] = take_rows(ptr, ind, idx)
        return sub

    def _put(self, st: dict, rows: np.ndarray, sub: dict) -> None:
        """The chunk's keys ``rows`` of ``st`` replaced by the state ``sub`` of those keys
        (the facets' tables padded to the wider)."""
        n = st["u0"].shape[0]
        for k, v in sub.items():
            if isinstance(v, _Edges):
                st[k].put(rows, v)
            elif isinstance(v, np.ndarray) and v.ndim and st[k].shape[0] == n and k[:3] != "lit":
                st[k][rows] = v

    def _defend(self, st: dict, lo, hi, proven) -> None:
        """The defensive box of each key's proposal (module docstring, step 5): where the
        provable box (lo, hi) holds (``proven``), the first ``DEFEND`` of each batch's
        draws come from it and the box is cut to it; where the bisection found no
        feasible point about the reference (the box at its floor), every draw."""
        box_lo, box_hi = st["box_lo"], st["box_hi"]
        cut_lo, cut_hi = np.maximum(box_lo, lo), np.minimum(box_hi, hi)
        # the box's part in the provable box: nothing feasible lies outside it
        lost = ((box_hi - box_lo) <= 2.5e-9 * self.domain.gamma).all(axis=1)
        lost |= ~(cut_hi > cut_lo).all(axis=1)
        n_def = np.where(proven, np.where(lost, self.samples, int(DEFEND * self.samples)), 0)
        cut = (proven & ~lost)[:, None]
        st["box_lo"] = np.where(cut, cut_lo, box_lo)
        st["box_hi"] = np.where(cut, cut_hi, box_hi)
        st["def_lo"] = np.where(proven[:, None], lo, box_lo)
        st["def_hi"] = np.where(proven[:, None], hi, box_hi)
        st["n_def"] = n_def.astype(np.int64)
        st["proven"] = proven

    def _mixture(self, st: dict, t_lo: np.ndarray, t_hi: np.ndarray, t_n: np.ndarray) -> None:
        """The tight box of each key's mixture (module docstring, step 5): the pilot's
        feasible points' box (t_lo, t_hi) widened ``TIGHT_WIDEN`` times and cut to the
        box, ``TIGHT`` of each batch's draws where it has ``TIGHT_MIN`` points or more and
        the key is not drawn from the defensive box alone (:meth:`_boxes`)."""
        lo, hi = st["box_lo"], st["box_hi"]
        with np.errstate(invalid="ignore"):  # no feasible point: inf - inf
            mid, half = 0.5 * (t_lo + t_hi), 0.5 * TIGHT_WIDEN * (t_hi - t_lo)
            tl, th = np.maximum(mid - half, lo), np.minimum(mid + half, hi)
            ok = (t_n >= TIGHT_MIN) & (th > tl).all(axis=1) & (st["n_def"] < self.samples)
        st["tight_lo"] = np.where(ok[:, None], tl, lo)
        st["tight_hi"] = np.where(ok[:, None], th, hi)
        st["n_tight"] = np.where(ok, int(TIGHT * self.samples), 0).astype(np.int64)

    def _boxes(self, st: dict) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Each key's mixture: boxes (N, 3, 2, 3) (lo, hi) and each batch's draws from
        them in turn, counts (N, 3): the defensive box's ``n_def``, the tight box's
        ``n_tight`` (at most the rest), the rest from the box; dens = share / volume."""
        m = self.samples
        n_def = st["n_def"]
        n_t = np.minimum(st.get("n_tight", 0 * n_def), m - n_def)
        counts = np.stack([n_def, n_t, m - n_def - n_t], axis=1).astype(np.int64)
        t_lo, t_hi = st.get("tight_lo", st["box_lo"]), st.get("tight_hi", st["box_hi"])
        boxes = np.stack([np.stack([st["def_lo"], st["def_hi"]], 1), np.stack([t_lo, t_hi], 1),
                          np.stack([st["box_lo"], st["box_hi"]], 1)], axis=1)  # fmt: skip
        with np.errstate(divide="ignore"):
            dens = counts / m / np.prod(boxes[:, :, 1] - boxes[:, :, 0], axis=2)
        return boxes, counts, np.where(counts > 0, dens, 0.0)

    #: limit3d's top-ups may draw each key its own batches (:meth:`sample_counts`)
    batch_counts = True
