"""The HEALPix proposal of the spherical limit (:mod:`eyeviz.estimators.limit3d`, module
docstring steps 1-5): per chunk of keys, each eye's feasible caps from its edge cells
(:mod:`.limit3d_eye`), A's box of centres, B's region along A's rays (:mod:`.limit3d_proposal`),
g where both eyes' modelled radii allow it, the prefilter, then the exact check. Only HEALPix eyes
come here; a measured pair has its own proposal (:mod:`.limit3d_measured`)."""

from __future__ import annotations

import math

import numpy as np

from eyeviz.core import kernels
from eyeviz.core.domain import Domain3D
from eyeviz.estimators.base import LitCSR
from eyeviz.estimators.limit3d_exact import band_pass, exact_hits, prior_density
from eyeviz.estimators.limit3d_eye import _Eye
from eyeviz.estimators.limit3d_proposal import (
    _angle_box,
    _batch_uniforms,
    _extent,
    _locate,
    _prefilter,
    _ray_in_box,
    _ray_in_region,
)

__all__ = ["HealpixProposal"]

#: facet widths the centre search may move: edge cells that cannot bind within them are
#: dropped before it
PRUNE = 0.25
#: zoom levels of the search for the centre (each grid a third as wide)
LEVELS = 4
#: grid points and rounds of the search along the ray for where the g test can pass
RAY_GRID = 8
RAY_ROUNDS = 1
#: the share of each batch's draws whose u is uniform on B's box along the ray (the
#: defensive component: the search's bracket is not a proven hull of the posterior)
DEFENSIVE = 1 / 16
#: the per-key slack: this many times the model's second-order error in the box
SLACK_SAFETY = 4.0


class HealpixProposal:
    """Importance draws for keys of a HEALPix pair: :meth:`setup` once per chunk (and
    window factor ``wide``), then :meth:`sample` per batch of ``samples`` draws."""

    def __init__(self, domain: Domain3D, prior: str, samples: int, grid: int) -> None:
        self.domain, self.prior, self.samples, self.grid = domain, prior, samples, grid

    def setup(self, lit_a: LitCSR, lit_b: LitCSR, keys: np.ndarray, wide: float) -> dict:
        """Each eye's edge cells, centre and box of centres for a chunk of keys."""
        d = self.domain
        fw = math.sqrt(4 * math.pi / d.npix)
        A = np.array([-d.h, 0.0, 0.0])
        B = np.array([d.h, 0.0, 0.0])
        reach = np.full(lit_a[0].size - 1, PRUNE * wide * fw)
        ea = _Eye(d, lit_a, A, 0, reach)
        eb = _Eye(d, lit_b, B, 1, reach)
        n = ea.c.shape[0]
        slack0 = wide * 0.002 * fw
        for e in (ea, eb):
            e.prune(reach)
            _locate(e, 0.25 * wide * fw, self.grid, LEVELS)
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
        # the keys whose slack is still the window's have these boxes already (the same
        # model, reach and slack: the same bits)
        same = slack[:, 0] == slack0
        ext = _extent(ea, wide * 0.5 * fw, slack, known=(same, ext))
        ext_b = _extent(eb, wide * 0.5 * fw, slack, known=(same, ext_b))
        ea.prune(1.2 * math.sqrt(2.0) * ext.max(axis=1))
        eb.prune(1.2 * math.sqrt(2.0) * ext_b.max(axis=1))
        # A's centre: uniform in (theta, phi) over the bounds of A's box, theta cut to
        # those of B's box (both caps' centres share the ball's theta: B's box bounds it)
        box = _angle_box(ea, ext)
        box_b = _angle_box(eb, ext_b)
        th_lo = np.fmax(box[:, 0], box_b[:, 0])
        th_hi = np.fmin(box[:, 1], box_b[:, 1])
        # the exact check's band cells about the located centres (compiled only)
        bands = (ea.band(), eb.band()) if kernels.use(n * self.samples) else None
        # the draws' kernel evaluates each eye's model in its box only: the forms that
        # never give its value there dropped (the same values, bit for bit)
        boxl = (ea.box_lists(ext), eb.box_lists(ext_b)) if bands is not None else None
        return dict(A=A, B=B, ea=ea, eb=eb, n=n, slack=slack, ext=ext, ext_b=ext_b,
                    box=box, th_lo=th_lo, th_hi=th_hi, lit_a=lit_a, lit_b=lit_b,
                    bands=bands, box_lists=boxl)  # fmt: skip

    def sample(self, st: dict, keys: np.ndarray, stream, rows=None) -> dict[str, np.ndarray]:
        """``samples`` weighted draws per key of a chunk set up by :meth:`setup`, per
        stream (an int or a sequence: batches side by side, :func:`_batch_uniforms`); only
        the keys ``rows`` (bool (N,), default all) get draws, the others weight 0. The
        draws are one kernel unless ``EYEVIZ_JIT=0`` (:meth:`_draws_kernel`; the numpy
        :meth:`_draws_ref` is the reference), then each draw with prior mass is checked
        exactly (:meth:`_check`)."""
        if rows is None:
            rows = np.ones(keys.size, bool)
        if kernels.use(keys.size * self.samples):
            out, ca, alpha = self._draws_kernel(st, keys, stream, rows)
        else:
            u = _batch_uniforms(keys, self.samples, 4, stream)
            out, ca, alpha = self._draws_ref(st, u, rows)
        out["w"] = self._check(st, out, ca, alpha)
        return out

    def _draws_kernel(self, st: dict, keys: np.ndarray, stream, rows: np.ndarray):
        """:meth:`_draws_ref` compiled (kernels.limit3d_draws.healpix_draws_kernel): the
        same formulas draw by draw, each draw given up at its first failed test, on the
        uniforms of :func:`_batch_uniforms` (keys, ``samples``, 4, stream) drawn inside
        as they are read (the same bits); values written only where the weight is above 0
        (zeros elsewhere)."""
        from eyeviz.core.kernels.limit3d_draws import healpix_draws_kernel

        d, ea, eb = self.domain, st["ea"], st["eb"]
        s = kernels.arg(np.atleast_1d(np.asarray(stream, np.int64)))
        n, m = keys.size, self.samples * s.size
        # the kernel writes every weight, the rest only where the weight is above 0
        out = {k: np.empty((n, m)) for k in ("x", "y", "z", "g", "r", "az", "el", "w")}
        ca, alpha = np.empty((n, m, 3)), np.empty((n, m))
        u_max = 1.0 / (d.r_min - d.h) if d.r_min > d.h else np.inf
        f64 = np.float64
        la, lb = st.get("box_lists") or (ea.lists, eb.lists)  # (Eye.box_lists)
        fa = (ea.a_lit, ea.t_lit, ea.a_unl, ea.t_unl, la)
        fb = (eb.a_lit, eb.t_lit, eb.a_unl, eb.t_unl, lb)
        arg = kernels.arg
        healpix_draws_kernel(arg(keys, np.uint64), s, arg(rows, np.bool_), arg(st["th_lo"], f64),
                             arg(st["th_hi"], f64),
                             arg(st["box"], f64), arg(st["ext"], f64), arg(st["ext_b"], f64),
                             arg(st["slack"][:, 0], f64), fa, arg(ea.c, f64), arg(ea.e1, f64),
                             arg(ea.e2, f64), fb, arg(eb.c, f64), arg(eb.e1, f64), arg(eb.e2, f64),
                             arg(eb.a, f64), arg(st["A"], f64), arg(st["B"], f64),
                             1.0 / (d.r_max + d.h), u_max, math.sin(d.gamma / 2), float(d.g_max),
                             float(d.r_min), float(d.r_max), float(d.el_max), float(d.psi),
                             self.prior == "multi", np.linspace(0.0, 1.0, RAY_GRID), RAY_ROUNDS,
                             int(self.samples * DEFENSIVE), self.samples, out["x"], out["y"],
                             out["z"], out["g"], out["r"], out["az"], out["el"], out["w"], ca,
                             alpha)  # fmt: skip
        return out, ca, alpha

    # long: the weighted draws of one chunk (propose, weigh) in one pass over shared arrays
    def _draws_ref(self, st: dict, u: np.ndarray, rows: np.ndarray):
        """The draws before the exact check in numpy (the reference): (theta, phi) of A's
        direction, u = 1 / rho along its ray, g; every draw's values, its weight (prior
        over the proposal's density, 0 where a test fails), A's direction and the cap's
        half-angle seen from A."""
        d, A, B, ea, eb = self.domain, st["A"], st["B"], st["ea"], st["eb"]
        n, slack, ext, ext_b = st["n"], st["slack"], st["ext"], st["ext_b"]
        box, th_lo, th_hi = st["box"], st["th_lo"], st["th_hi"]
        m = u.shape[1]
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
        # then narrowed to where the g test can pass (the search's bracket); a defensive
        # share of the draws takes u on the box's interval, every weight over the mixture
        with np.errstate(invalid="ignore"):
            sa = (np.sin(np.clip(lo_a - slack, 0.0, math.pi / 2)),
                  np.sin(np.clip(hi_a + slack, 0.0, math.pi / 2)))  # fmt: skip
        h_lo, h_hi = _ray_region_draws(eb, ca, u_lo, u_hi, good, slack, 1.0 / d.r_max, sa)
        wide = ~(h_hi > h_lo)  # a bracket of no width: the box's interval instead
        h_lo, h_hi = np.where(wide, u_lo, h_lo), np.where(wide, u_hi, h_hi)
        n_def = int(self.samples * DEFENSIVE)
        lam = n_def / self.samples
        box_u = (np.arange(m) % self.samples < n_def)[None, :]
        uu = np.where(box_u, u_lo + (u_hi - u_lo) * u[..., 2], h_lo + (h_hi - h_lo) * u[..., 2])
        with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
            q = lam / (u_hi - u_lo) + np.where(
                (uu >= h_lo) & (uu <= h_hi), (1.0 - lam) / (h_hi - h_lo), 0.0
            )
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
            vol = vol * ((g_hi - g_lo) / q)
            w = prior_density(d, self.prior, r, gg, el, az) * rho**4 * sp * vol
        good = good & rows[:, None]  # the other keys' draws as drawn (weights 0: not checked)
        w = np.where(good & np.isfinite(w), w, 0.0)
        out = {"r": r, "az": az, "el": el, "g": gg, "x": p[..., 0], "y": p[..., 1],
               "z": p[..., 2], "w": w}  # fmt: skip
        return out, ca, alpha

    def _check(self, st: dict, out: dict, ca: np.ndarray, alpha: np.ndarray) -> np.ndarray:
        """The weights ``out["w"]`` (N, M) kept where the draw reproduces the key exactly
        (the 0/1 likelihood), 0 elsewhere."""
        d, B, ea, eb = self.domain, st["B"], st["ea"], st["eb"]
        w = out["w"]
        n, m = w.shape
        # the exact 0/1 likelihood on the draws with prior mass (only theirs are read: the
        # kernel leaves the others' values unset)
        cand = np.flatnonzero(w.ravel() > 0)
        pc = np.stack([out[k].ravel()[cand] for k in ("x", "y", "z")], axis=1)
        gc = out["g"].ravel()[cand]
        ok = np.zeros(cand.size, bool)  # each candidate's verdict
        todo = np.arange(cand.size)  # the candidates not decided yet
        if cand.size and st["bands"] is not None:
            # the band check decides most draws at once (the prefilter below only drops
            # draws the exact check rejects: it is left for the others)
            sure = band_pass(d.eyes, pc, gc, cand // m, st["bands"])
            at = np.flatnonzero(sure != 2)
            ok[at] = exact_hits(d, pc[at], gc[at], cand[at] // m, st["lit_a"], st["lit_b"],
                                matched=sure[at] == 1)  # fmt: skip
            todo = np.flatnonzero(sure == 2)
        if todo.size:  # a cheap necessary condition first
            c = cand[todo]
            row = c // m
            pb_ = pc[todo] - B
            rb = np.linalg.norm(pb_, axis=1)
            keep = _prefilter(ea, row, ca.reshape(-1, 3)[c], alpha.ravel()[c])
            todo, row, pb_, rb = todo[keep], row[keep], pb_[keep], rb[keep]
            sin_b = np.minimum(gc[todo] / rb, 1.0)
            keep = _prefilter(eb, row, pb_ / rb[:, None], np.arcsin(sin_b))
            todo = todo[keep]
        ok[todo] = exact_hits(d, pc[todo], gc[todo], cand[todo] // m, st["lit_a"], st["lit_b"])
        hit = np.zeros(n * m, bool)
        hit[cand[ok]] = True
        w = np.where(hit.reshape(n, m), w, 0.0)
        return w


def _ray_region_draws(eb: _Eye, ca, u_lo, u_hi, good, slack, u_dead: float, sa=None):
    """Each live draw's u-interval (``good`` (N, M)) narrowed to B's region along its ray
    (:func:`_ray_in_region`; numpy only: no draw uses it now), or with ``sa`` (A's
    sin(lo_A - s), sin(hi_A + s), (N, M) each) to where the g test can pass (the draws'
    kernel's search, compiled there: kernels.limit3d_draws.ray_region_kernel, in place on
    the live draws); the other draws' set to ``u_dead``. numpy: on the live draws moved to
    the front of each row."""
    if sa is not None and kernels.use(good.size):
        from eyeviz.core.kernels.limit3d_draws import ray_region_kernel

        lo, hi = np.array(u_lo, np.float64), np.array(u_hi, np.float64)
        n = good.shape[0]
        sl = kernels.arg(np.broadcast_to(slack, (n, 1))[:, 0], np.float64)
        t = np.linspace(0.0, 1.0, RAY_GRID)
        f64 = np.float64
        ray_region_kernel(eb.a_lit, eb.t_lit, eb.a_unl, eb.t_unl, eb.lists, eb.c, eb.e1, eb.e2,
                          kernels.arg(eb.a, f64), kernels.arg(ca, f64), lo, hi, sl, t, RAY_ROUNDS,
                          kernels.arg(good), kernels.arg(sa[0], f64),
                          kernels.arg(sa[1], f64))  # fmt: skip
        return np.where(good, lo, u_dead), np.where(good, hi, u_dead)
    n = good.shape[0]
    order = np.argsort(~good, axis=1, kind="stable")[:, : max(1, int(good.sum(1).max()))]
    sel = np.take_along_axis(good, order, 1)

    def pick(x: np.ndarray) -> np.ndarray:
        return np.take_along_axis(x, order if x.ndim == 2 else order[..., None], 1)

    c_lo = np.where(sel, pick(u_lo), u_dead)
    c_hi = np.where(sel, pick(u_hi), u_dead)
    aim = None if sa is None else (pick(sa[0]), pick(sa[1]))
    c_lo, c_hi = _ray_in_region(eb, pick(ca), c_lo, c_hi, slack, RAY_GRID, RAY_ROUNDS, aim)
    rows = np.arange(n)[:, None]
    u_lo, u_hi = u_lo.copy(), u_hi.copy()
    u_lo[rows, order] = c_lo
    u_hi[rows, order] = c_hi
    return np.where(good, u_lo, u_dead), np.where(good, u_hi, u_dead)
