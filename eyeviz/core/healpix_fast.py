"""The float64 fast path of the HEALPix lit sets (docs/spherical.md, steps 1-5), HEALPix
only: per ball and eye, the rings a cap's z-range meets; per ring the candidate cells
from the cap's widest longitude span over the ring's z-band and the surely lit cells from
its span on the ring's own z; the cells between tested on their vertices and edges with a
proven second-derivative bound of the edge curves plus float64's rounding bound, and the
few that stay within both bounds of the cap's boundary decided in
:mod:`eyeviz.core.exact3d`. :mod:`eyeviz.core.geometry3d` (the pair) calls it through
``_lit_runs``; :mod:`eyeviz.core.kernels.healpix_lit` is its compiled twin.
"""

from __future__ import annotations

import math
from collections import Counter
from fractions import Fraction

import numpy as np

from eyeviz.core import exact3d, healpix

_EPS = 2.0**-52
#: Largest number of lit indices one call may return (2^28 int64: 2 GiB). A whole eye at
#: nside 2^20 is 1.3e13 facets: such a lit set exists only as runs, not as indices.
MAX_LIT = 1 << 28
#: Per-nside ring tables (_ring_tables) and ring info (_ring_info_tables), built once.
_TABLES: dict[int, tuple[np.ndarray, np.ndarray, np.ndarray]] = {}
_INFO: dict[int, tuple[np.ndarray, ...]] = {}

_DP = 64 * _EPS  # error of a facet vertex vector from healpix.xyf2vec


_STAGES = (16, 256)  # samples per edge in the second and third stages


_SQ6 = math.sqrt(6.0)


#: Diagnostics: cells the vertex/edge test could not clear ("tested"), cells that needed
#: edge sampling ("sampled") and cells decided in mpmath ("exact").
FALLBACK_COUNTS: Counter[str] = Counter()


def _jr_of_theta(theta: np.ndarray) -> np.ndarray:
    """Height in rings / nside of the colatitude theta (the inverse of the rings' z)."""
    c = np.cos(theta)
    return np.where(
        c >= 2.0 / 3.0,
        _SQ6 * np.sin(0.5 * theta),
        np.where(c <= -2.0 / 3.0, 4.0 - _SQ6 * np.cos(0.5 * theta), 2.0 - 1.5 * c),
    )


def _edge_bounds(n: int, face, fixed_is_y: bool, fixed, lo) -> np.ndarray:
    """Vectorised :func:`eyeviz.core.exact3d.edge_bound` (2 / n^2 off the polar caps)."""
    out = np.full(face.shape, 2.0 / (n * n))
    pol = np.flatnonzero((face < 4) | (face >= 8))
    if pol.size:
        f, fx, lo_f = face[pol], fixed[pol] / n, lo[pol] / n
        north = f < 4
        a = np.where(north, 1.0 - fx, fx)
        nr_min = np.where(north, 2.0 - fx - lo_f - 1.0 / n, fx + lo_f)
        polar = (nr_min < 1.0) & (a > 0)
        with np.errstate(divide="ignore", invalid="ignore"):
            extra = np.where(polar, 7.2 * a / np.maximum(nr_min, 1e-300) ** 2, 0.0)
        out[pol] += extra / (n * n)
    return out


def _ring_tables(n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(sin theta, z, pi / (4 K)) of rings 0 .. 4 n (K: cells per quarter; 0 at poles)."""
    tab = _TABLES.get(n)
    if tab is None:
        k = np.arange(4 * n + 1)
        sth, zr = healpix.ring_sz(n, k)
        q = np.minimum(np.minimum(k, n), 4 * n - k)
        unit = np.where(q > 0, 0.25 * math.pi / np.maximum(q, 1), 0.0)
        if len(_TABLES) > 64:
            _TABLES.clear()
        tab = _TABLES[n] = (sth, zr, unit)
    return tab


def _edge_lower(fa, fb, mf):
    """A lower bound of f on [0, 1] from f(0) = fa, f(1) = fb and |f''| <= mf.

    f(t) >= (1 - t) fa + t fb - mf t (1 - t) / 2 (the interpolation error of the chord),
    whose minimum over [0, 1] is (fa + fb) / 2 - mf / 8 - (fb - fa)^2 / (2 mf) when
    |fb - fa| <= mf / 2, else min(fa, fb). Never below min(fa, fb) - mf / 8.
    """
    dd = fb - fa
    inner = 0.5 * (fa + fb) - 0.125 * mf - dd * dd / (2 * mf)
    return np.where(np.abs(dd) <= 0.5 * mf, inner, np.minimum(fa, fb))


def _ring_info_tables(n: int) -> tuple[np.ndarray, ...]:
    """Per ring 0 .. 4 n (0 and 4 n unused): first pixel, pixels, shifted, the longitude
    spacing 2 pi / pixels and the offset o of the first cell's W edge (0 or -1/2)."""
    tab = _INFO.get(n)
    if tab is None:
        k = np.clip(np.arange(4 * n + 1), 1, 4 * n - 1)
        first, nr, shifted = healpix.ring_info(n, k)
        if len(_INFO) > 64:
            _INFO.clear()
        tab = _INFO[n] = (first, nr, shifted, 2 * math.pi / nr, np.where(shifted, 0.0, -0.5))
    return tab


def _runs_to_pieces(first, nr, lo, hi):
    """Cyclic runs [lo, hi] (unwrapped, hi - lo < nr) of rings -> up to two pieces each,
    (start index, length) in RING order."""
    lo_w = np.mod(lo, nr)
    length = hi - lo + 1
    end = lo_w + length
    split = end > nr
    len1 = np.where(split, nr - lo_w, length)
    start1 = first + lo_w
    start2 = first
    len2 = np.where(split, end - nr, 0)
    return start1, len1, start2, len2


# long: the float64 path of the 3D Proposition 2 as one vectorised pass over (ball, ring) pairs,
# step for step as the compiled kernel (core/kernels/healpix_lit.py) reads; split, some twenty
# arrays would pass between the pieces
def _lit_runs_fast(n: int, x, y, z, g, cx: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`_lit_runs` for caps the float64 path places (and any other, more slowly)."""
    nb = x.shape[0]
    npix = 12 * n * n
    with np.errstate(over="ignore", under="ignore", invalid="ignore", divide="ignore"):
        dx0 = x - cx
        # the exact rounding error of dx = x - cx (two-sum): x - cx = dx0 + err
        bv = dx0 - x
        err = (x - (dx0 - bv)) + (-cx - bv)
        errabs0 = np.abs(err) + 2.0**-1070
        # scale every ball by a power of two (exact) so that |d| ~ 1
        big = np.maximum(np.maximum(np.abs(dx0), np.abs(y)), np.maximum(np.abs(z), g))
        ex = np.frexp(big)[1]
        dx, dy, dz, gs = (np.ldexp(v, -ex) for v in (dx0, y, z, g))
        errabs = np.ldexp(errabs0, -ex)
        d2 = dx * dx + dy * dy + dz * dz
        d = np.sqrt(d2)
        errdir = 8 * _EPS + 4 * errabs / d
        # the whole eye: decided exactly where float cannot tell
        dmg = (d - gs) * (d + gs)
        sep = 8 * _EPS * (d + gs) ** 2 + 4 * errabs * (d + gs)
        whole = dmg < -sep
        near = np.abs(dmg) <= sep
        for i in np.flatnonzero(near):
            whole[i] = exact3d.whole_eye(
                Fraction(float(x[i])) - Fraction(cx),
                Fraction(float(y[i])),
                Fraction(float(z[i])),
                Fraction(float(g[i])),
            )
        part = ~whole
        q = gs / d
        # the output is materialised: refuse a call whose lit sets cannot fit
        frac = np.where(part, 0.5 * q * q, 1.0)  # >= (1 - cos alpha) / 2, the cap's share
        est = float(frac.sum()) * npix
        if est > MAX_LIT:
            raise ValueError(
                f"the lit sets would hold about {est:.3g} facets (more than {MAX_LIT}): "
                "use fewer or smaller balls per call, or a smaller nside"
            )
        cosa = np.sqrt(np.maximum(dmg, 0.0)) / d
        dcos = (4 * _EPS * d + 4 * errabs) * (d + gs) / (np.sqrt(np.maximum(dmg, 0.0)) * d)
        dcos = np.where(np.isfinite(dcos), dcos + 4 * _EPS, 4.0)
        # grazing caps (g / |d| -> 1): cos(alpha) from the exact |d|^2 - g^2
        for i in np.flatnonzero(part & (dcos > 1e-9)):
            X = Fraction(float(x[i])) - Fraction(cx)
            D2 = X * X + Fraction(float(y[i])) ** 2 + Fraction(float(z[i])) ** 2
            cosa[i] = math.sqrt(float((D2 - Fraction(float(g[i])) ** 2) / D2))
            dcos[i] = 8 * _EPS * cosa[i] + 1e-300
        s2 = 2 * q * q / (1 + cosa)
        ds2 = 2 * dcos + 8 * _EPS * s2
        alpha = np.arctan2(q, cosa)
        dalpha = dcos / np.maximum(q, 1e-300) + 8 * _EPS
        rxy = np.hypot(dx, dy)
        rho_c = rxy / d
        z_c = dz / d
        theta_c = np.arctan2(rxy, dz)
        phi_c = np.arctan2(dy, dx)
        dphi = 4 * errdir / np.maximum(rho_c, 1e-300) + 1e-12
        pad_t = dalpha + 4 * errdir + 1e-12
        th_lo = np.clip(theta_c - alpha - pad_t, 0.0, math.pi)
        th_hi = np.clip(theta_c + alpha + pad_t, 0.0, math.pi)
        i_min = np.floor(n * _jr_of_theta(th_lo) * (1 - 1e-12)).astype(np.int64) - 1
        i_max = np.ceil(n * _jr_of_theta(th_hi) * (1 + 1e-12)).astype(np.int64) + 1
        i_min = np.clip(i_min, 1, 4 * n - 1)
        i_max = np.clip(i_max, 1, 4 * n - 1)
        i_max = np.where(part, i_max, i_min - 1)  # whole-eye balls: no rings
        zc_hi = np.cos(th_lo)
        zc_lo = np.cos(th_hi)

        # --- (ball, ring) pairs -------------------------------------------------------
        cnt = np.maximum(i_max - i_min + 1, 0)
        pb = np.repeat(np.arange(nb), cnt)
        offs = np.arange(pb.size) - np.repeat(np.cumsum(cnt) - cnt, cnt)
        ring = i_min[pb] + offs
        sth_t, zr_t, _ = _ring_tables(n)
        first_t, nr_t, shifted_t, delta_t, o_t = _ring_info_tables(n)
        first, nr, shifted = first_t[ring], nr_t[ring], shifted_t[ring]
        delta, o = delta_t[ring], o_t[ring]
        # the closures of a ring's cells lie between the centres' z of the rings around
        zb_lo, zb_hi, z_i = zr_t[ring + 1], zr_t[ring - 1], zr_t[ring]
        za = np.maximum(zb_lo, zc_lo[pb])
        zb = np.minimum(zb_hi, zc_hi[pb])
        empty = za > zb
        cos_p, zc_p, rc_p = cosa[pb], z_c[pb], rho_c[pb]
        dnum = dcos[pb] + 2 * errdir[pb] + 4 * _EPS
        drel = 2 * errdir[pb] / np.maximum(rc_p, 1e-300) + 8 * _EPS

        def arg_bounds(zz, rr=None, upper=False):
            """Lower (upper) bound of the acos argument on z = zz (rr: its sin theta)."""
            if rr is None:
                rr = np.sqrt(np.maximum(1.0 - zz * zz, 0.0))
            den = rc_p * rr
            a = (cos_p - zc_p * zz) / den
            da = dnum / den + np.abs(a) * drel
            out_ = a + da if upper else a - da
            # at a pole (rho = 0) or about a cap centred on one: any longitude may be in
            bad = ~(np.isfinite(out_) & (den > 0))
            out_[bad] = np.inf if upper else -np.inf
            return out_

        zstar = zc_p / cos_p
        zs_in = (zstar >= za) & (zstar <= zb)
        lo_a = arg_bounds(za)
        lo_b = arg_bounds(zb)
        lo_s = arg_bounds(np.where(zs_in, zstar, za))
        amin = np.minimum(np.minimum(lo_a, lo_b), lo_s)
        dph = dphi[pb] + 1e-9
        W = np.arccos(np.clip(amin, -1.0, 1.0)) + dph
        no_cand = empty | (amin > 1.0)
        full_c = (W >= math.pi) | (amin <= -1.0)
        pc = phi_c[pb]
        jc_lo = np.ceil((pc - W) / delta - o - 1).astype(np.int64)
        jc_hi = np.floor((pc + W) / delta - o).astype(np.int64)
        full_c |= jc_hi - jc_lo + 1 >= nr
        # surely lit: the cell's W-E diagonal (on z_i) meets the cap's interior
        hi_i = arg_bounds(z_i, sth_t[ring], upper=True)
        in_z = (z_i > zc_lo[pb]) & (z_i < zc_hi[pb])
        has_s = in_z & (hi_i < 1.0) & ~no_cand
        ws = np.arccos(np.clip(hi_i, -1.0, 1.0)) - dph
        has_s &= ws > 0
        full_s = has_s & (hi_i <= -1.0)
        js_lo = np.floor((pc - ws) / delta - o - 1).astype(np.int64) + 1
        js_hi = np.ceil((pc + ws) / delta - o).astype(np.int64) - 1
        has_s &= js_hi >= js_lo
        full_s |= has_s & (js_hi - js_lo + 1 >= nr)
        js_lo = np.where(full_s, 0, js_lo)
        js_hi = np.where(full_s, nr - 1, js_hi)
        # clip the sure range into the candidate range (it lies inside it in exact terms)
        part_c = ~full_c & ~no_cand
        js_lo = np.where(has_s & part_c, np.maximum(js_lo, jc_lo), js_lo)
        js_hi = np.where(has_s & part_c, np.minimum(js_hi, jc_hi), js_hi)
        has_s &= js_hi >= js_lo

        # --- undecided cells: (pair, j) ---------------------------------------------------
        # left block [u1_lo, u1_hi] and right block [u2_lo, u2_hi] in unwrapped j
        u1_lo = np.where(full_c, np.where(has_s, js_hi + 1, 0), jc_lo)
        u1_hi = np.where(
            full_c,
            np.where(has_s, js_lo + nr - 1, nr - 1),
            np.where(has_s, js_lo - 1, jc_hi),
        )
        u2_lo = np.where(full_c | ~has_s, 1, js_hi + 1)
        u2_hi = np.where(full_c | ~has_s, 0, jc_hi)
        kill = no_cand | full_s
        u1_hi = np.where(kill, u1_lo - 1, u1_hi)
        u2_hi = np.where(kill, u2_lo - 1, u2_hi)
        has_s &= ~no_cand
        c1 = np.maximum(u1_hi - u1_lo + 1, 0)
        c2 = np.maximum(u2_hi - u2_lo + 1, 0)
        cc = c1 + c2
        up = np.repeat(np.arange(pb.size), cc)
        k = np.arange(up.size) - np.repeat(np.cumsum(cc) - cc, cc)
        uj = np.where(k < c1[up], u1_lo[up] + k, u2_lo[up] + k - c1[up])
        upix = first[up] + np.mod(uj, nr[up])
        ub = pb[up]
        lit_u = _decide_cells(
            n,
            upix,
            ub,
            ring[up],
            np.mod(uj, nr[up]),
            shifted[up],
            dx,
            dy,
            dz,
            d,
            s2,
            ds2,
            errdir,
            alpha,
            x,
            y,
            z,
            g,
            cx,
        )

    # --- assemble: per pair the lit j's are one cyclic run (else explicit pieces) ----------
    big_i = np.iinfo(np.int64).max
    uj_lit = uj[lit_u]
    up_lit = up[lit_u]
    lo = np.where(has_s, js_lo, big_i)
    hi = np.where(has_s, js_hi, -big_i)
    num = np.where(has_s, js_hi - js_lo + 1, 0)
    if up_lit.size:  # up is sorted (cells are generated pair by pair): segment reductions
        seg = np.flatnonzero(np.r_[True, up_lit[1:] != up_lit[:-1]])
        keys = up_lit[seg]
        lo[keys] = np.minimum(lo[keys], np.minimum.reduceat(uj_lit, seg))
        hi[keys] = np.maximum(hi[keys], np.maximum.reduceat(uj_lit, seg))
        num[keys] += np.diff(np.r_[seg, up_lit.size])
    anyl = num > 0
    contig = anyl & (hi - lo + 1 == num)
    cp = np.flatnonzero(contig)
    s1, l1, s2_, l2 = _runs_to_pieces(first[cp], nr[cp], lo[cp], hi[cp])
    starts = [s1, s2_]
    lens = [l1, l2]
    balls = [pb[cp], pb[cp]]
    # pairs whose lit cells are not one run (not expected; kept exact all the same)
    odd = np.flatnonzero(anyl & ~contig)
    if odd.size:
        so = np.flatnonzero(has_s[odd])
        a1, b1, a2, b2 = _runs_to_pieces(
            first[odd[so]], nr[odd[so]], js_lo[odd[so]], js_hi[odd[so]]
        )
        starts += [a1, a2]
        lens += [b1, b2]
        balls += [pb[odd[so]], pb[odd[so]]]
        sel = np.isin(up_lit, odd)
        starts.append(first[up_lit[sel]] + np.mod(uj_lit[sel], nr[up_lit[sel]]))
        lens.append(np.ones(int(sel.sum()), np.int64))
        balls.append(pb[up_lit[sel]])
        FALLBACK_COUNTS["non-run rings"] += odd.size
    # whole-eye balls: one piece of every pixel
    wb = np.flatnonzero(whole)
    starts.append(np.zeros(wb.size, np.int64))
    lens.append(np.full(wb.size, npix, np.int64))
    balls.append(wb)
    st = np.concatenate(starts).astype(np.int64)
    ln = np.concatenate(lens).astype(np.int64)
    bl = np.concatenate(balls).astype(np.int64)
    keep = ln > 0
    st, ln, bl = st[keep], ln[keep], bl[keep]
    order = np.lexsort((st, bl))
    st, ln, bl = st[order], ln[order], bl[order]
    per_ball = np.bincount(bl, weights=ln, minlength=nb).astype(np.int64)
    return per_ball, st, ln


# long: vertices, then edges, then exact3d over the same undecided cells and ring tables; split,
# the tables would pass between three functions
def _decide_cells(
    n, upix, ub, uring, uj, ushift, dx, dy, dz, d, s2, ds2, errdir, alpha, x, y, z, g, cx
):
    """Lit flags of the undecided cells: vertices, then edges, then exact3d.

    Cell i is pixel upix[i], cell uj[i] of ring uring[i] (``ushift``: the ring is
    shifted), lit or not by ball ub[i].
    """
    m = upix.size
    out = np.zeros(m, bool)
    if m == 0:
        return out
    FALLBACK_COUNTS["tested"] += m
    cxv = dx[ub] / d[ub]
    cyv = dy[ub] / d[ub]
    czv = dz[ub] / d[ub]
    s2u, ds2u, edu = s2[ub], ds2[ub], errdir[ub]
    cpix = healpix.vec2pix_ring(n, dx, dy, dz)
    # the float centre's pixel is the true centre's when the cap is far wider than the
    # direction's error; a smaller cap's own cell is found exactly below
    sure_centre = alpha[ub] > 1e6 * errdir[ub]
    out |= (upix == cpix[ub]) & sure_centre

    # the 4 vertices from the rings' (sin theta, z) and longitudes L * unit (healpix.
    # vertex_lon): W and E on the cell's ring, N and S on the rings above and below
    sth, zr, unit = _ring_tables(n)
    lw = 2 * uj - (~ushift)
    ui = unit[uring]
    ln, ls = lw + 1, lw + 1
    un, us = ui, ui
    pol = np.flatnonzero((uring <= n) | (uring >= 3 * n))
    if pol.size:
        ln, ls, un, us = ln.copy(), ls.copy(), un.copy(), us.copy()
        pn, pun, _, _, _, pls, pus = healpix.vertex_lon(n, uring[pol], uj[pol])
        ln[pol], un[pol], ls[pol], us[pol] = pn, pun, pls, pus
    ph = np.empty((4, m))
    np.multiply(ln, un, out=ph[0])
    np.multiply(lw, ui, out=ph[1])
    np.multiply(ls, us, out=ph[2])
    np.multiply(lw + 2, ui, out=ph[3])
    rk = np.stack([uring - 1, uring, uring + 1, uring])
    sv, zv = sth[rk], zr[rk]
    vx = sv * np.cos(ph)
    vx -= cxv
    vy = sv * np.sin(ph)
    vy -= cyv
    zv -= czv
    vx *= vx
    vy *= vy
    zv *= zv
    vx += vy
    vx += zv
    fN, fW, fS, fE = vx

    def tol(f):
        return 4 * (np.sqrt(f) + np.sqrt(s2u)) * (_DP + edu) + ds2u + 1e-300

    vmin = np.minimum(np.minimum(fN, fW), np.minimum(fS, fE))
    out |= vmin < s2u - tol(vmin)
    # edges (fixed_is_y, which of the 4 vertices: f_a, f_b); face coordinates, fixed and
    # lo as offsets from (ix, iy): W-N, S-W, S-E, E-N
    edges = (
        (True, 1, 0, fW, fN),
        (False, 0, 0, fS, fW),
        (True, 0, 0, fS, fE),
        (False, 1, 0, fE, fN),
    )
    # the curvature bound is 2 / n^2 off the polar caps (rings n < i < 3n, whose cells'
    # closures lie in |z| <= 2/3); the cells of the other rings get their own
    pol_xyf = healpix.pix2xyf(n, upix[pol]) if pol.size else None
    clear_all = ~out
    open_edges = []
    for fixed_is_y, dfix, dlo, fa, fb in edges:
        mf = np.full(m, 2.5 * 2.0 / (n * n))
        if pol_xyf is not None:
            pix_, piy_, pface = pol_xyf
            pfx, pfy = pix_.astype(np.float64), piy_.astype(np.float64)
            fixed, lo = (pfy + dfix, pfx + dlo) if fixed_is_y else (pfx + dfix, pfy + dlo)
            mf[pol] = 2.5 * _edge_bounds(n, pface, fixed_is_y, fixed, lo)
        lower = _edge_lower(fa, fb, mf)
        clear = lower > s2u + tol(np.maximum(lower, 0.0)) + 8 * _EPS * (fa + fb + mf)
        clear_all &= clear
        open_edges.append((fixed_is_y, dfix, dlo, fa, fb, mf, ~clear & ~out))
    undecided = ~out & ~clear_all
    idx = np.flatnonzero(undecided)
    ix, iy, face = healpix.pix2xyf(n, upix[idx])
    fx, fy = ix.astype(np.float64), iy.astype(np.float64)
    if idx.size:
        FALLBACK_COUNTS["sampled"] += idx.size
        lit_now = np.zeros(idx.size, bool)
        # rows: (cell, edge) pairs still open; each stage samples them K times
        rows = [(k, need[idx]) for k, (*_, need) in enumerate(open_edges)]
        for samples in _STAGES:
            t = np.arange(1, samples) / samples
            still = np.zeros(idx.size, bool)
            new_rows = []
            for k, nd in rows:
                nd = nd & ~lit_now
                if not nd.any():
                    continue
                fixed_is_y, dfix, dlo, fa, fb, mf, _ = open_edges[k]
                FALLBACK_COUNTS[f"edges sampled x{samples}"] += int(nd.sum())
                e = idx[nd]
                fixed, lo = (fy + dfix, fx + dlo) if fixed_is_y else (fx + dfix, fy + dlo)
                fix = np.broadcast_to(fixed[nd, None], (e.size, t.size))
                run = lo[nd, None] + t
                px, py = (run, fix) if fixed_is_y else (fix, run)
                v = healpix.xyf2vec(n, px, py, face[nd, None])
                f = (
                    (v[..., 0] - cxv[e, None]) ** 2
                    + (v[..., 1] - cyv[e, None]) ** 2
                    + (v[..., 2] - czv[e, None]) ** 2
                )
                s2e = s2u[e, None]
                tl = 4 * (np.sqrt(f) + np.sqrt(s2e)) * (_DP + edu[e, None]) + ds2u[e, None]
                lit_now[nd] |= (f < s2e - tl).any(axis=1)
                fmin = np.minimum(f.min(axis=1), np.minimum(fa[e], fb[e]))
                lower = fmin - mf[e] / (8 * samples * samples)
                lw0 = np.maximum(lower, 0.0)
                tle = 4 * (np.sqrt(lw0) + np.sqrt(s2u[e])) * (_DP + edu[e]) + ds2u[e] + 1e-300
                open_ = np.zeros(idx.size, bool)
                open_[nd] = ~(lower > s2u[e] + tle)
                still |= open_
                new_rows.append((k, open_))
            rows = new_rows
        still &= ~lit_now
        out[idx[lit_now]] = True
        rest = idx[~lit_now & still]
    else:
        rest = idx
    # a cap that meets no edge of a cell lies inside it or outside it: its centre decides.
    # Where the float centre cannot be trusted (a cap within 1e6 errors of a point), every
    # candidate cell not yet lit goes to the exact test, or a tiny cap would light nothing.
    pending = np.zeros(m, bool)
    pending[rest] = True
    tiny = np.flatnonzero(~out & ~pending & ~sure_centre)
    rest = np.concatenate([rest, tiny]).astype(np.int64)
    if rest.size:
        rix, riy, rface = healpix.pix2xyf(n, upix[rest])
        for k, i in enumerate(rest):
            FALLBACK_COUNTS["exact"] += 1
            b = int(ub[i])
            out[i] = exact3d.cell_lit(
                n,
                Fraction(float(x[b])) - Fraction(cx),
                Fraction(float(y[b])),
                Fraction(float(z[b])),
                Fraction(float(g[b])),
                int(rface[k]),
                int(rix[k]),
                int(riy[k]),
                int(upix[i]),
            )
    return out
