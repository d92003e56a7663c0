"""The information limit of the spherical eyes: the posterior under the 3D Algorithm 1 prior.

The likelihood of a ball (x, y, z, g) given a key (the two eyes' lit sets) is 0/1: 1
exactly when ``EyePair3D.lit_csr`` of the ball gives both lit sets (docs/spherical.md,
3D Proposition 2). The posterior is the prior of :mod:`eyeviz.dataset.algorithm1_3d`
restricted to those balls. In (r, g, el, az) the single-pass prior's density is

    1 / (g_max - r sin(gamma/2)) * 1 / (pi - 2 az0(r, g, el))

on r in [r_min, r_max], g in [r sin(gamma/2), g_max], |el| <= el_max, az in
[az0, pi - az0] with cos(az0) = cos(psi + asin(g/r)) / cos(el) (steps 7-12; its
rejections, the 3D field test and Definition 1, only restrict the support). The multi-pass
prior has r^2 cos(el) / (g_max - r sin(gamma/2)) / (pi - 2 az0(r, g, el_max)) (its
segment quotas are treated as the r^2 density they approximate). In (x, y, z, g) both
gain the Jacobian 1 / (r^2 cos el).

**Proposal (importance sampling).** The posterior's support is a sliver: at nside 180 a
ball lighting 1,000 facets per eye is pinned to about a hundredth of a facet in
direction. So the proposal is built from each eye's feasible caps, as the planar limit
integrates over eye A's tangent sectors and then along the ray (:mod:`.limit`):

1. Per eye, the cells where the cap's edge can lie: the key's lit cells that a cap
   ``EDGE`` facet widths (:mod:`.limit3d_proposal`) smaller than the lit set's cap
   (:func:`.analytic3d.cap_estimates`)
   does not light, and the unlit cells a cap as much larger lights. For each, its
   boundary point nearest the cap centre (``STEP`` points per edge) linearises its
   distance to a cap centre c near the estimate: dist(c) ~ d - t . delta (delta: c in
   gnomonic coordinates about the estimate). The cap (c, alpha) lights exactly the key's
   cells only if alpha > dist for every lit edge cell and alpha <= dist for every unlit
   one, so the feasible centres are where G(delta) = min_unlit - max_lit > 0 (concave),
   and alpha lies in (max_lit, min_unlit] there. Both are affine forms in delta (the
   unlit distances squared), one product and one reduction per evaluation.
2. Per eye: G on a grid about the estimate, the centre moved to its best point and the
   distances modelled again there (zooming grids); the box holding every centre with
   G >= -slack (bisection along ``NDIR`` directions). The slack is the search window's
   (0.002 facet widths) or, for a box far smaller than the window (a thin posterior),
   ``SLACK_SAFETY`` times the model's second-order error in the box, R^2 (1/alpha + 1).
3. Eye A's centre: uniform in (theta, phi) over the bounds of A's box, theta = atan2(z, y)
   (the angle of the plane through the baseline) cut to the bounds of B's box: a ball's
   centre and both caps' centres share one theta, so B bounds it too. Draws outside A's
   box are dropped (the model region lies in it).
4. Along the ray A + c_A / u the directions from B, c_A + (A - B) u, span a great circle,
   a line in B's gnomonic coordinates: the u where it lies in B's box is exact (each side
   linear in u), then narrowed to B's region G_B >= -slack (concave along the line: a
   grid, kept from the point before the first inside to the one after the last). u is
   uniform there; then g uniform where both eyes' modelled radii and the prior's g range
   allow it: rho_A sin[max_lit_A - slack, min_unlit_A + slack] intersected with B's.
5. A necessary condition on the edge cells' boundary samples (their true distances, the
   sampling gap bounded: :func:`_prefilter`) drops most draws that cannot match; the rest
   are checked exactly with ``EyePair3D.lit_csr`` (0/1 likelihood), against the prior's
   support and the exact field test ``in_bfv``, and weighted by prior x rho^4 sin(phi)
   (d(x, y, z, g) / d(u, theta, phi, g)) / the proposal's density (uniform in each box).

The slacks make the proposal's support cover the posterior's (the tests compare with
brute-force rejection sampling from the prior at nside 4), and the exact check makes the
likelihood exact whatever the linearisation's error; the price of a loose proposal is
fewer accepted samples, not bias. A key whose Monte-Carlo error of r exceeds
``MC_TARGET``, or whose effective sample size is below ``MIN_ESS``, gets ``TOPUP`` more
batches of draws. A key with no accepted sample is
drawn again, more times (``RETRY``: its posterior is a small part of the proposal; more
draws find it where wider windows did not); a key still empty is answered by the analytic
triangulation and ``flagged``.

**Estimates.** MAPE-optimal (Eq. 34): the 1/r-weighted posterior median of r and the
1/az-weighted median of the azimuth; the elevation crosses 0, where a relative error is
undefined, so its estimate is the posterior median (optimal for its mean absolute error).
Monte-Carlo error per key: ``mc_error`` (relative standard error of r's estimate,
1.2533 sd_w(r) / sqrt(ESS) / r, ESS = (sum w)^2 / sum w^2) and ``n_accepted`` travel with
the prediction. Draws are a function of the key alone (a counter-based hash of its lit
sets), so a row's answer never depends on the other rows.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from eyeviz.core.domain3d import PAPER_DOMAIN3D, Domain3D
from eyeviz.estimators.analytic3d import estimate
from eyeviz.estimators.base3d import Estimator3D, LitCSR, Prediction3D, as_csr, take_rows
from eyeviz.estimators.limit3d_proposal import (
    _angle_box,
    _extent,
    _Eye,
    _key_hash,
    _locate,
    _prefilter,
    _ray_in_box,
    _ray_in_region,
    _uniforms,
)
from eyeviz.estimators.weighted import weighted_median

__all__ = ["PRIORS", "Limit3DEstimator", "load", "posterior_samples3d", "prior_density"]

PRIORS = ("single", "multi")
#: the retries of keys with no accepted draw: (window and slack factor, batches of draws)
RETRY = ((1.0, 8), (2.5, 24), (1.0, 96))
#: facet widths the centre search may move: edge cells that cannot bind within them are
#: dropped before it
PRUNE = 0.25
#: zoom levels of the search for the centre (each grid a third as wide)
LEVELS = 4
#: grid points and rounds of the search along the ray for B's region
RAY_GRID = 8
RAY_ROUNDS = 2
#: the Monte-Carlo error of r a key's draws are topped up to (at most TOPUP more batches)
MC_TARGET = 0.01
TOPUP = 1
#: a key whose effective sample size is below this is topped up too (one or two accepted
#: draws give a Monte-Carlo error of 0 or none at all, not a small one)
MIN_ESS = 4.0
#: the largest ``samples`` and ``grid`` a Limit3DEstimator takes
MAX_SAMPLES = 1 << 14
MAX_GRID = 64
#: the per-key slack: this many times the model's second-order error in the box
SLACK_SAFETY = 4.0
#: keys processed together
_CHUNK = 8
#: The most facets per eye a key may light and still be sampled: each exact check of a
#: draw costs about its lit count, and a draw is checked up to (1 + TOPUP + sum of
#: RETRY's batches) x samples times. A key beyond it, or beyond what any ball of the
#: domain can light (:func:`max_lit`), gets no draws: its posterior is empty (or too
#: costly to find) and it is answered by analytic3d and flagged (issue 35: a row lighting
#: the whole eye took 33 s).
MAX_KEY_LIT = 1 << 20


def max_lit(domain: Domain3D) -> int:
    """An upper bound on the facets one eye of ``domain`` sees lit by any ball of its
    prior: the cap's half-angle is at most asin(g_max / (r_min - h)) (the ball's centre
    lies r_min or more from the origin, so r_min - h or more from an eye; pi/2 when that
    is not positive), its area a fraction (1 - cos alpha) / 2 of the sphere, and the cells
    on its rim at most 8 per facet width of its perimeter (generous: HEALPix cells are
    within a factor ~2 of square), plus 16."""
    d = domain
    near = d.r_min - d.h
    alpha = math.pi / 2 if near <= d.g_max else math.asin(d.g_max / near)
    fw = math.sqrt(4 * math.pi / d.npix)
    bound = d.npix * (1 - math.cos(alpha)) / 2 + 8 * 2 * math.pi * math.sin(alpha) / fw + 16
    return int(min(d.npix, math.ceil(bound)))


def prior_density(domain: Domain3D, prior: str, r, g, el, az) -> np.ndarray:
    """The prior density of Algorithm 1 in 3D in (x, y, z, g), up to a constant, at balls
    of centre (r, az, el) and radius g (0 outside its support; the field test and
    Definition 1 are not applied here)."""
    d = domain
    s = math.sin(d.gamma / 2)
    with np.errstate(invalid="ignore", divide="ignore"):
        a = np.arcsin(np.minimum(g / r, 1.0))
        cone = d.psi + a
        ok = (r >= d.r_min) & (r <= d.r_max) & (g >= r * s) & (g <= d.g_max) & (g <= r)
        ok &= (cone < math.pi / 2) & (np.abs(el) <= d.el_max)
        cel = np.cos(el)
        if prior == "multi":
            az0 = np.arccos(np.minimum(np.cos(cone) / math.cos(d.el_max), 1.0))
            dens = r * r * cel
        else:
            az0 = np.arccos(np.minimum(np.cos(cone) / cel, 1.0))
            dens = np.ones_like(r)
        ok &= (az >= az0) & (az <= math.pi - az0)
        dens = dens / ((d.g_max - r * s) * (math.pi - 2 * az0) * r * r * cel)
    return np.where(ok & np.isfinite(dens), dens, 0.0)


# --- counter-based uniforms: a function of the key and the draw's number -----------------


# --- one eye's edge cells ------------------------------------------------------------------


class Limit3DEstimator(Estimator3D):
    """The MAPE-optimal answers of the 3D posterior, by importance sampling with the exact
    0/1 likelihood (module docstring); any design, no weights.

    Predictions carry ``flagged`` (empty posterior: answered by analytic3d),
    ``mc_error`` (relative standard error of r's estimate; NaN where flagged) and
    ``n_accepted`` (samples that reproduce both lit sets)."""

    name = "limit3d"

    def __init__(
        self,
        domain: Domain3D = PAPER_DOMAIN3D,
        prior: str = "single",
        samples: int = 256,
        grid: int = 8,
        seed: int = 0,
    ) -> None:
        if prior not in PRIORS:
            raise ValueError(f"prior must be one of {PRIORS}, got {prior!r}")
        # bounded so that one chunk's draws and grid fit in memory
        for name, v, lo, hi in (("samples", samples, 4, MAX_SAMPLES), ("grid", grid, 4, MAX_GRID)):
            if not isinstance(v, int | np.integer) or isinstance(v, bool) or not lo <= v <= hi:
                raise ValueError(f"{name} must be an integer >= {lo} and <= {hi}, got {v!r}")
        # the seed is xor-ed into the keys' uint64 hashes
        if (
            not isinstance(seed, int | np.integer)
            or isinstance(seed, bool)
            or not 0 <= seed < 2**64
        ):
            raise ValueError(f"seed must be an integer >= 0 and < 2^64, got {seed!r}")
        super().__init__(domain, {"n_weights": 0, "train_seconds": 0.0, "prior": prior})
        self.prior = prior
        self.samples = int(samples)
        self.grid = int(grid)
        self.seed = int(seed)
        self.last_mc_error: np.ndarray = np.zeros(0)
        self.last_accepted: np.ndarray = np.zeros(0, np.int64)

    # --- the posterior of a chunk of keys ------------------------------------------------
    def _draw(
        self,
        lit_a: LitCSR,
        lit_b: LitCSR,
        keys: np.ndarray,
        wide: float,
        stream: int,
        reps: int = 1,
    ) -> dict[str, np.ndarray]:
        """Weighted posterior samples of a chunk: dict of (N, reps * samples) arrays (the
        proposal set up once, ``reps`` batches of draws)."""
        d = self.domain
        fw = math.sqrt(4 * math.pi / d.npix)
        A = np.array([-d.h, 0.0, 0.0])
        B = np.array([d.h, 0.0, 0.0])
        ea = _Eye(d, lit_a, A, 0)
        eb = _Eye(d, lit_b, B, 1)
        n = ea.c.shape[0]
        m = self.samples
        ng = self.grid
        slack0 = wide * 0.002 * fw
        for e in (ea, eb):
            e.prune(np.full(n, PRUNE * wide * fw))
            _locate(e, 0.25 * wide * fw, ng, LEVELS)
        ext = _extent(ea, wide * 0.5 * fw, slack0)
        eb.a = A - B
        ext_b = _extent(eb, wide * 0.5 * fw, slack0)
        # within a box of radius R the model's distances are off by second-order terms,
        # below R^2 (1 / alpha + 1) / 2: a thin posterior (a box far smaller than the
        # search window) needs a slack far below the window's, or the proposal is
        # mostly slack (keys with a tiny posterior found nothing in 10^4 draws)
        sec = np.zeros(n)
        for e, x in ((ea, ext), (eb, ext_b)):
            sec = np.maximum(sec, (x * x).sum(axis=1) * (1.0 / e.alpha0 + 1.0))
        slack = np.minimum(slack0, wide * (SLACK_SAFETY * sec + 1e-7 * fw))[:, None]
        ext = _extent(ea, wide * 0.5 * fw, slack)
        ext_b = _extent(eb, wide * 0.5 * fw, slack)
        ea.prune(1.2 * math.sqrt(2.0) * ext.max(axis=1))
        eb.prune(1.2 * math.sqrt(2.0) * ext_b.max(axis=1))
        # A's centre: uniform in (theta, phi) over the bounds of A's box, theta cut to
        # those of B's box (both caps' centres share the ball's theta: B's box bounds it)
        box = _angle_box(ea, ext)
        box_b = _angle_box(eb, ext_b)
        th_lo = np.fmax(box[:, 0], box_b[:, 0])
        th_hi = np.fmin(box[:, 1], box_b[:, 1])
        st = dict(d=d, A=A, B=B, ea=ea, eb=eb, n=n, m=m, slack=slack, ext=ext, ext_b=ext_b,
                  box=box, th_lo=th_lo, th_hi=th_hi, lit_a=lit_a, lit_b=lit_b)  # fmt: skip
        parts = [self._sample(st, keys, stream + 8 * rep) for rep in range(reps)]
        out = {k: np.concatenate([q[k] for q in parts], axis=1) for k in parts[0]}
        if reps > 1:
            return out
        # top-ups: a key with too few or too spread draws (_needs_more) gets another batch
        # (its own stream; the other keys' draws are left as they are)
        for rep in range(1, 1 + TOPUP):
            need = _needs_more(out["r"], out["w"])
            if not need.any():
                break
            more = self._sample(st, keys, stream + 8 * rep)
            more["w"] = np.where(need[:, None], more["w"], 0.0)
            out = {k: np.concatenate([out[k], more[k]], axis=1) for k in out}
        if out["w"].shape[1] > m:  # the accepted draws first, in draw order
            order = np.argsort(~(out["w"] > 0), axis=1, kind="stable")[:, :m]
            out = {k: np.take_along_axis(v, order, 1) for k, v in out.items()}
        return out

    # long: the weighted draws of one chunk (propose, test the key, weigh) in one pass over shared
    # arrays
    def _sample(self, st: dict, keys: np.ndarray, stream: int) -> dict[str, np.ndarray]:
        """``samples`` weighted draws per key of a chunk set up by :meth:`_draw`."""
        d, A, B, ea, eb = st["d"], st["A"], st["B"], st["ea"], st["eb"]
        n, m, slack, ext, ext_b = st["n"], st["m"], st["slack"], st["ext"], st["ext_b"]
        box, th_lo, th_hi = st["box"], st["th_lo"], st["th_hi"]
        lit_a, lit_b = st["lit_a"], st["lit_b"]
        u = _uniforms(keys, m, 4, stream)
        th = th_lo[:, None] + (th_hi - th_lo)[:, None] * u[..., 0]
        ph = box[:, 2:3] + (box[:, 3] - box[:, 2])[:, None] * u[..., 1]
        sp = np.sin(ph)
        ca = np.stack([np.cos(ph), sp * np.cos(th), sp * np.sin(th)], axis=-1)
        good = np.broadcast_to(((th_hi > th_lo) & (box[:, 3] > box[:, 2]))[:, None], (n, m))
        with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
            delta = ea.gnomonic(np.where(good[..., None], ca, ea.c[:, None, :]))
        # outside A's box the model region is empty: drawn, then dropped
        good = good & (np.abs(delta) <= ext[:, None, :]).all(axis=2)
        delta = np.where(good[..., None], delta, 0.0)
        ca = np.where(good[..., None], ca, ea.c[:, None, :])
        lo_a, hi_a = ea.bounds(delta)
        good = good & (hi_a - lo_a > -2.0 * slack)
        # along the ray A + c_A / u: u where B's view of it lies in B's box (the
        # directions from B, c_A + u (A - B), span a great circle: a line in B's
        # gnomonic coordinates, and each side of the box is linear in u), then in B's
        # modelled region; on the live draws only (moved to the front of each row)
        u_lo, u_hi = _ray_in_box(eb, ca, ext_b)
        u_lo = np.maximum(u_lo, 1.0 / (d.r_max + d.h))
        if d.r_min > d.h:
            u_hi = np.minimum(u_hi, 1.0 / (d.r_min - d.h))
        good = good & (u_hi > u_lo)
        order = np.argsort(~good, axis=1, kind="stable")[:, : max(1, int(good.sum(1).max()))]
        sel = np.take_along_axis(good, order, 1)

        def pick(x: np.ndarray) -> np.ndarray:
            return np.take_along_axis(x, order if x.ndim == 2 else order[..., None], 1)

        c_lo = np.where(sel, pick(u_lo), 1.0 / d.r_max)
        c_hi = np.where(sel, pick(u_hi), 1.0 / d.r_max)
        c_lo, c_hi = _ray_in_region(eb, pick(ca), c_lo, c_hi, slack, RAY_GRID, RAY_ROUNDS)
        rows = np.arange(n)[:, None]
        u_lo, u_hi = u_lo.copy(), u_hi.copy()
        u_lo[rows, order] = c_lo
        u_hi[rows, order] = c_hi
        u_lo = np.where(good, u_lo, 1.0 / d.r_max)
        u_hi = np.where(good, u_hi, 1.0 / d.r_max)
        uu = u_lo + (u_hi - u_lo) * u[..., 2]
        uu = np.where(good, uu, 1.0 / d.r_max)
        rho = 1.0 / uu
        p = A + rho[..., None] * ca
        r = np.linalg.norm(p, axis=2)
        vb = p - B
        rho_b = np.linalg.norm(vb, axis=2)
        # g: uniform where both eyes' modelled cap radii allow it (and the prior's g range)
        lo_b, hi_b = eb.bounds(eb.gnomonic(vb / rho_b[..., None]))
        g_lo, g_hi = r * math.sin(d.gamma / 2), np.full_like(r, d.g_max)
        for lo_e, hi_e, rh in ((lo_a, hi_a, rho), (lo_b, hi_b, rho_b)):
            g_lo = np.maximum(g_lo, rh * np.sin(np.clip(lo_e - slack, 0.0, math.pi / 2)))
            g_hi = np.minimum(g_hi, rh * np.sin(np.clip(hi_e + slack, 0.0, math.pi / 2)))
        good = good & (g_hi > g_lo)
        gg = g_lo + (g_hi - g_lo) * u[..., 3]
        el = np.arcsin(np.clip(p[..., 2] / r, -1, 1))
        az = np.arctan2(p[..., 1], p[..., 0])
        alpha = np.arcsin(np.clip(gg / rho, 0.0, 1.0))
        # d(x, y, z, g) = rho^4 sin(phi) d(u, theta, phi, g); 1 / q = the boxes' volume
        with np.errstate(over="ignore", invalid="ignore"):
            vol = (th_hi - th_lo)[:, None] * (box[:, 3] - box[:, 2])[:, None]
            vol = vol * (u_hi - u_lo) * (g_hi - g_lo)
            w = prior_density(d, self.prior, r, gg, el, az) * rho**4 * sp * vol
        w = np.where(good & np.isfinite(w), w, 0.0)
        # the exact 0/1 likelihood on the draws with prior mass
        cand = np.flatnonzero(w.ravel() > 0)
        hit = np.zeros(n * m, bool)
        if cand.size:  # a cheap necessary condition first
            row = cand // m
            pc = p.reshape(-1, 3)[cand]
            pb_ = pc - B
            rb = np.linalg.norm(pb_, axis=1)
            keep = _prefilter(ea, row, ca.reshape(-1, 3)[cand], alpha.ravel()[cand])
            cand, row, pb_, rb = cand[keep], row[keep], pb_[keep], rb[keep]
            sin_b = np.minimum(gg.ravel()[cand] / rb, 1.0)
            keep = _prefilter(eb, row, pb_ / rb[:, None], np.arcsin(sin_b))
            cand = cand[keep]
        if cand.size:
            x, y, z = (p.reshape(-1, 3)[cand, i] for i in range(3))
            gc = gg.ravel()[cand]
            inb = d.eyes.in_bfv(x, y, z, gc)
            (pa, ia), (pb, ib) = d.eyes.lit_csr(x, y, z, gc)
            row = cand // m
            match = inb & _same(pa, ia, lit_a, row) & _same(pb, ib, lit_b, row)
            hit[cand] = match
        w = np.where(hit.reshape(n, m), w, 0.0)
        return {"r": r, "az": az, "el": el, "g": gg, "x": p[..., 0], "y": p[..., 1],
                "z": p[..., 2], "w": w}  # fmt: skip

    def _posterior(self, lit_a: LitCSR, lit_b: LitCSR):
        keys = _key_hash(lit_a, lit_b) ^ np.uint64(self.seed)
        s = self._draw(lit_a, lit_b, keys, 1.0, 0)
        m = self.samples
        for stream, (wide, reps) in enumerate(RETRY, start=1):
            few = np.flatnonzero(~(s["w"].sum(axis=1) > 0))
            if not few.size:
                break
            # keys with nothing accepted: their posterior is a small part of the proposal
            # (the misses are found with more draws, not with wider windows): ``reps``
            # times the draws, the window and slack ``wide`` times wider; the accepted
            # draws kept, the first ``samples`` of them in draw order
            sub_a, sub_b = take_rows(*lit_a, few), take_rows(*lit_b, few)
            s2 = self._draw(sub_a, sub_b, keys[few], wide, stream, reps)
            order = np.argsort(~(s2["w"] > 0), axis=1, kind="stable")[:, :m]
            for k in s:
                s[k][few] = np.take_along_axis(s2[k], order, 1)
        return s

    def _predict_csr(self, lit_a: LitCSR, lit_b: LitCSR):
        n = lit_a[0].size - 1
        r = np.empty(n)
        az = np.empty(n)
        el = np.empty(n)
        empty = np.zeros(n, bool)
        mc = np.full(n, np.nan)
        acc = np.zeros(n, np.int64)
        # keys no ball of the domain lights, or too costly to sample: no draws (flagged)
        most = min(MAX_KEY_LIT, max_lit(self.domain))
        over = (np.diff(lit_a[0]) > most) | (np.diff(lit_b[0]) > most)
        empty |= over
        live = np.flatnonzero(~over)
        for s0 in range(0, live.size, _CHUNK):
            rows = live[s0 : s0 + _CHUNK]
            la, lb = take_rows(*lit_a, rows), take_rows(*lit_b, rows)
            sm = self._posterior(la, lb)
            w = sm["w"]
            tot = w.sum(axis=1)
            e = ~(tot > 0)
            with np.errstate(invalid="ignore", divide="ignore"):
                rr = weighted_median(sm["r"], w / sm["r"])
                aa = weighted_median(sm["az"], w / sm["az"])
                ee = weighted_median(sm["el"], w)
                _, sd, ess = _spread(sm["r"], w)
                mc[rows] = np.where(e, np.nan, 1.2533 * sd / np.sqrt(ess) / rr)
            r[rows], az[rows], el[rows] = rr, aa, ee
            empty[rows] = e
            acc[rows] = (w > 0).sum(axis=1)
        if empty.any():
            idx = np.flatnonzero(empty)
            fr, fa, fe, _ = estimate(self.domain, take_rows(*lit_a, idx), take_rows(*lit_b, idx))
            r[idx], az[idx], el[idx] = fr, fa, fe
        self._mc_parts.append(mc)
        self._acc_parts.append(acc)
        return r, az, el, empty

    def predict(self, lit_a, lit_b) -> Prediction3D:
        """As :meth:`Estimator3D.predict`, plus ``mc_error`` and ``n_accepted`` (also in
        :attr:`last_mc_error`, :attr:`last_accepted`); NaN / 0 on invalid rows."""
        self._mc_parts: list[np.ndarray] = []
        self._acc_parts: list[np.ndarray] = []
        p: Any = super().predict(lit_a, lit_b)
        valid = np.atleast_1d(p.valid)
        mc = np.full(valid.shape, np.nan)
        acc = np.zeros(valid.shape, np.int64)
        if self._mc_parts:
            mc[valid] = np.concatenate(self._mc_parts)
            acc[valid] = np.concatenate(self._acc_parts)
        scalar = np.ndim(p.valid) == 0
        p.mc_error = mc[0] if scalar else mc
        p.n_accepted = acc[0] if scalar else acc
        self.last_mc_error, self.last_accepted = mc, acc
        return p

    def __repr__(self) -> str:
        d = self.domain
        return (
            f"<Limit3DEstimator h={d.h:g} l={d.l:g} nside={d.nside} r=[{d.r_min:g}, "
            f"{d.r_max:g}] g_max={d.g_max:g} el_max={d.el_max:g} prior={self.prior}>"
        )


def _spread(r: np.ndarray, w: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per row of weighted draws: the weighted mean and standard deviation of r and the
    effective sample size ESS = (sum w)^2 / sum w^2 (NaN where nothing is accepted)."""
    tot = w.sum(axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        wn = w / tot[:, None]
        mean = (wn * r).sum(axis=1)
        sd = np.sqrt(np.maximum((wn * (r - mean[:, None]) ** 2).sum(axis=1), 0.0))
        ess = tot**2 / (w**2).sum(axis=1)
    return mean, sd, ess


def _needs_more(r: np.ndarray, w: np.ndarray) -> np.ndarray:
    """The keys to top up: the relative Monte-Carlo error of r, 1.2533 sd_w(r) / sqrt(ESS)
    / mean_w(r), above ``MC_TARGET``, or an ESS below ``MIN_ESS`` (one or two accepted
    draws give an error of 0 or none at all, not a small one), or nothing accepted."""
    mean, sd, ess = _spread(r, w)
    with np.errstate(invalid="ignore", divide="ignore"):
        mc = 1.2533 * sd / np.sqrt(ess) / mean
    return ~(ess >= MIN_ESS) | ~(mc <= MC_TARGET)


def _same(ptr: np.ndarray, ind: np.ndarray, key: LitCSR, row: np.ndarray) -> np.ndarray:
    """Whether each CSR row i of (ptr, ind) equals the key's row ``row[i]``."""
    kp, ki = key
    cnt = np.diff(ptr)
    kc = np.diff(kp)[row]
    same = cnt == kc
    sel = np.flatnonzero(same & (cnt > 0))
    if sel.size:
        lens = cnt[sel]
        starts = ptr[sel]
        kstarts = kp[row[sel]]
        off = np.arange(int(lens.sum())) - np.repeat(np.cumsum(lens) - lens, lens)
        a = ind[np.repeat(starts, lens) + off]
        b = ki[np.repeat(kstarts, lens) + off]
        bad = np.add.reduceat((a != b).astype(np.int64), np.cumsum(lens) - lens)
        same[sel] = bad == 0
    return same


def posterior_samples3d(est: Limit3DEstimator, lit_a, lit_b) -> dict[str, np.ndarray]:
    """The weighted posterior samples of one key (lit sets as sorted index arrays):
    ``x, y, z, g, r, azimuth, elevation, weight`` (weights sum to 1; empty arrays when no
    sample reproduced the key), for the app's point cloud."""
    a = np.asarray(lit_a, np.int64)
    b = np.asarray(lit_b, np.int64)
    ptr_a = np.array([0, a.size])
    ptr_b = np.array([0, b.size])
    la = as_csr("lit_a", (ptr_a, a), est.domain.npix)[:2]
    lb = as_csr("lit_b", (ptr_b, b), est.domain.npix)[:2]
    s = est._posterior(la, lb)
    w = s["w"][0]
    keep = w > 0
    tot = w.sum()
    return {
        "x": s["x"][0][keep],
        "y": s["y"][0][keep],
        "z": s["z"][0][keep],
        "g": s["g"][0][keep],
        "r": s["r"][0][keep],
        "azimuth": s["az"][0][keep],
        "elevation": s["el"][0][keep],
        "weight": w[keep] / tot if tot > 0 else w[keep],
    }


def load(domain: Domain3D | None = None, prior: str = "single", **kw) -> Limit3DEstimator:
    """The limit for ``domain`` (default the paper's design at nside 180)."""
    return Limit3DEstimator(PAPER_DOMAIN3D if domain is None else domain, prior, **kw)
