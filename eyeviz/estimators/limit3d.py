"""The information limit of the spherical eyes: the posterior under the 3D Algorithm 1 prior.

One estimator for every eye model of the spherical side: the prior, the retries and
top-ups, the estimates and their Monte-Carlo errors are here; the proposal is the
model's own (HEALPix cells: :mod:`.limit3d_healpix`, the construction below; measured
facets' acceptance cones: :mod:`.limit3d_measured`); both check every draw exactly with
the pair's ``lit_csr`` and ``in_bfv`` (:mod:`.limit3d_exact`).

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
   ``EDGE`` facet widths (:mod:`.limit3d_eye`) smaller than the lit set's cap
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
``accuracy`` (default ``MC_TARGET``), or whose effective sample size is below ``MIN_ESS``,
gets more batches of draws until it is not, at most ``max_batches`` batches in all (a key
still above its target then is marked ``mc_capped``). A key with no accepted sample is
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

from eyeviz.core.domain import PAPER_DOMAIN3D, Domain3D
from eyeviz.estimators.analytic3d import estimate
from eyeviz.estimators.base import Estimator3D, LitCSR, Prediction3D, as_csr, take_rows
from eyeviz.estimators.limit3d_exact import prior_density, same_rows
from eyeviz.estimators.limit3d_eye import _Eye  # noqa: F401  (read by tests)
from eyeviz.estimators.limit3d_proposal import _key_hash
from eyeviz.estimators.limit3d_rows import (
    _compact,
    _compact_sparse,
    _put_rows,
    _rows_of,
    _spread,
    _spread_flat,
)
from eyeviz.estimators.weighted import weighted_median

__all__ = ["PRIORS", "Limit3DEstimator", "load", "posterior_samples3d", "prior_density"]

_same = same_rows  # the exact check's row comparison (kept under its old name)

PRIORS = ("single", "multi")
#: the retries of keys with no accepted draw: (window and slack factor, batches of draws)
RETRY = ((1.0, 8), (2.5, 24), (1.0, 96))
#: the default accuracy: the relative Monte-Carlo error of r a key's draws are topped up
#: to, batch by batch, at most MAX_BATCHES batches in all (docs/limit3d.md)
MC_TARGET = 0.01
MAX_BATCHES = 16
#: the default draws per batch. 256 left the reported DD 0.051 +- 0.011 points above the
#: converged DD at nside 180 (a median of 12 accepted draws a key: the answers' Monte-Carlo
#: noise inflates the mean |error|, as 1 / draws); 8x the draws is within 0.01 points,
#: at about 2.8x the run time (issue 38.2, docs/limit3d.md, scripts/check_limit3d_seeds.py)
SAMPLES = 2048
#: the largest ``max_batches`` a Limit3DEstimator takes
MAX_BATCHES_BOUND = 256
#: a key whose effective sample size is below this is topped up too (one or two accepted
#: draws give a Monte-Carlo error of 0 or none at all, not a small one)
MIN_ESS = 4.0
#: the largest ``samples`` and ``grid`` a Limit3DEstimator takes
MAX_SAMPLES = 1 << 14
MAX_GRID = 64
#: keys processed together
_CHUNK = 8
#: batches of draws of a retry proposed in one call (their arrays side by side), and of
#: the top-ups (taken one by one: the answers are those of one batch a call)
_GROUP = 8
_TOPUP = 4
#: The most facets per eye a key may light and still be sampled: each exact check of a
#: draw costs about its lit count, and a draw is checked up to (max_batches + sum of
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
    if d.kind == "measured":  # no closed form: every facet of the larger eye
        return int(max(d.facet_counts))
    near = d.r_min - d.h
    alpha = math.pi / 2 if near <= d.g_max else math.asin(d.g_max / near)
    fw = math.sqrt(4 * math.pi / d.npix)
    bound = d.npix * (1 - math.cos(alpha)) / 2 + 8 * 2 * math.pi * math.sin(alpha) / fw + 16
    return int(min(d.npix, math.ceil(bound)))


class Limit3DEstimator(Estimator3D):
    """The MAPE-optimal answers of the 3D posterior, by importance sampling with the exact
    0/1 likelihood (module docstring); any design, no weights.

    Predictions carry ``flagged`` (empty posterior: answered by analytic3d),
    ``mc_error`` (relative standard error of r's estimate; NaN where flagged) and
    ``n_accepted`` (samples that reproduce both lit sets)."""

    name = "limit3d"
    kinds = ("spherical", "measured")

    def __init__(
        self,
        domain: Domain3D = PAPER_DOMAIN3D,
        prior: str = "single",
        samples: int = SAMPLES,
        grid: int = 8,
        seed: int = 0,
        accuracy: float = MC_TARGET,
        max_batches: int = MAX_BATCHES,
    ) -> None:
        if prior not in PRIORS:
            raise ValueError(f"prior must be one of {PRIORS}, got {prior!r}")
        # bounded so that one chunk's draws and grid fit in memory
        ints = (("samples", samples, 4, MAX_SAMPLES), ("grid", grid, 4, MAX_GRID),
                ("max_batches", max_batches, 1, MAX_BATCHES_BOUND))  # fmt: skip
        for name, v, lo, hi in ints:
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
        ok = isinstance(accuracy, float | int | np.floating) and not isinstance(accuracy, bool)
        if not (ok and 0.0 < float(accuracy) <= 1.0):
            raise ValueError(f"accuracy must be a number > 0 and <= 1, got {accuracy!r}")
        self.accuracy = float(accuracy)
        self.max_batches = int(max_batches)
        self._proposal = _proposal(domain, prior, self.samples, self.grid)
        self.last_mc_error: np.ndarray = np.zeros(0)
        self.last_accepted: np.ndarray = np.zeros(0, np.int64)
        self.last_capped: np.ndarray = np.zeros(0, bool)

    # --- the posterior of a chunk of keys ------------------------------------------------
    def _draw(
        self,
        lit_a: LitCSR,
        lit_b: LitCSR,
        keys: np.ndarray,
        wide: float,
        stream: int,
        reps: int = 1,
        top_all: bool = False,
    ) -> dict[str, np.ndarray]:
        """Weighted posterior samples of a chunk: dict of (N, reps * samples) arrays (the
        eye model's proposal set up once, ``reps`` batches of draws). With ``reps`` > 1
        (the retries: their caller keeps each key's first ``samples`` accepted draws in
        draw order) a key gets no more groups of batches once it has ``samples``. With
        ``top_all`` every key may be topped up (:func:`_tops_up` not asked)."""
        prop = self._proposal
        st = prop.setup(lit_a, lit_b, keys, wide)
        # the batches ``_GROUP`` at a time (side by side; each as if drawn alone)
        streams = [stream + 8 * rep for rep in range(reps)]
        parts: list[dict] = []
        got = np.zeros(keys.size, np.int64)
        for i in range(0, reps, _GROUP):
            rows = got < self.samples
            if not rows.any():
                break
            part = _sampled(prop, st, keys, streams[i : i + _GROUP], None if rows.all() else rows)
            got += (part["w"] > 0).sum(axis=1)
            parts.append(part)
        out = {k: np.concatenate([q[k] for q in parts], axis=1) for k in parts[0]}
        if reps > 1:
            return out
        # top-ups: a key with too few or too spread draws (_needs_more) gets another batch
        # (its own stream; the other keys get none), up to max_batches. Up to _TOPUP
        # batches are drawn in one call, then taken one by one as if drawn one at a time:
        # a batch counts for a key only while the key still needs more after the batches
        # before it (a key that needs no more keeps needing none: its new draws weigh 0),
        # and none is taken once no key needs more. Only accepted draws are kept
        # (:func:`_compact`). A proposal with ``retry_empty`` tops up no key whose first
        # batch found nothing (:func:`_tops_up`): such a key goes to the retries at once
        # (and gets these top-ups too only if they find it less: :meth:`_posterior`).
        ok = np.ones(keys.size, bool) if top_all else _tops_up(prop, out)
        if getattr(prop, "batch_counts", False):
            return self._topups_sized(st, keys, stream, out, ok)
        rep, m = 1, self.samples
        need = _needs_more(out["r"], out["w"], self.accuracy) & ok
        while rep < self.max_batches and need.any():
            g = min(_TOPUP, self.max_batches - rep)
            more = prop.sample(st, keys, [stream + 8 * (rep + j) for j in range(g)], rows=need)
            for j in range(g):
                part = _compact(more, j * m, (j + 1) * m, need)
                out = {k: np.concatenate([out[k], v], axis=1) for k, v in part.items()}
                rep += 1
                need = _needs_more(out["r"], out["w"], self.accuracy) & ok
                if not need.any():
                    break
        return out

    def _topups_sized(
        self, st: dict, keys: np.ndarray, stream: int, out: dict, ok: np.ndarray
    ) -> dict:
        """The top-ups of :meth:`_draw` for a proposal that draws each key its own number
        of batches (``sample_counts``): key n's k-th batch is its stream + 8 k, taken while
        the key still needs more after the batches before it, as there, so a key gets the
        same draws; but each round draws a key the batches its error predicts
        (:func:`_more_batches`), not ``_TOPUP`` for every key. Only the keys ``ok``.
        Returns :func:`_compact` of the draws (what the caller's ``_compact`` makes of
        them): the accepted draws are kept flat, batch after batch (each batch's rows in
        order), the decisions read r and w from them (:func:`_spread_flat`), and the
        arrays are built once at the end."""
        m, n = self.samples, keys.size
        rep = np.ones(n, np.int64)
        acc = out["w"] > 0
        vals = [{k: v[acc] for k, v in out.items()}]
        row_all, r_all, w_all = np.nonzero(acc)[0], vals[0]["r"], vals[0]["w"]
        sp = _spread_flat(n, row_all, r_all, w_all)
        need = _needs_more_of(*sp, self.accuracy) & (rep < self.max_batches) & ok
        while need.any():
            cnt = np.where(need, _more_batches_of(*sp, self.accuracy, rep), 0)
            cnt = np.minimum(cnt, self.max_batches - rep)
            # the accepted draws alone (flat indices n W + m, W = max(cnt) batches), batch
            # by batch; r and w of each taken batch as it is taken, the rest of the round's
            # taken draws gathered once after it (in the same order)
            at, more = self._proposal.sample_counts_sparse(st, keys, stream + 8 * rep, cnt)
            width = int(cnt.max()) * m
            row, col = at // width, at % width
            batch = col // m
            sels = []
            for j in range(int(cnt.max())):
                take = need & (cnt > j)
                if not take.any():
                    break
                sels.append(np.flatnonzero(take[row] & (batch == j)))
                row_all = np.concatenate([row_all, row[sels[-1]]])
                r_all = np.concatenate([r_all, more["r"][sels[-1]]])
                w_all = np.concatenate([w_all, more["w"][sels[-1]]])
                rep += take
                sp = _spread_flat(n, row_all, r_all, w_all)
                need = _needs_more_of(*sp, self.accuracy) & (rep < self.max_batches)
                need &= ok
            if sels:
                sel = np.concatenate(sels)
                vals.append({k: v[sel] for k, v in more.items()})
        # each row's accepted draws in draw order: batch after batch, stably by row
        by = np.argsort(row_all, kind="stable")
        got = {k: np.concatenate([v[k] for v in vals])[by] for k in out}
        return _rows_of(np.bincount(row_all, minlength=n), got)

    def _posterior(self, lit_a: LitCSR, lit_b: LitCSR):
        keys = _key_hash(lit_a, lit_b) ^ np.uint64(self.seed)
        s = self._draw(lit_a, lit_b, keys, 1.0, 0)
        m = self.samples
        retried = np.zeros(keys.size, bool)
        for stream, wide, reps in _retries(self._proposal):
            few = np.flatnonzero(~(s["w"].sum(axis=1) > 0))
            if not few.size:
                break
            retried[few] = True
            # keys with nothing accepted: their posterior is a small part of the proposal
            # (the misses are found with more draws, not with wider windows): ``reps``
            # times the draws, the window and slack ``wide`` times wider; the accepted
            # draws kept, the first ``samples`` of them in draw order
            sub_a, sub_b = take_rows(*lit_a, few), take_rows(*lit_b, few)
            s2 = self._draw(sub_a, sub_b, keys[few], wide, stream, reps)
            order = np.argsort(~(s2["w"] > 0), axis=1, kind="stable")[:, :m]
            s = _put_rows(s, few, {k: np.take_along_axis(v, order, 1) for k, v in s2.items()})
        got = (s["w"] > 0).sum(axis=1)
        few = np.flatnonzero(retried & (got < MIN_ESS))
        if few.size and getattr(self._proposal, "retry_empty", False):
            # keys sent to the retries by an empty first batch (``retry_empty``) that the
            # retries found fewer than MIN_ESS draws for: the first pass's top-ups too (the
            # draws they had without the rule), and whichever found more is kept
            sub_a, sub_b = take_rows(*lit_a, few), take_rows(*lit_b, few)
            s2 = self._draw(sub_a, sub_b, keys[few], 1.0, 0, top_all=True)
            more = (s2["w"] > 0).sum(axis=1) > got[few]
            if more.any():
                s = _put_rows(s, few[more], {k: v[more] for k, v in s2.items()})
        return _compact(s)

    def _predict_csr(self, lit_a: LitCSR, lit_b: LitCSR):
        n = lit_a[0].size - 1
        r = np.empty(n)
        az = np.empty(n)
        el = np.empty(n)
        empty = np.zeros(n, bool)
        mc = np.full(n, np.nan)
        acc = np.zeros(n, np.int64)
        cap = np.zeros(n, bool)
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
            cap[rows] = ~e & _needs_more(sm["r"], w, self.accuracy)
        if empty.any():
            idx = np.flatnonzero(empty)
            fr, fa, fe, _ = estimate(self.domain, take_rows(*lit_a, idx), take_rows(*lit_b, idx))
            r[idx], az[idx], el[idx] = fr, fa, fe
        self._mc_parts.append(mc)
        self._acc_parts.append(acc)
        self._cap_parts.append(cap)
        return r, az, el, empty

    def predict(self, lit_a, lit_b) -> Prediction3D:
        """As :meth:`Estimator3D.predict`, plus ``mc_error``, ``n_accepted`` and
        ``mc_capped`` (the key's error is still above ``accuracy`` after ``max_batches``
        batches; also in :attr:`last_mc_error`, :attr:`last_accepted`,
        :attr:`last_capped`); NaN / 0 / False on invalid rows."""
        self._mc_parts: list[np.ndarray] = []
        self._acc_parts: list[np.ndarray] = []
        self._cap_parts: list[np.ndarray] = []
        p: Any = super().predict(lit_a, lit_b)
        valid = np.atleast_1d(p.valid)
        mc = np.full(valid.shape, np.nan)
        acc = np.zeros(valid.shape, np.int64)
        cap = np.zeros(valid.shape, bool)
        if self._mc_parts:
            mc[valid] = np.concatenate(self._mc_parts)
            acc[valid] = np.concatenate(self._acc_parts)
            cap[valid] = np.concatenate(self._cap_parts)
        scalar = np.ndim(p.valid) == 0
        p.mc_error = mc[0] if scalar else mc
        p.n_accepted = acc[0] if scalar else acc
        p.mc_capped = cap[0] if scalar else cap
        self.last_mc_error, self.last_accepted, self.last_capped = mc, acc, cap
        return p

    def __repr__(self) -> str:
        d = self.domain
        return (
            f"<Limit3DEstimator h={d.h:g} l={d.l:g} nside={d.nside} r=[{d.r_min:g}, "
            f"{d.r_max:g}] g_max={d.g_max:g} el_max={d.el_max:g} prior={self.prior}>"
        )


def _proposal(domain: Domain3D, prior: str, samples: int, grid: int) -> Any:
    """The eye model's proposal (``setup(lit_a, lit_b, keys, wide)`` then
    ``sample(state, keys, stream)``): HEALPix cells or measured facets' cones."""
    return _PROPOSALS[domain.kind]()(domain, prior, samples, grid)


def _retries(proposal: Any) -> tuple[tuple[int, float, int], ...]:
    """The retries of keys with nothing accepted, as (stream, window and slack factor,
    batches): ``RETRY`` in order from stream 1, or the proposal's own ``retries`` (the
    measured one keeps only the stage that finds keys: limit3d_measured.RETRIES)."""
    own = getattr(proposal, "retries", None)
    if own is not None:
        return tuple(own)
    return tuple((i, wide, reps) for i, (wide, reps) in enumerate(RETRY, start=1))


def _healpix_proposal() -> type:
    from eyeviz.estimators.limit3d_healpix import HealpixProposal

    return HealpixProposal


def _measured_proposal() -> type:
    from eyeviz.estimators.limit3d_measured import MeasuredProposal

    return MeasuredProposal


#: each eye model's (``domain.kind``) proposal class, imported when first asked for
_PROPOSALS = {"spherical": _healpix_proposal, "measured": _measured_proposal}


def _sampled(prop: Any, st: dict, keys: np.ndarray, streams, rows) -> dict:
    """:func:`_compact` of ``prop.sample`` (its ``sample_sparse`` where it has one: the
    same arrays without the dense ones)."""
    if not hasattr(prop, "sample_sparse"):
        return _compact(prop.sample(st, keys, streams, rows))
    at, vals, m = prop.sample_sparse(st, keys, streams, rows)
    return _compact_sparse(keys.size, at // m, vals)


def _tops_up(proposal: Any, s: dict) -> np.ndarray:
    """The keys that may be topped up after their first batch: all, or for a proposal with
    ``retry_empty`` (the measured one) those with a draw accepted (a key whose first batch
    found nothing goes to the retries at once: its later batches rarely find it,
    limit3d_measured.RETRY_EMPTY; it gets them too if the retries find under MIN_ESS draws)."""
    if getattr(proposal, "retry_empty", False):
        return (s["w"] > 0).any(axis=1)
    return np.ones(s["w"].shape[0], bool)


def _needs_more(r: np.ndarray, w: np.ndarray, target: float = MC_TARGET) -> np.ndarray:
    """The keys to top up: the relative Monte-Carlo error of r, 1.2533 sd_w(r) / sqrt(ESS)
    / mean_w(r), above ``target``, or an ESS below ``MIN_ESS`` (one or two accepted
    draws give an error of 0 or none at all, not a small one), or nothing accepted."""
    return _needs_more_of(*_spread(r, w), target)


def _needs_more_of(mean, sd, ess, target: float) -> np.ndarray:
    """:func:`_needs_more` from the rows' :func:`_spread`."""
    with np.errstate(invalid="ignore", divide="ignore"):
        mc = 1.2533 * sd / np.sqrt(ess) / mean
    return ~(ess >= MIN_ESS) | ~(mc <= target)


def _more_batches(s: dict, target: float, done: np.ndarray) -> np.ndarray:
    """Per key, the batches of draws after ``done`` that its relative Monte-Carlo error of
    r (1 / sqrt(batches)) or its ESS (as batches) predicts it needs to reach ``target``
    and ``MIN_ESS``, at least 1; ``_TOPUP`` where nothing is accepted yet."""
    return _more_batches_of(*_spread(s["r"], s["w"]), target, done)


def _more_batches_of(mean, sd, ess, target: float, done: np.ndarray) -> np.ndarray:
    """:func:`_more_batches` from the rows' :func:`_spread`."""
    with np.errstate(invalid="ignore", divide="ignore"):
        mc = 1.2533 * sd / np.sqrt(ess) / mean
        f = np.maximum((mc / target) ** 2, MIN_ESS / ess)
        k = np.ceil(done * f) - done
    return np.where(np.isfinite(k), np.clip(k, 1, MAX_BATCHES_BOUND), _TOPUP).astype(np.int64)


def posterior_samples3d(est: Limit3DEstimator, lit_a, lit_b) -> dict[str, np.ndarray]:
    """The weighted posterior samples of one key (lit sets as sorted index arrays):
    ``x, y, z, g, r, azimuth, elevation, weight`` (weights sum to 1; empty arrays when no
    sample reproduced the key), for the app's point cloud."""
    a = np.asarray(lit_a, np.int64)
    b = np.asarray(lit_b, np.int64)
    ptr_a = np.array([0, a.size])
    ptr_b = np.array([0, b.size])
    na, nb = est.domain.facet_counts
    la = as_csr("lit_a", (ptr_a, a), na)[:2]
    lb = as_csr("lit_b", (ptr_b, b), nb)[:2]
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
