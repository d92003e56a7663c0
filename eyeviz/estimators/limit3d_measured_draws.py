"""The measured proposal's draws (:class:`eyeviz.estimators.limit3d_measured.
MeasuredProposal`, mixed in): a chunk's weighted draws from the mixture of boxes, each
with a weight checked exactly (:func:`.limit3d_cones.key_hits`), compiled
(kernels.measured_limit.mixture_draws_kernel) unless ``EYEVIZ_JIT=0``, with the numpy
:meth:`MeasuredDraws._draws_ref` as the reference. The proposal and its weight: the
docstring of :mod:`.limit3d_measured`, step 5."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from eyeviz.core import kernels
from eyeviz.core.domain import Domain3D
from eyeviz.estimators.limit3d_cones import both_columns, key_hits
from eyeviz.estimators.limit3d_exact import prior_density
from eyeviz.estimators.limit3d_proposal import _batch_uniforms

if TYPE_CHECKING:
    from eyeviz.estimators.limit3d_cones import _Facets

__all__ = ["MeasuredDraws"]

#: the quantities of a draw, in the order the proposal returns them
_VALUES = ("x", "y", "z", "g", "r", "az", "el", "w")


def _uniforms(keys: np.ndarray, m: int, k: int, streams) -> np.ndarray:
    """:func:`.limit3d_proposal._batch_uniforms` (an int stream or a sequence of them),
    compiled unless ``EYEVIZ_JIT=0``: the same floats bit for bit."""
    if not kernels.use(keys.size * m):
        return _batch_uniforms(keys, m, k, streams)
    from eyeviz.core.kernels.limit3d_region import uniforms_kernel

    s = np.atleast_1d(np.asarray(streams, np.int64))
    out = np.empty((keys.size, m * s.size, k))
    uniforms_kernel(kernels.arg(keys, np.uint64), int(m), kernels.arg(s), out)
    return out


def _dense(at: np.ndarray, vals: dict, n: int, m: int) -> dict[str, np.ndarray]:
    """Dense (n, m) arrays of the draws ``vals`` at the flat indices ``at``, 0 elsewhere."""
    out = {}
    for k, v in vals.items():
        o = np.zeros(n * m)
        o[at] = v
        out[k] = o.reshape(n, m)
    return out


class MeasuredDraws:
    """Mixed into MeasuredProposal: needs its set-up (``domain``, ``prior``, ``samples``,
    ``fa``, ``bhat``, ``blen``, ``origin``, ``s_half``, ``w_min``) and its region
    (``_boxes``, ``_bcentres``, ``_h``, ``_keys``)."""

    domain: Domain3D
    prior: str
    samples: int
    fa: _Facets
    bhat: np.ndarray
    blen: float
    origin: np.ndarray
    s_half: float
    w_min: float
    if TYPE_CHECKING:

        def _boxes(self, st: dict) -> tuple[np.ndarray, np.ndarray, np.ndarray]: ...
        def _bcentres(self, st: dict, delta: np.ndarray, beta: np.ndarray) -> Any: ...
        def _h(self, st: dict, c: np.ndarray) -> tuple[np.ndarray, np.ndarray]: ...
        def _keys(self, st: dict, idx: np.ndarray) -> dict: ...

    def sample(self, st: dict, keys: np.ndarray, stream, rows=None) -> dict[str, np.ndarray]:
        """``samples`` weighted draws per key of a chunk set up by :meth:`setup`, per
        stream (an int or a sequence: batches side by side, :func:`_batch_uniforms`); only
        the keys ``rows`` (bool (N,), default all) get draws, the others weight 0. Dense
        (N, M) arrays: :meth:`sample_sparse`'s draws in their places, weight 0 elsewhere
        (where the other arrays hold 0)."""
        at, vals, m = self.sample_sparse(st, keys, stream, rows)
        return _dense(at, vals, st["u0"].shape[0], m)

    def sample_sparse(self, st: dict, keys: np.ndarray, stream, rows=None):
        """:meth:`sample`'s accepted draws alone: (their flat indices n M + m in order,
        {x, y, z, g, r, az, el, w} of them, M), the draws weighted above 0 by the proposal
        that also pass the exact check."""
        n = st["u0"].shape[0]
        s = np.atleast_1d(np.asarray(stream, np.int64))
        streams = np.broadcast_to(s, (n, s.size))
        return self._sampled(st, keys, streams, np.full(n, s.size, np.int64), rows)

    def _sampled(self, st: dict, keys: np.ndarray, streams: np.ndarray, nst: np.ndarray, rows):
        """The accepted draws of key n's batches of the streams streams[n, :nst[n]] (N, S),
        side by side: (their flat indices n M + m in order, M = samples x S; {x, y, z, g,
        r, az, el, w} of them, M)."""
        d = self.domain
        n, m = st["u0"].shape[0], self.samples * streams.shape[1]
        if kernels.use(n * m):
            at, out = self._draws_sparse(st, keys, streams, nst, None, rows)
        else:  # numpy (the reference): the keys with the same streams together
            at_l, outs = [np.zeros(0, np.int64)], [{k: np.zeros(0) for k in _VALUES}]
            key = np.concatenate([streams, nst[:, None]], axis=1)
            live = nst > 0 if rows is None else (nst > 0) & rows
            for grp in np.unique(key[live], axis=0):
                idx = np.flatnonzero(live & (key == grp).all(axis=1))
                u = _uniforms(keys[idx], self.samples, 4, [int(v) for v in grp[: grp[-1]]])
                dense = self._draws_ref(self._keys(st, idx), u, None)
                flat = np.flatnonzero(dense["w"].ravel() > 0)
                at_l.append(idx[flat // u.shape[1]] * m + flat % u.shape[1])
                outs.append({k: dense[k].ravel()[flat] for k in _VALUES})
            at = np.concatenate(at_l)
            order = np.argsort(at, kind="stable")
            at = at[order]
            out = {k: np.concatenate([q[k] for q in outs])[order] for k in _VALUES}
        c = np.stack([out["x"], out["y"], out["z"]], axis=1)
        hit = key_hits(d, c, out["g"], at // m, st["lit_a"], st["lit_b"])
        return at[hit], {k: v[hit] for k, v in out.items()}, m

    def sample_counts(self, st: dict, keys, first: np.ndarray, counts: np.ndarray) -> dict:
        """:meth:`sample` of key n's batches of the streams first[n] + 8 j, j < counts[n],
        side by side (weight 0 after them), each key as drawn alone."""
        at, vals = self.sample_counts_sparse(st, keys, first, counts)
        return _dense(at, vals, keys.size, int(counts.max()) * self.samples)

    def sample_counts_sparse(self, st: dict, keys, first: np.ndarray, counts: np.ndarray):
        """:meth:`sample_counts`' accepted draws alone: (their flat indices n W + m, W =
        max(counts) x samples, in order; {x, y, z, g, r, az, el, w} of them)."""
        streams = first[:, None] + 8 * np.arange(int(counts.max()))[None, :]
        at, vals, _ = self._sampled(st, keys, streams.astype(np.int64), counts.astype(np.int64),
                                    counts > 0)  # fmt: skip
        return at, vals

    def _draws_sparse(self, st: dict, keys, streams, nst, u, rows):
        """The compiled draws before the exact check (kernels.measured_limit.
        mixture_draws_kernel): (flat indices n M + m of the draws weighted above 0, in
        order; their x, y, z, g, r, az, el, w). The uniforms those of key n's streams
        streams[n, :nst[n]] (N, S), drawn inside, or u (N, M, 4) where given. The same
        draws as :meth:`_draws_ref`, weights to about 1e-13 (its cone distances and
        trigonometry round differently)."""
        from eyeviz.core.kernels import measured_limit

        # Any: the kernel takes 38 arrays and numbers (numba's Dispatcher stub types fewer)
        kernel: Any = measured_limit.mixture_draws_kernel
        d = self.domain
        n = st["u0"].shape[0]
        m = u.shape[1] if u is not None else self.samples * streams.shape[1]
        uu = kernels.arg(u, np.float64) if u is not None else np.zeros((0, 1, 4))
        live = np.ones(n, np.bool_) if rows is None else kernels.arg(rows, np.bool_)
        f64 = np.float64
        at = np.empty(n * m, np.int64)
        outs = {k: np.empty(n * m) for k in _VALUES}
        boxes, counts, dens = self._boxes(st)
        # a copy: a read-only broadcast (one key's, contiguous) would be another signature,
        # loaded from numba's cache at the first predict's retry (docs/limit3d.md, bee33g)
        cnt = kernel(
            kernels.arg(keys, np.uint64), np.array(streams, np.int64, order="C"),
            kernels.arg(nst, np.int64), uu, kernels.arg(boxes, f64),
            kernels.arg(counts, np.int64), kernels.arg(dens, f64), self.samples,
            kernels.arg(st["u0"], f64), kernels.arg(st["e1"], f64), kernels.arg(st["e2"], f64),
            kernels.arg(self.fa.centre, f64), kernels.arg(self.bhat, f64), self.blen,
            kernels.arg(self.origin, f64), self.s_half, float(d.g_max), float(d.r_min),
            float(d.r_max), float(d.el_max), self.prior == "multi", live,
            *both_columns(st["ea"], st["eb"]), at,
            outs["x"], outs["y"], outs["z"], outs["g"], outs["r"], outs["az"], outs["el"],
            outs["w"],
        )  # fmt: skip
        return at[:cnt].copy(), {k: v[:cnt].copy() for k, v in outs.items()}

    def _draws_kernel(self, st: dict, u: np.ndarray, rows) -> dict[str, np.ndarray]:
        """:meth:`_draws_ref` compiled, draw by draw, of the uniforms u (N, M, 4)
        (:meth:`_draws_sparse`): the same draws, weights to about 1e-13; dense (N, M)
        arrays, 0 where the weight is not above 0."""
        n, m = u.shape[:2]
        none = np.zeros((n, 1), np.int64)
        at, vals = self._draws_sparse(st, np.zeros(n, np.uint64), none, none[:, 0], u, rows)
        return _dense(at, vals, n, m)

    def _draws_ref(self, st: dict, u: np.ndarray, rows) -> dict[str, np.ndarray]:
        """The weighted draws of the uniforms u (N, M, 4) before the exact check (numpy,
        the reference): (delta, beta) uniform in the box, the centre, g uniform on its
        interval, the weight."""
        d = self.domain
        boxes, counts, dens = self._boxes(st)
        # each batch's draws from the mixture's boxes in turn
        j = np.arange(u.shape[1]) % self.samples
        comp = (j[None, :, None] >= np.cumsum(counts, axis=1)[:, None, :]).sum(axis=2)
        comp = np.minimum(comp, counts.shape[1] - 1)
        key = np.arange(comp.shape[0])[:, None]
        blo, bhi = boxes[key, comp, 0], boxes[key, comp, 1]
        x = blo + (bhi - blo) * u[..., :3]
        delta = x[..., :2]
        c, rho, drho = self._bcentres(st, delta, x[..., 2])
        good = np.isfinite(rho)
        c = np.where(good[..., None], c, self.fa.centre + st["u0"][:, None, :] / self.w_min)
        if rows is not None:
            good &= rows[:, None]
        g_lo, g_hi = self._h(st, c)
        pad = 1e-9 * g_hi
        g_lo, g_hi = np.maximum(g_lo - pad, 0.0), g_hi + pad
        good &= g_hi > g_lo
        gg = g_lo + (g_hi - g_lo) * u[..., 3]
        q = c - self.origin
        r = np.linalg.norm(q, axis=2)
        el = np.arcsin(np.clip(q[..., 2] / r, -1.0, 1.0))
        az = np.arctan2(q[..., 1], q[..., 0])
        with np.errstate(over="ignore", invalid="ignore"):
            # d(x, y, z) = rho^2 (1 + |delta|^2)^(-3/2) d(delta) d(rho), d(rho) = drho d(beta)
            jac = rho * rho * (1.0 + (delta * delta).sum(axis=2)) ** -1.5 * drho
            q = np.zeros(x.shape[:2])
            for k in range(boxes.shape[1]):
                lo, hi = boxes[:, k, 0][:, None], boxes[:, k, 1][:, None]
                inside = ((x >= lo) & (x <= hi)).all(axis=2) & (dens[:, k] > 0)[:, None]
                q = q + np.where(inside, dens[:, k][:, None], 0.0)
            wt = prior_density(d, self.prior, r, gg, el, az) * jac * ((g_hi - g_lo) / q)
        wt = np.where(good & np.isfinite(wt), wt, 0.0)
        return {"r": r, "az": az, "el": el, "g": gg, "x": c[..., 0], "y": c[..., 1],
                "z": c[..., 2], "w": wt}  # fmt: skip
