"""A box that provably holds the posterior of a key of a measured eye pair, for the
measured proposal of the spherical limit (:mod:`.limit3d_measured`, step 5: the
defensive component of its mixture), from the facets' acceptance cones alone.

Take an eye (centroid o) and the key's constraining facets of it
(any subset of the facets gives a valid bound: it only drops constraints), their lenses
p_i within e of an apex o_k (their mean), axes a_i, half angles alpha_i. For a ball (c,
g) of the posterior's support let D = |c - o_k|, u = (c - o_k) / D its direction, v_i = c
- p_i, theta_i the angle between v_i and a_i and phi_i the angle between u and a_i. The
prior gives D >= d_min = r_min - |o_k - origin|, g <= g_max, and the field test (no lens
in the ball) g < |v_i|; assume d_min > e.

(a) The lens seen from c: the angle between v_i and u is at most asin(e / D) (the
    directions from c to the points within e of o_k form a cone of that half angle), so
    |phi_i - theta_i| <= asin(e / D).
(b) A lit facet i: dist(c, K_i) <= g with the cone distance above. If theta_i <=
    alpha_i, theta_i - alpha_i <= 0; if 0 < theta_i - alpha_i < pi/2, |v_i| sin(theta_i
    - alpha_i) <= g; if theta_i - alpha_i >= pi/2 the distance is |v_i| > g: not lit. So
    theta_i - alpha_i <= asin(g / |v_i|) <= asin(g / (D - e)) (|v_i| >= D - e).
(c) An unlit facet j: dist(c, K_j) > g > 0, so theta_j > alpha_j, and either theta_j -
    alpha_j >= pi/2 or |v_j| sin(theta_j - alpha_j) > g: theta_j - alpha_j > asin(g /
    |v_j|) >= asin(g / (D + e)).
(d) With (a): L(u) = max over lit i of (phi_i - alpha_i) <= asin(min(1, g / (D - e))) +
    asin(e / D) and F(u) = L(u) - min over unlit j of (phi_j - alpha_j) < asin(min(1, g
    / (D - e))) - asin(g / (D + e)) + 2 asin(e / D). Both right sides grow with g and
    shrink as D grows (the derivatives of the asin difference in g and in D have those
    signs), so at g = g_max, D = d_min they are bounds S and T that hold for every ball
    of the support (:func:`_lens_tolerances`).
(e) Every angle above is 1-Lipschitz in u along the sphere, so L is too and F is
    2-Lipschitz; the gnomonic map's inverse shrinks lengths (its singular values are 1 /
    (1 + |x|^2) and 1 / sqrt(1 + |x|^2)), so a grid cell whose half diagonal in the plane
    is h lies within h of its centre's direction. A cell whose centre has F > T + 2 h or
    L > S + h holds no feasible direction; all of them lie in the cap of radius
    alpha_i + S about any lit axis a_i, so the search starts from that cap's gnomonic
    square and zooms onto the kept cells (:func:`dir_region`; a margin
    of 1e-7 rad covers arccos's rounding near 1).
(f) The box's coordinates are about the eye's centroid o, not o_k: the direction from o
    lies within asin(|o_k - o| / (r_min - |o - origin|)) of the direction from o_k (as
    in (a)), so each kept cell's directions from o lie within h plus that of its centre.
    A's delta is gnomonic about u0 (its map stretches an angle by at most sec^2 of the
    largest angle from u0), B's beta is the angle from -b, 1-Lipschitz. The bounding box
    of the kept cells so widened holds every ball of the support
    (:func:`provable_box`).
The bound holds where d_min exceeds the lens offsets and the first cap stays within
``PROOF_REACH`` rad of the reference (the honeybee's keys at its default domain; not the
test pair at 4-12 eye radii, whose balls may nearly touch the eye); elsewhere a key's
proposal is the box of step 4 alone, as before."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from eyeviz.core import kernels
from eyeviz.estimators.limit3d_proposal import _frame

#: a key chunk's constraining facets of one eye (limit3d_measured._Edges: pos, ax, half,
#: lit, pad), and the measured proposal (limit3d_measured.MeasuredProposal); not imported
#: here, which imports this module
_Edges = Any
MeasuredProposal = Any

__all__ = ["dir_region", "keep_cells", "provable_box"]

#: the provable box: grid points per axis and zoom levels of each eye's direction search,
#: and the largest angle from the reference its first cap may reach (a gnomonic plane
#: holds less than a hemisphere)
PROOF_GRID = 12
PROOF_LEVELS = 3
PROOF_REACH = 1.4
#: dir_region's grids as one compiled call (the same cells as its numpy loop with the
#: compiled cell test, which the tests compare with it)
GRID_KERNEL = True


def _asin1(y):
    return np.arcsin(np.clip(y, 0.0, 1.0))


def _lens_tolerances(g_max: float, d_min: np.ndarray, e: np.ndarray):
    """(T, S, ok) per key (module docstring, "A box that provably holds the posterior"):
    every feasible ball at distance D >= d_min from the apex, radius g <= g_max, whose
    eye's lenses lie within e of the apex, has F(u) < T and max over lit facets of
    (angle(u, a_i) - alpha_i) <= S at its direction u from the apex; ``ok`` where d_min > e
    (else the lens offsets bound nothing)."""
    ok = d_min > e
    dm = np.where(ok, d_min, 1.0)
    em = np.where(ok, e, 0.0)
    par = _asin1(em / dm)
    near = _asin1(g_max / np.maximum(dm - em, 1e-300))
    t = near - _asin1(g_max / (dm + em)) + 2.0 * par
    return t, near + par, ok


def _angles(e: _Edges, u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(F, L) (N, G) at unit directions u (N, G, 3): F = max over lit facets of
    (angle(a_i, u) - alpha_i) - min over unlit ones of (angle(a_j, u) - alpha_j), L the
    first term alone."""
    ang = np.arccos(np.clip(np.matmul(e.ax, np.swapaxes(u, 1, 2)), -1.0, 1.0)) - e.half[..., None]
    lit = (e.lit & ~e.pad)[..., None]
    unl = (~e.lit & ~e.pad)[..., None]
    top = np.where(lit, ang, -np.inf).max(axis=1)
    return top - np.where(unl, ang, np.inf).min(axis=1), top


def dir_region(g_max: float, e: _Edges, apex: np.ndarray, w0: np.ndarray, d_min: np.ndarray):
    """Step (e) of the module docstring: the directions from ``apex``
    (N, 3) that a feasible ball at distance ``d_min`` (N,) or more can have, on
    zooming gnomonic grids about w0 (N, 3), first the cap of the lit facets' bound S:
    a cell whose centre has F > T + 2 h or L > S + h (h its half diagonal in the
    plane, which bounds its geodesic radius) holds none; the next grid spans the kept
    cells. Returns (the last grid's centres (N, G, 3) as unit vectors, kept (N, G), h
    (N,), ok): ``ok`` where the bound holds (d_min above the lenses' offsets from the
    apex, the cap within ``PROOF_REACH`` of w0, some cell kept)."""
    live = ~e.pad
    off = np.where(live, np.linalg.norm(e.pos - apex[:, None], axis=2), 0.0).max(axis=1)
    t, s, ok = _lens_tolerances(g_max, d_min, off)
    e1, e2 = _frame(w0)
    cos0 = np.clip(np.einsum("nkj,nj->nk", e.ax, w0), -1.0, 1.0)
    reach = np.where(e.lit & live, np.arccos(cos0) + e.half, np.inf).min(axis=1) + s
    ok &= reach < PROOF_REACH
    w = np.tan(np.where(ok, reach, 0.1))
    lo, hi = -np.stack([w, w], 1), np.stack([w, w], 1)
    tt = (np.arange(PROOF_GRID) + 0.5) / PROOF_GRID
    g2 = np.stack(np.meshgrid(tt, tt, indexing="ij"), axis=-1).reshape(-1, 2)
    if GRID_KERNEL and kernels.use(lo.shape[0] * g2.shape[0]):
        from eyeviz.core.kernels.limit3d_region import dir_grid_kernel

        n, f64 = lo.shape[0], np.float64
        v = np.empty((n, g2.shape[0], 3))
        keep = np.empty((n, g2.shape[0]), np.bool_)
        h = np.empty(n)
        ok = np.ascontiguousarray(ok, np.bool_)
        dir_grid_kernel(kernels.arg(e.ax, f64), kernels.arg(e.half, f64), kernels.arg(e.lit),
                        kernels.arg(e.pad), kernels.arg(w0, f64), kernels.arg(e1, f64),
                        kernels.arg(e2, f64), kernels.arg(t, f64), kernels.arg(s, f64),
                        kernels.arg(lo, f64), kernels.arg(hi, f64), g2, PROOF_GRID,
                        PROOF_LEVELS, v, keep, h, ok)  # fmt: skip
        return v, keep, h, ok
    for _ in range(PROOF_LEVELS):
        span = hi - lo
        dd = lo[:, None] + span[:, None] * g2[None]
        h = 0.5 * np.hypot(span[:, 0], span[:, 1]) / PROOF_GRID
        v = w0[:, None] + dd[..., :1] * e1[:, None] + dd[..., 1:] * e2[:, None]
        v = v / np.linalg.norm(v, axis=2, keepdims=True)
        keep = keep_cells(e, v, t, s, h)
        half = 0.5 * span[:, None] / PROOF_GRID
        some: np.ndarray = np.asarray(keep.any(axis=1))
        ok &= some
        lo = np.where(some[:, None], np.where(keep[..., None], dd - half, np.inf).min(1), lo)
        hi = np.where(some[:, None], np.where(keep[..., None], dd + half, -np.inf).max(1), hi)
    return v, keep, h, ok


def keep_cells(e: _Edges, v: np.ndarray, t, s, h) -> np.ndarray:
    """The cells (N, G) of :func:`dir_region`'s grid that may hold a feasible
    direction: F <= t + 2 h and L <= s + h at their centres v (N, G, 3), with 1e-7 rad
    for arccos's rounding near 1 (about 1.5e-8). Compiled with an early exit
    (kernels.limit3d_region.direction_keep_kernel) unless ``EYEVIZ_JIT=0``."""
    if kernels.use(v.shape[0] * v.shape[1]):
        from eyeviz.core.kernels.limit3d_region import direction_keep_kernel

        keep = np.empty(v.shape[:2], np.bool_)
        f64 = np.float64
        direction_keep_kernel(kernels.arg(e.ax, f64), kernels.arg(e.half, f64),
                              kernels.arg(e.lit), kernels.arg(e.pad), kernels.arg(v, f64),
                              kernels.arg(t, f64), kernels.arg(s, f64), kernels.arg(h, f64),
                              keep)  # fmt: skip
        return keep
    f, top = _angles(e, v)
    tiny = 1e-7
    return (f <= (t + 2 * h + tiny)[:, None]) & (top <= (s + h + tiny)[:, None])


def provable_box(prop: MeasuredProposal, st: dict) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(lo, hi, proven): per key a box in (delta, beta) of the measured proposal ``prop``
    (its chunk set up in ``st``) holding every ball of the posterior's support where
    ``proven`` (module docstring)."""
    d = prop.domain
    n = st["u0"].shape[0]
    proven = np.ones(n, bool)
    cells = []
    for e, centre in ((st["ea"], prop.fa.centre), (st["eb"], prop.fb.centre)):
        live = ~e.pad
        apex = np.where(live[..., None], e.pos, 0.0).sum(axis=1)
        apex = apex / np.maximum(live.sum(axis=1), 1)[:, None]
        w0 = st["ref"] - apex
        w0 = w0 / np.linalg.norm(w0, axis=1, keepdims=True)
        # the least distance of a ball's centre from the apex and from the centroid
        d_apex = d.r_min - np.linalg.norm(apex - prop.origin, axis=1)
        d_centre = d.r_min - float(np.linalg.norm(centre - prop.origin))
        v, keep, h, ok = dir_region(float(d.g_max), e, apex, w0, d_apex)
        # step 2: from the centroid, a cell's directions lie within h + asin(|o_k -
        # o| / d_centre) of its centre
        q = np.linalg.norm(apex - centre, axis=1)
        proven &= ok & (d_centre > q)
        cells.append((v, keep, h + _asin1(q / max(d_centre, 1e-300))))
    (va, ka, pa), (vb, kb, pb) = cells
    # A's delta: gnomonic about u0, which stretches an angle by at most sec^2 of the
    # largest angle from u0
    cu = np.einsum("ngj,nj->ng", va, st["u0"])
    ang = np.arccos(np.clip(cu, -1.0, 1.0)) + pa[:, None]
    proven &= ~(ka & (ang >= 1.5)).any(axis=1)
    grow = pa[:, None] / np.cos(np.minimum(ang, 1.5)) ** 2
    with np.errstate(divide="ignore", invalid="ignore"):
        dx = np.stack([np.einsum("ngj,nj->ng", va, st[k]) / cu for k in ("e1", "e2")], -1)
    lo_a = np.where(ka[..., None], dx - grow[..., None], np.inf).min(axis=1)
    hi_a = np.where(ka[..., None], dx + grow[..., None], -np.inf).max(axis=1)
    # B's beta, the angle between -b and the direction from o_B: 1-Lipschitz
    bc = np.arccos(np.clip(vb @ -prop.bhat, -1.0, 1.0))
    b_lo = np.where(kb, bc - pb[:, None], np.inf).min(axis=1)
    b_hi = np.where(kb, bc + pb[:, None], -np.inf).max(axis=1)
    lo = np.concatenate([lo_a, np.maximum(b_lo, 0.0)[:, None]], axis=1)
    hi = np.concatenate([hi_a, np.minimum(b_hi, math.pi)[:, None]], axis=1)
    proven &= np.isfinite(lo).all(axis=1) & np.isfinite(hi).all(axis=1)
    return lo, hi, proven
