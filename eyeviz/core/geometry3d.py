"""The spherical binocular eye: two HEALPix eyes, features are balls (docs/spherical.md).

Two spherical eyes of radius l at A = (-h, 0, 0) and B = (h, 0, 0); x right, y forward,
z up; the plane z = 0 is the paper's planar model (Section 8 names this as its next goal).
Facets are HEALPix cells in RING order (:mod:`eyeviz.core.healpix`), 12 nside^2 per eye.

A facet is lit iff some direction of the closed tangent cone from the eye centre to the
ball (the cap of half-angle alpha = asin(g / |d|) about d / |d|; the whole eye when
|d| <= g) maps to it under ang2pix, in exact real arithmetic on the float inputs: the 3D
Proposition 2. The cap is closed with interior and a cell is the closure of its interior
minus part of its boundary, so a cell is lit iff the distance from the cap centre to the
cell's closure is < alpha, or = alpha with a touch point that ang2pix maps to the cell.

The float64 fast path, per ball and eye: the rings the cap's z-range meets; per ring the
candidate cells from the cap's widest longitude span over the ring's z-band and the
surely lit cells from its span on the ring's own z (where each cell's W-E diagonal lies);
the few cells between are tested on their vertices and edges with a proven
second-derivative bound of the edge curves plus the rounding bound of float64. Only the
cells that stay within both bounds of the cap's boundary reach :mod:`eyeviz.core.exact3d`.
Lit sets come out as per-ring runs, hence sorted without a sort of the indices.
"""

from __future__ import annotations

import math
from collections import Counter
from dataclasses import dataclass
from fractions import Fraction

import numpy as np

from eyeviz.core import exact3d, healpix, kernels, tiny_caps
from eyeviz.core.bounds import MAX_NSIDE, check_nside
from eyeviz.core.geometry import _first_index, check_h_l, eye_x

__all__ = ["EyePair3D", "validate_balls", "MAX_NSIDE", "MAX_LIT", "FALLBACK_COUNTS"]

_EPS = 2.0**-52
_DP = 64 * _EPS  # error of a facet vertex vector from healpix.xyf2vec
_STAGES = (16, 256)  # samples per edge in the second and third stages
_SQ6 = math.sqrt(6.0)
#: Largest number of lit indices one call may return (2^28 int64: 2 GiB). A whole eye at
#: nside 2^20 is 1.3e13 facets: such a lit set exists only as runs, not as indices.
MAX_LIT = 1 << 28
_BLOCK = 512  # balls per block of the fast path at nside 64 (more at smaller nside)


def _block(n: int) -> int:
    """Balls per block: about _BLOCK * 64 / nside (the (ball, ring) pairs and boundary
    cells per ball grow like nside), within [256, 2048] (measured best at 16, 64, 180)."""
    return int(min(2048, max(256, _BLOCK * 64 // n)))


#: Diagnostics: cells the vertex/edge test could not clear ("tested"), cells that needed
#: edge sampling ("sampled") and cells decided in mpmath ("exact").
FALLBACK_COUNTS: Counter[str] = Counter()


def validate_balls(x, y, z, g) -> tuple[np.ndarray, ...]:
    """Broadcast x, y, z, g to float64; refuse non-finite values and g <= 0."""
    try:
        arrs = np.broadcast_arrays(*(np.asarray(v, dtype=np.float64) for v in (x, y, z, g)))
    except (TypeError, ValueError) as exc:
        raise ValueError(
            f"x, y, z, g must be real numbers of broadcastable shapes: {exc}"
        ) from None
    for name, a in zip("xyzg", arrs, strict=True):
        bad = ~np.isfinite(a)
        if bad.any():
            raise ValueError(
                f"{name} has {int(bad.sum())} non-finite value(s) (NaN or inf); "
                f"first at index {_first_index(bad)}"
            )
    bad = arrs[3] <= 0
    if bad.any():
        raise ValueError(
            f"g (feature radius) must be > 0: {int(bad.sum())} value(s) are not; "
            f"first at index {_first_index(bad)}"
        )
    return tuple(arrs)


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


_TABLES: dict[int, tuple[np.ndarray, np.ndarray, np.ndarray]] = {}


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


_INFO: dict[int, tuple[np.ndarray, ...]] = {}


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


def _lit_runs(n: int, x, y, z, g, cx: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The lit facets of one eye for flat float64 arrays of balls, as runs: (lit facets
    per ball, run starts, run lengths), the runs sorted by ball, then start. The compiled
    kernel (:mod:`eyeviz.core.kernels.healpix_lit`) where it is in use, else the numpy
    reference :func:`_lit_runs_ref`."""
    if kernels.use(x.shape[0]):
        return _lit_runs_jit(n, x, y, z, g, cx)
    return _lit_runs_ref(n, x, y, z, g, cx)


def _lit_runs_jit(n: int, x, y, z, g, cx: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The kernel's runs; the balls it leaves to the exact branches go through
    :func:`_lit_runs_ref` and are merged in."""
    from eyeviz.core.kernels.healpix_lit import lit_runs_kernel

    sth, zr, unit = _ring_tables(n)
    first, nr, shifted, delta, o = _ring_info_tables(n)
    x, y, z, g = (np.ascontiguousarray(v, dtype=np.float64) for v in (x, y, z, g))
    status, per, st, ln, bl = lit_runs_kernel(
        n, x, y, z, g, float(cx), sth, zr, unit, first, nr, shifted, delta, o
    )
    kernels.mark_ready()
    ref = np.flatnonzero(status)
    if ref.size == 0:
        return per, st, ln
    FALLBACK_COUNTS["kernel -> reference balls"] += ref.size
    p2, s2, l2 = _lit_runs_ref(n, x[ref], y[ref], z[ref], g[ref], cx)
    per[ref] = p2
    bl = np.concatenate([bl, ref[tiny_caps.run_balls(p2, l2)]])
    st = np.concatenate([st, s2])
    ln = np.concatenate([ln, l2])
    order = np.lexsort((st, bl))
    return per, st[order], ln[order]


def _lit_runs_ref(n: int, x, y, z, g, cx: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`_lit_runs` in numpy (the reference). Caps far below their direction's
    rounding error go through :mod:`eyeviz.core.tiny_caps`."""
    tiny = tiny_caps.tiny_mask(x, y, z, g, cx)
    if not tiny.any():
        return _lit_runs_fast(n, x, y, z, g, cx)
    parts = []
    for sel, fn in ((~tiny, _lit_runs_fast), (tiny, _lit_runs_tiny)):
        idx = np.flatnonzero(sel)
        per, st, ln = fn(n, x[idx], y[idx], z[idx], g[idx], cx)
        parts.append((idx[tiny_caps.run_balls(per, ln)], st, ln, idx, per))
    bl, st, ln = (np.concatenate([p[k] for p in parts]) for k in range(3))
    order = np.lexsort((st, bl))
    per_ball = np.zeros(x.shape[0], np.int64)
    for p in parts:
        per_ball[p[3]] = p[4]
    return per_ball, st[order], ln[order]


def _lit_runs_tiny(n: int, x, y, z, g, cx: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    return tiny_caps.tiny_lit_runs(n, x, y, z, g, cx, _lit_runs_fast)


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


def _runs_to_csr(per_ball, st, ln) -> tuple[np.ndarray, np.ndarray]:
    """(indptr, indices) from runs (start, length) sorted by ball, then start."""
    nb = per_ball.size
    indptr = np.zeros(nb + 1, np.int64)
    np.cumsum(per_ball, out=indptr[1:])
    total = int(indptr[-1])
    # runs -> indices in one pass: steps of 1 inside a run, a jump at each run's start
    indices = np.ones(total, np.int64)
    if total:
        pos = np.cumsum(ln) - ln
        jump = st.copy()
        jump[1:] -= st[:-1] + ln[:-1] - 1
        indices[pos] = jump
        np.cumsum(indices, out=indices)
    return indptr, indices


def _lit_eye(n: int, x, y, z, g, cx: float) -> tuple[np.ndarray, np.ndarray]:
    """(indptr, indices) of the lit facets of one eye for flat float64 arrays of balls."""
    return _runs_to_csr(*_lit_runs(n, x, y, z, g, cx))


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


@dataclass(frozen=True)
class EyePair3D:
    """Two spherical HEALPix eyes (docs/spherical.md; the paper's Section 8 goal).

    Parameters
    ----------
    h : distance from the origin to each eye centre (eyes 2h apart), h > l.
    l : eye radius, l > 0.
    nside : HEALPix resolution, an even integer in [2, MAX_NSIDE]; 12 nside^2 facets per
        eye, m = 4 nside of them on the equator (the planar eye EyePair(h, l, 4 nside)).
    """

    h: float = 40.0
    l: float = 20.0
    nside: int = 180

    def __post_init__(self) -> None:
        h, l = check_h_l(self.h, self.l)
        n = check_nside(self.nside)
        object.__setattr__(self, "h", h)
        object.__setattr__(self, "l", l)
        object.__setattr__(self, "nside", n)

    @property
    def npix(self) -> int:
        """Facets per eye, 12 nside^2."""
        return 12 * self.nside * self.nside

    @property
    def m(self) -> int:
        """Facets on the equator, 4 nside (the planar eye's m)."""
        return 4 * self.nside

    @property
    def psi(self) -> float:
        """Half-angle of each eye's tangent cone from the origin, asin(l / h) (Eq. 15)."""
        return math.asin(self.l / self.h)

    @property
    def centers(self) -> tuple[tuple[float, float, float], tuple[float, float, float]]:
        """((-h, 0, 0), (h, 0, 0)): eye A (left) and eye B (right)."""
        return ((-self.h, 0.0, 0.0), (self.h, 0.0, 0.0))

    # --- the eye-model seam (eyeviz.core.eyes.EyeModel) --------------------------------
    @property
    def kind(self) -> str:
        """``"spherical"``: HEALPix eyes in space (docs/spherical.md)."""
        return "spherical"

    @property
    def dims(self) -> int:
        """Coordinates of a feature centre: 3 (x, y, z)."""
        return 3

    @property
    def facet_counts(self) -> tuple[int, int]:
        """Facets of eye A and of eye B: (12 nside^2, 12 nside^2)."""
        return (self.npix, self.npix)

    @property
    def design(self) -> dict[str, float | int]:
        """{"h", "l", "nside"}: what a scene, a data set or an estimator must agree on."""
        return {"h": self.h, "l": self.l, "nside": self.nside}

    def _cx(self, eye: str) -> float:
        return eye_x(self.h, eye)

    def facet(self, x, y, z, eye: str) -> np.ndarray:
        """RING index of the direction from the eye centre to the point (Prop. 1 in 3D).

        Exact on the float inputs: a point within rounding of a cell edge is decided by
        ang2pix in mpmath with the floors snapped (:func:`exact3d.ang2pix_snap`); the eye
        centre itself is given the facet of the north pole (0), as atan2(0, 0) = 0.
        """
        cx = self._cx(eye)
        xa, ya, za, _ = validate_balls(x, y, z, 1.0)
        shape = xa.shape
        xa, ya, za = xa.ravel(), ya.ravel(), za.ravel()
        n = self.nside
        dx = xa - cx
        out = healpix.vec2pix_ring(n, dx, ya, za)
        # a point is near a boundary when a cap of the rounding radius about it is not
        # inside one cell: the lit set of a tiny ball says so, exactly
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            r = np.sqrt(dx * dx + ya * ya + za * za)
        ok = (r > 1e-150) & (r < 1e150)
        i = np.flatnonzero(ok)
        # the lit set of a ball of angular radius 1e-8 about the point is exact: one cell
        # means the point's direction lies inside it
        ip, idx = _lit_eye(n, xa[i], ya[i], za[i], 1e-8 * r[i], cx)
        one = np.diff(ip) == 1
        out[i[one]] = idx[ip[:-1][one]]
        todo = i[~one]
        todo = np.concatenate([todo, np.flatnonzero(~ok)])
        import mpmath

        for j in todo:
            X = Fraction(float(xa[j])) - Fraction(cx)
            Y, Z = Fraction(float(ya[j])), Fraction(float(za[j]))
            if X == 0 and Y == 0 and Z == 0:
                out[j] = 0
                continue
            prec = 200 + 2 * max(
                abs(v.numerator).bit_length() + v.denominator.bit_length() for v in (X, Y, Z)
            )
            with mpmath.workprec(prec):
                v = tuple(mpmath.mpf(q.numerator) / q.denominator for q in (X, Y, Z))
                out[j] = exact3d.ang2pix_snap(n, v, mpmath.ldexp(1, -prec // 2))
        return out.reshape(shape)

    def lit_csr(self, x, y, z, g) -> tuple[tuple[np.ndarray, np.ndarray], ...]:
        """Per eye (A, B): (indptr, indices) of the lit facets, CSR over the flattened
        balls; indices sorted int64 RING indices per row (the 3D Proposition 2)."""
        xa, ya, za, ga = validate_balls(x, y, z, g)
        xf, yf, zf, gf = (np.ascontiguousarray(a).reshape(-1) for a in (xa, ya, za, ga))
        nb, n = xf.shape[0], self.nside
        est = 0.0
        with np.errstate(over="ignore", under="ignore", invalid="ignore", divide="ignore"):
            for cx in (-self.h, self.h):
                q = gf / np.hypot(np.hypot(xf - cx, yf), zf)
                est += float(np.where(q >= 1, 1.0, 0.5 * q * q).sum()) * self.npix
        if est > MAX_LIT:
            raise ValueError(
                f"the lit sets would hold about {est:.3g} facets (more than {MAX_LIT}): "
                "use fewer or smaller balls per call, or a smaller nside"
            )
        out = []
        block = _block(n)
        for cx in (-self.h, self.h):
            # blocks of balls keep the temporaries in cache; the indices are written once,
            # from the runs of every block
            runs = [
                _lit_runs(n, xf[s:e], yf[s:e], zf[s:e], gf[s:e], cx)
                for s, e in ((s, min(nb, s + block)) for s in range(0, nb, block))
            ]
            if runs:
                cat = [np.concatenate(r) for r in zip(*runs, strict=True)]
                out.append(_runs_to_csr(*cat))
            else:
                out.append((np.zeros(1, np.int64), np.zeros(0, np.int64)))
        return out[0], out[1]

    def lit(self, x, y, z, g) -> tuple[np.ndarray, np.ndarray]:
        """One ball: (lit_a, lit_b), sorted int64 RING indices of the lit facets."""
        for name, v in zip("xyzg", (x, y, z, g), strict=True):
            if np.ndim(v) != 0:
                raise ValueError(f"{name} must be a scalar for lit(); use lit_csr for arrays")
        (pa, ia), (pb, ib) = self.lit_csr(x, y, z, g)
        return ia[pa[0] : pa[1]], ib[pb[0] : pb[1]]

    def bitmaps(self, x, y, z, g) -> tuple[np.ndarray, np.ndarray]:
        """(omega_a, omega_b) bool of shape (..., npix)."""
        xa, _, _, _ = validate_balls(x, y, z, g)
        shape = xa.shape
        res = []
        for indptr, idx in self.lit_csr(x, y, z, g):
            nb = indptr.size - 1
            bm = np.zeros((nb, self.npix), bool)
            rows = np.repeat(np.arange(nb), np.diff(indptr))
            bm[rows, idx] = True
            res.append(bm.reshape(shape + (self.npix,)))
        return res[0], res[1]

    def visible(self, x, y, z, g) -> tuple[np.ndarray, np.ndarray]:
        """Definition 1 per eye: the ball lights at least two facets (vis_a, vis_b)."""
        xa, _, _, _ = validate_balls(x, y, z, g)
        (pa, _), (pb, _) = self.lit_csr(x, y, z, g)
        return (np.diff(pa) >= 2).reshape(xa.shape), (np.diff(pb) >= 2).reshape(xa.shape)

    def in_bfv(self, x, y, z, g) -> np.ndarray:
        """The closed ball lies in the 3D binocular field of view (Prop. 4 generalised).

        In front (y >= g) and outside both open tangent cones from the origin to the eyes:
        w * sqrt(y^2 + z^2) - l * |x| >= g * h with w = sqrt(h^2 - l^2); on z = 0 this is
        Eq. 17 (docs/spherical.md derives it).
        """
        xa, ya, za, ga = validate_balls(x, y, z, g)
        shape = xa.shape
        xa, ya, za, ga = xa.ravel(), ya.ravel(), za.ravel(), ga.ravel()
        h, l = self.h, self.l
        with np.errstate(over="ignore", invalid="ignore", under="ignore"):
            w = math.sqrt((h - l) * (h + l))
            b = np.hypot(ya, za)
            lhs = w * b
            rhs = l * np.abs(xa) + ga * h
            tol = 16 * _EPS * (lhs + rhs)
            near = (np.abs(lhs - rhs) <= tol) | ~np.isfinite(lhs + rhs)
            near |= ~(lhs + rhs >= 2.0**-900) & (ya >= ga)
        out = (ya >= ga) & (lhs >= rhs)
        for i in np.flatnonzero(near & (ya >= ga)):
            X, Y, Z, G = (Fraction(float(v[i])) for v in (xa, ya, za, ga))
            H, L = Fraction(h), Fraction(l)
            # w b >= l|x| + g h  <=>  (h^2 - l^2)(y^2 + z^2) >= (l|x| + g h)^2, both >= 0
            out[i] = (H * H - L * L) * (Y * Y + Z * Z) >= (L * abs(X) + G * H) ** 2
        return out.reshape(shape)

    def overlaps_eye(self, x, y, z, g) -> tuple[np.ndarray, np.ndarray]:
        """Per eye: the closed ball meets the closed eye ball of radius l."""
        xa, ya, za, ga = validate_balls(x, y, z, g)
        shape = xa.shape
        xa, ya, za, ga = xa.ravel(), ya.ravel(), za.ravel(), ga.ravel()
        res = []
        for cx in (-self.h, self.h):
            with np.errstate(over="ignore", invalid="ignore", under="ignore"):
                dx = xa - cx
                d2 = dx * dx + ya * ya + za * za
                s = ga + self.l
                rhs = s * s
                tot = d2 + rhs
                near = np.abs(d2 - rhs) <= 16 * _EPS * tot + 8 * _EPS * (np.abs(xa) + self.h) * s
                near |= ~(tot >= 2.0**-900) | ~np.isfinite(tot)
            out = d2 <= rhs
            for i in np.flatnonzero(near):
                X = Fraction(float(xa[i])) - Fraction(cx)
                Y, Z = Fraction(float(ya[i])), Fraction(float(za[i]))
                S = Fraction(float(ga[i])) + Fraction(self.l)
                out[i] = X * X + Y * Y + Z * Z <= S * S
            res.append(out.reshape(shape))
        return res[0], res[1]
