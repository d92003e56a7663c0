"""The share of a HEALPix cell's area inside a cap: the ``cell`` response (docs/responses.md).

HEALPix is equal-area in the chart (phi, z = cos t): a cell's area is
int L_cell(t) sin t dt, L_cell(t) its width in longitude at colatitude t. In the HEALPix
projection (Calabretta and Roukema 2007; y_s = 3 pi z / 8 in the equatorial zone,
pi/4 (2 - sigma) with sigma = sqrt(3 (1 - |z|)) at the poles, x_s = phi_f + (phi -
phi_f) sigma about the polar face's centre phi_f) every cell is the diamond
|x_s - X_c| + |y_s - Y_c| <= pi / (4 nside), so at each t the cell is one interval of
longitude, closed form. A cap (radius b about colatitude theta_c, longitude phi_c) is at
each t the interval phi_c +- omega(t), omega by the half-angle formula of the triangle
(pole, cap centre, point). The covered area is int |cell(t) cap cap(t)| sin t dt: split
at the cell's vertices, the zone boundary |z| = 2/3 and the cap's extreme and polar
colatitudes (where omega has square-root ends, removed by t = m - h cos s), then
Gauss-Legendre on each piece, bisected where two rules differ by more than the
tolerance (the kinks where the cap's edge crosses a cell edge are found that way).
"""

from __future__ import annotations

import functools
import math

import numpy as np

from eyeviz.core import healpix, kernels

__all__ = ["cell_fraction", "cells_inside", "integrate", "integrate_compiled"]

_NODES = 16
_COARSE = 12  # the error estimate: |16-node - 12-node| (12 nodes converge on smooth pieces)
_TOL = 1e-12  # on the fraction of the cell, summed over a cell's pieces
_MAX_ROUNDS = 60
_THIN = 1e-11
#: A piece whose two rules differ by at most this share of the cell is taken as it is: the
#: rounding of t next to a cap's square-root tip (t - (theta_c - b) has an absolute error
#: of an ulp of t) keeps the two rules about 1e-15 of the cell apart there however thin
#: the piece; a cell has at most a few hundred pieces, so these add well under 1e-11.
_FLOOR = 1e-14
_SAMPLES = 17  # per piece, in the piece's s variable: sign changes of the edge gaps
#: Halvings of a sign change's sample interval (pi / 16 in s): 2^-40 of it, about 1e-13 of
#: the piece; the kink left that near a piece's end costs the rule ~ (1e-13)^2 of it.
_BISECT = 40
_SHIFTS = (-2 * math.pi, 0.0, 2 * math.pi)


def _ys(z: np.ndarray) -> np.ndarray:
    az = np.abs(z)
    pol = math.pi / 4 * (2 - np.sqrt(3 * np.maximum(1 - az, 0)))
    return np.where(az <= 2 / 3, 3 * math.pi / 8 * z, np.sign(z) * pol)


def _t_of_ys(y: np.ndarray) -> np.ndarray:
    """Colatitude of the projected height y_s in [-pi/2, pi/2]."""
    ay = np.abs(y)
    sig = np.clip(2 - 4 * ay / math.pi, 0, 1)
    # polar: z = 1 - sigma^2 / 3, so t = 2 asin(sigma / sqrt 6) (accurate near the pole)
    t_pol = 2 * np.arcsin(sig / math.sqrt(6))
    t_eq = np.arccos(np.clip(8 * ay / (3 * math.pi), -1, 1))
    t = np.where(ay <= math.pi / 4, t_eq, t_pol)
    return np.where(y >= 0, t, math.pi - t)


class _Cells:
    """Per (cap, cell) pair: the cell's diamond and the cap, flat arrays."""

    def __init__(self, nside: int, pix, theta_c, phi_c, b):
        ix, iy, face = healpix.pix2xyf(nside, pix)
        zc, phc = healpix.xyf2loc(nside, ix + 0.5, iy + 0.5, face)
        phc = np.mod(phc, 2 * math.pi)
        self.phf = (np.floor(2 * phc / math.pi) + 0.5) * math.pi / 2
        self.yc = _ys(zc)
        polar = np.abs(zc) > 2 / 3
        sig = np.sqrt(3 * np.maximum(1 - np.abs(zc), 0))
        self.xc = np.where(polar, self.phf + (phc - self.phf) * sig, phc)
        self.delta = math.pi / (4 * nside)
        far = math.pi / 2 - (np.abs(self.yc) + self.delta)  # the far vertex's depth
        self.pole_gap = np.where(np.abs(far) < 1e-12, 0.0, np.where(far > 0, far, np.inf))
        self.theta_c, self.phi_c, self.b = theta_c, phi_c, b
        self.area = 4 * math.pi / healpix.npix(nside)

    def parts(self, t: np.ndarray, k: np.ndarray):
        """(lo, hi, centre, omega, whole, none): the cell's longitudes at colatitude t and
        the cap's, centre +- omega (omega = pi: every longitude; none: no cap there)."""
        z = np.cos(t)
        az = np.abs(z)
        sig = np.where(az > 2 / 3, math.sqrt(6) * np.sin(np.minimum(t, math.pi - t) / 2), 1.0)
        # the height below the pole, pi/2 - |y_s|, from sigma (no cancellation near it)
        depth = np.where(az > 2 / 3, math.pi / 4 * sig, math.pi / 2 - 3 * math.pi / 8 * az)
        ys = np.sign(z) * (math.pi / 2 - depth)
        yc = self.yc[k]
        # a cell's distance from its far vertex, that vertex's height from the pole taken
        # exactly 0 for the cells at a pole (their width tends to a quarter there)
        gap = np.where(ys * yc > 0, self.pole_gap[k], np.inf)
        hw = np.minimum(self.delta - np.abs(ys - yc), gap + depth)
        hw = np.maximum(hw, 0)
        phf, xc = self.phf[k], self.xc[k]
        with np.errstate(divide="ignore", invalid="ignore"):
            lo = np.where(sig > 0, phf + (xc - hw - phf) / sig, phf - math.pi / 4)
            hi = np.where(sig > 0, phf + (xc + hw - phf) / sig, phf + math.pi / 4)
        tc, b = self.theta_c[k], self.b[k]
        s = (t + tc + b) / 2
        with np.errstate(divide="ignore", invalid="ignore"):
            q = np.sin(s - t) * np.sin(s - tc) / (np.sin(s) * np.sin(s - b))
            omega = 2 * np.arctan(np.sqrt(np.maximum(q, 0)))
        whole = (t <= b - tc) | (t >= 2 * math.pi - tc - b) | (b >= math.pi)
        none = ~whole & ((t >= tc + b) | (t <= tc - b))
        omega = np.where(whole, math.pi, np.where(none, 0.0, np.nan_to_num(omega)))
        return lo, hi, self.phi_c[k], omega, whole, none

    def width(self, t: np.ndarray, k: np.ndarray) -> np.ndarray:
        """|cell(t) intersect cap(t)| in longitude, for pairs k at colatitudes t."""
        lo, hi, pc, omega, whole, none = self.parts(t, k)
        out = np.zeros(t.shape)
        for sh in _SHIFTS:
            top = np.minimum(hi, pc + omega + sh)
            out += np.clip(top - np.maximum(lo, pc - omega + sh), 0, None)
        out = np.where(whole, hi - lo, np.where(none, 0.0, out))
        return np.minimum(out, hi - lo)

    def edges(self, t: np.ndarray, k: np.ndarray) -> np.ndarray:
        """(..., 12): the signed gaps between the cap's edges (3 shifts) and the cell's;
        where one changes sign the width has a kink."""
        lo, hi, pc, omega, _, _ = self.parts(t, k)
        g = [pc + sg * omega + sh - e for sg in (-1, 1) for sh in _SHIFTS for e in (lo, hi)]
        return np.stack(g, axis=-1)  # omega is 0 where no cap, pi where all: continuous


@functools.lru_cache(maxsize=4)
def _leggauss(nodes: int) -> tuple[np.ndarray, np.ndarray]:
    return np.polynomial.legendre.leggauss(nodes)


def _piece(cells: _Cells, k, lo, hi, nodes: int) -> np.ndarray:
    """int_lo^hi width(t) sin t dt on t = m - h cos s, s in [0, pi] (Gauss-Legendre)."""
    x, w = _leggauss(nodes)
    s = (x + 1) * math.pi / 2
    m, h = (lo + hi) / 2, (hi - lo) / 2
    t = m[:, None] - h[:, None] * np.cos(s)
    f = cells.width(t, np.broadcast_to(k[:, None], t.shape)) * np.sin(t)
    return (f * (h[:, None] * np.sin(s))) @ w * (math.pi / 2)


def _t_at(lo, hi, s):
    return (lo + hi) / 2 - (hi - lo) / 2 * np.cos(s)


def _split_at_crossings(cells: _Cells, k, lo, hi):
    """The pieces cut again where the cap's edge crosses a cell edge: sign changes of
    :meth:`_Cells.edges` on _SAMPLES points (uniform in s, so dense at the ends, where
    a crossing may sit next to the cap's square-root tip), each bisected to the last bit."""
    s = np.linspace(0, math.pi, _SAMPLES)
    t = _t_at(lo[:, None], hi[:, None], s)
    e = cells.edges(t, np.broadcast_to(k[:, None], t.shape))  # (pieces, samples, 12)
    change = np.signbit(e[:, :-1]) != np.signbit(e[:, 1:])
    pi_, si, ei = np.nonzero(change)
    if not pi_.size:
        return k, lo, hi
    a, b = s[si].copy(), s[si + 1].copy()
    kk, ll, hh = k[pi_], lo[pi_], hi[pi_]
    sa = np.signbit(cells.edges(_t_at(ll, hh, a), kk)[np.arange(pi_.size), ei])
    for _ in range(_BISECT):
        m = (a + b) / 2
        sm = np.signbit(cells.edges(_t_at(ll, hh, m), kk)[np.arange(pi_.size), ei])
        same = sm == sa
        a = np.where(same, m, a)
        b = np.where(same, b, m)
    roots = _t_at(ll, hh, (a + b) / 2)
    # every piece with its roots: sorted cut points per piece
    cut_k = np.concatenate([np.arange(k.size), np.arange(k.size), pi_])
    cut_t = np.concatenate([lo, hi, roots])
    order = np.lexsort((cut_t, cut_k))
    cut_k, cut_t = cut_k[order], cut_t[order]
    same = cut_k[1:] == cut_k[:-1]
    nlo, nhi, owner = cut_t[:-1][same], cut_t[1:][same], cut_k[:-1][same]
    keep = nhi > nlo
    return k[owner[keep]], nlo[keep], nhi[keep]


def cells_inside(nside: int, pix, theta_c, phi_c, b) -> np.ndarray:
    """Per pair: the closed cell ``pix`` lies in the closed cap (radius b <= pi/2 about
    (theta_c, phi_c)) surely, so its share is exactly 1 (False: not sure; integrate).

    The lit test's bound turned over (docs/spherical.md, step 4): on each edge P(t),
    t in [0, 1], f(t) = |P(t) - c|^2 has |f''| <= M (2.5 times the proven |P''| bound),
    so f(t) <= (1 - t) f_a + t f_b + M t (1 - t) / 2; its maximum below s2 = 4 sin^2(b/2)
    by 1e-11 (some hundred times float64's error in f and s2) puts the edge in the cap.
    A cap of radius <= pi/2 holding a cell's boundary holds the cell (the boundary's other
    side holds the cap's complement, of area >= 2 pi, more than a cell)."""
    from eyeviz.core.healpix_fast import _edge_bounds

    pix, theta_c, phi_c, b = (
        np.ravel(v)
        for v in np.broadcast_arrays(
            np.asarray(pix, np.int64), *(np.asarray(v, np.float64) for v in (theta_c, phi_c, b))
        )
    )
    out = np.zeros(pix.size, bool)
    ok = np.flatnonzero(b <= math.pi / 2)
    if not ok.size:
        return out
    ix, iy, face = healpix.pix2xyf(nside, pix[ok])
    fx, fy = ix.astype(np.float64), iy.astype(np.float64)
    st = np.sin(theta_c[ok])
    c = np.stack([st * np.cos(phi_c[ok]), st * np.sin(phi_c[ok]), np.cos(theta_c[ok])], axis=-1)
    s2 = 4 * np.sin(b[ok] / 2) ** 2

    def f(dx: int, dy: int) -> np.ndarray:
        v = healpix.xyf2vec(nside, fx + dx, fy + dy, face)
        return ((v - c) ** 2).sum(axis=-1)

    f00, f10, f01, f11 = f(0, 0), f(1, 0), f(0, 1), f(1, 1)
    inside = np.ones(ok.size, bool)
    # (fixed_is_y, fixed, lo, f at lo, f at lo + 1): the four edges
    for fixed_is_y, fixed, lo, fa, fb in (
        (True, fy, fx, f00, f10),
        (True, fy + 1, fx, f01, f11),
        (False, fx, fy, f00, f01),
        (False, fx + 1, fy, f10, f11),
    ):
        m = 2.5 * _edge_bounds(nside, face, fixed_is_y, fixed, lo)
        dd = fb - fa
        top = np.where(
            np.abs(dd) <= 0.5 * m,
            0.5 * (fa + fb) + 0.125 * m + dd * dd / (2 * m),
            np.maximum(fa, fb),
        )
        inside &= top < s2 - 1e-11
    out[ok] = inside
    return out


def cell_fraction(nside: int, pix, theta_c, phi_c, b, jit: bool | None = None) -> np.ndarray:
    """Share of each cell ``pix`` (RING) inside the cap of radius b (pi: the sphere)
    about (theta_c, phi_c), per pair (arrays broadcast), in [0, 1]. Cells the cap surely
    holds (:func:`cells_inside`) are 1 exactly; the others are integrated by the compiled
    kernel (:mod:`eyeviz.core.kernels.healpix_cells`) where it is in use (``jit`` None:
    :func:`eyeviz.core.kernels.use`), else by the numpy reference :func:`integrate`."""
    pix, theta_c, phi_c, b = np.broadcast_arrays(
        np.asarray(pix, np.int64), *(np.asarray(v, np.float64) for v in (theta_c, phi_c, b))
    )
    shape = pix.shape
    pix, theta_c, phi_c, b = (np.ravel(v) for v in (pix, theta_c, phi_c, b))
    out = np.ones(pix.size)
    rest = np.flatnonzero((b < math.pi) & ~cells_inside(nside, pix, theta_c, phi_c, b))
    if rest.size:
        args = (nside, pix[rest], theta_c[rest], phi_c[rest], b[rest])
        if jit is None:
            jit = kernels.use(rest.size)
        if jit:
            out[rest] = integrate_compiled(*args)
            kernels.mark_ready()
        else:
            out[rest] = integrate(*args)
    return out.reshape(shape)


def integrate(nside: int, pix, theta_c, phi_c, b) -> np.ndarray:
    """The reference: each pair's share by the adaptive quadrature of the module's
    docstring (flat arrays; b < pi), in [0, 1]."""
    n = pix.size
    out = np.zeros(n)
    if n == 0:
        return out
    cells = _Cells(nside, pix, theta_c, phi_c, b)
    top, bot, pts = _cuts(cells)
    lo_all, hi_all = pts[:, :-1], pts[:, 1:]
    ok = np.isfinite(lo_all) & np.isfinite(hi_all) & (hi_all > lo_all)
    k = np.repeat(np.arange(n), ok.sum(axis=1))
    lo, hi = lo_all[ok], hi_all[ok]
    k, lo, hi = _split_at_crossings(cells, k, lo, hi)
    span = (bot - top)[k]
    for _ in range(_MAX_ROUNDS):
        if not k.size:
            break
        fine = _piece(cells, k, lo, hi, _NODES)
        coarse = _piece(cells, k, lo, hi, _COARSE)
        good = np.abs(fine - coarse) <= cells.area * np.maximum(_TOL * (hi - lo) / span, _FLOOR)
        # a piece this thin holds at most its longitude width times 1e-11 of the cell's
        # height (well below 1e-9 of the cell): rounding, not the rule, limits it there
        good |= (hi - lo) <= _THIN * span
        np.add.at(out, k[good], fine[good])
        bad = ~good
        mid_t = (lo[bad] + hi[bad]) / 2
        k = np.concatenate([k[bad], k[bad]])
        lo, hi = np.concatenate([lo[bad], mid_t]), np.concatenate([mid_t, hi[bad]])
        span = np.concatenate([span[bad], span[bad]])
    if k.size:
        raise ArithmeticError(f"cell response: {k.size} piece(s) did not reach the tolerance")
    return np.clip(out / cells.area, 0.0, 1.0)


def integrate_compiled(nside: int, pix, theta_c, phi_c, b) -> np.ndarray:
    """:func:`integrate` by the compiled kernel
    (:func:`eyeviz.core.kernels.healpix_cells.cell_fraction_kernel`), pair by pair."""
    from eyeviz.core.kernels.healpix_cells import cell_fraction_kernel

    n = pix.size
    out = np.zeros(n)
    if n == 0:
        return out
    cells = _Cells(nside, pix, theta_c, phi_c, b)
    _, _, pts = _cuts(cells)
    xf, wf = _leggauss(_NODES)
    xc, wc = _leggauss(_COARSE)

    def f64(v: np.ndarray) -> np.ndarray:
        return np.ascontiguousarray(v, np.float64)

    failed = cell_fraction_kernel(
        f64(pts), f64(cells.phf), f64(cells.yc), f64(cells.xc), f64(cells.pole_gap),
        float(cells.delta), f64(cells.theta_c), f64(cells.phi_c), f64(cells.b),
        float(cells.area), xf, wf, xc, wc, out,
    )  # fmt: skip
    if failed:
        raise ArithmeticError(f"cell response: {failed} piece(s) did not reach the tolerance")
    return np.clip(out, 0.0, 1.0)


def _cuts(cells: _Cells) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(top, bot, points): per pair the cell's colatitude range and the sorted cut points
    (the cell's vertices, |z| = 2/3, the cap's extremes and polar colatitudes; NaN last)."""
    n = cells.yc.size
    top = _t_of_ys(cells.yc + cells.delta)
    mid = _t_of_ys(cells.yc)
    bot = _t_of_ys(cells.yc - cells.delta)
    tc, b = cells.theta_c, cells.b
    cuts = [top, mid, bot, np.full(n, math.acos(2 / 3)), np.full(n, math.acos(-2 / 3))]
    cuts += [tc - b, tc + b, b - tc, 2 * math.pi - tc - b]
    pts = np.stack(cuts, axis=1)
    pts = np.where((pts > top[:, None]) & (pts < bot[:, None]), pts, np.nan)
    pts = np.concatenate([top[:, None], pts, bot[:, None]], axis=1)
    return top, bot, np.sort(pts, axis=1)
