"""The spherical limit's proposal regions compiled (numba): the measured eyes' cone
distances (:meth:`eyeviz.estimators.limit3d_measured._Edges.bounds`), their draws, the
HEALPix prefilter and the exact check's row comparison. (The HEALPix eyes' affine model
is in :mod:`.limit3d_affine`, its ray search with the draws that call it in
:mod:`.limit3d_draws`.)

Scalar transcriptions of the numpy references, which ``EYEVIZ_JIT=0`` runs instead
(docs/kernels.md). The reductions keep numpy's NaN rules (a NaN anywhere in a max or min
gives NaN). The measured cone distances are computed without the reference's arctan2 and
sin (:func:`_cone`), and the reference's matrix products (BLAS) round differently: they
agree to about 1e-13 of the distances. Only where draws are proposed depends on these
numbers; every draw is still checked exactly.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

__all__ = [
    "cone_bounds_kernel",
    "direction_keep_kernel",
    "uniforms_kernel",
    "dir_grid_kernel",
    "measured_prior",
    "bcentre",
    "bcentre_at",
    "same_rows_kernel",
    "spread_rows_kernel",
    "constraining_kernel",
    "prefilter_kernel",
    "compact_draws_kernel",
    "warm",
]

_jit = njit(cache=True, nogil=True)
#: division as numpy's (x / 0 is inf or NaN, not an exception), for the kernels whose
#: reference divides by numbers that can be 0 (the measured draws)
_jit_np = njit(cache=True, nogil=True, error_model="numpy")
#: the measured draws' helpers (per facet and per draw), inlined into their callers by
#: numba: a call it does not inline counts a reference on every array it passes and is
#: not inlined by LLVM either, which cost more than a cone distance's arithmetic
#: (docs/limit3d.md, "bee33c"). Only measured_limit's kernels inline array-taking ones
#: (its fold and walks over one table of both eyes' live facets, ``bcentre_inline`` in
#: the draws' kernel; the box search writes its walk out with scalars, ``bcentre_at``, as
#: an inlined function's arrays count references too: "bee33h"): each inlined copy costs
#: compile time; the cone bounds keep calls.
_inline = njit(cache=True, nogil=True, inline="always")
_inline_np = njit(cache=True, nogil=True, error_model="numpy", inline="always")


@_inline
def _max(m, x):
    """numpy's maximum: NaN wins."""
    if m != m:
        return m
    if x != x or x > m:
        return x
    return m


@_inline
def _min(m, x):
    """numpy's minimum: NaN wins."""
    if m != m:
        return m
    if x != x or x < m:
        return x
    return m


@_inline
def _cone(pos, ax, ch, sh, n, k, cx, cy, cz):
    """(dist(c, K_k), |c - p_k|) of facet k of key n: with v = c - p, s = v . a and
    q = |v x a| (a unit), |v| sin(theta - alpha) = q C - s S and |v| cos(theta - alpha)
    = s C + q S (C, S = cos, sin alpha), so the reference's arctan2 and sin are not
    needed: 0 where q C - s S <= 0 (inside the cone), q C - s S where s C + q S > 0 (the
    nearest point on the cone's edge), |v| otherwise (the apex)."""
    vx, vy, vz = cx - pos[n, k, 0], cy - pos[n, k, 1], cz - pos[n, k, 2]
    a0, a1, a2 = ax[n, k, 0], ax[n, k, 1], ax[n, k, 2]
    s = vx * a0 + vy * a1 + vz * a2
    wx, wy, wz = vy * a2 - vz * a1, vz * a0 - vx * a2, vx * a1 - vy * a0
    q = math.sqrt(wx * wx + wy * wy + wz * wz)
    vn = math.sqrt(vx * vx + vy * vy + vz * vz)
    c, sn = ch[n, k], sh[n, k]
    m = q * c - s * sn
    if m <= 0.0:
        return 0.0, vn
    if s * c + q * sn > 0.0:
        return m, vn
    return vn, vn


@_jit
def _cone_fold(pos, ax, ch, sh, lit, n, k, cx, cy, cz, lo, hi):
    """lo, hi with facet k of key n folded in (lit: its cone's distance into lo, its lens'
    into hi; unlit: its cone's into hi)."""
    d, vn = _cone(pos, ax, ch, sh, n, k, cx, cy, cz)
    if lit[n, k]:
        return _max(lo, d), _min(hi, vn)
    return lo, _min(hi, d)


@_jit
def cone_bounds_kernel(pos, ax, ch, sh, lit, pad, c, lo, hi):
    """_Edges.bounds: (largest distance of a lit cone, smallest of an unlit cone or of a
    lit lens) (N, G) at centres c (N, G, 3)."""
    for n in range(c.shape[0]):
        for g in range(c.shape[1]):
            cx, cy, cz = c[n, g, 0], c[n, g, 1], c[n, g, 2]
            lo_, hi_ = -np.inf, np.inf
            for k in range(pos.shape[1]):
                if not pad[n, k]:
                    lo_, hi_ = _cone_fold(pos, ax, ch, sh, lit, n, k, cx, cy, cz, lo_, hi_)
            lo[n, g], hi[n, g] = lo_, hi_


@_inline
def _empty(lo, hi):
    """The sampler's test of an empty g interval (limit3d_measured.MeasuredProposal.sample:
    pad = 1e-9 g_hi, then g_hi + pad > max(g_lo - pad, 0) keeps the draw), in the same
    operations. Monotone: true for (lo, hi) is true for any larger lo or smaller hi."""
    pad = 1e-9 * hi
    low = lo - pad
    if low < 0.0:
        low = 0.0
    return not (hi + pad > low)


@_inline_np
def bcentre_at(u00, u01, u02, e10, e11, e12, e20, e21, e22, d0, d1, beta, f0, f1, f2, b0, b1,
               b2, blen):  # fmt: skip
    """:func:`bcentre` with the frame u0, e1, e2, A's centre fa and b_hat as scalars (its
    body: :func:`bcentre` reads its arrays' items and calls this): an array passed to a
    function, even an inlined one, counts an atomic reference on entry and exit
    (docs/limit3d.md, "hp31h"), which per draw cost more than the arithmetic."""
    vx = u00 + d0 * e10 + d1 * e20
    vy = u01 + d0 * e11 + d1 * e21
    vz = u02 + d0 * e12 + d1 * e22
    nv = math.sqrt(vx * vx + vy * vy + vz * vz)
    vx, vy, vz = vx / nv, vy / nv, vz / nv
    ca = min(max(vx * b0 + vy * b1 + vz * b2, -1.0), 1.0)
    sa = math.sqrt((1.0 - ca) * (1.0 + ca))
    rho, drho = np.nan, np.nan
    if beta > 0 and beta < math.pi:
        sb, cb = math.sin(beta), math.cos(beta)
        s_ab = sa * cb + ca * sb
        if s_ab > 0.0:
            rho = blen * sb / s_ab
            drho = blen * sa / (s_ab * s_ab)
    return f0 + vx * rho, f1 + vy * rho, f2 + vz * rho, rho, drho


@_jit_np
def bcentre(u0, e1, e2, d0, d1, beta, fa, bhat, blen):
    """limit3d_measured.MeasuredProposal._bcentres for one draw: (centre x, y, z, rho,
    d rho / d beta) at gnomonic offsets (d0, d1) of A's direction about u0 (frame e1, e2)
    and angle beta at o_B (rho = |b| sin(beta) / sin(a + beta)); rho and d rho NaN where
    the rays do not meet in front (beta <= 0 or a + beta >= pi). Without the reference's
    arccos and three sines: cos a = v . b_hat, sin a = sqrt((1 - cos a)(1 + cos a)) (a in
    [0, pi]), sin(a + beta) = sin a cos beta + cos a sin beta; for beta in (0, pi), a +
    beta lies in (0, 2 pi), so the rays meet in front iff sin(a + beta) > 0 (the draws'
    kernel 1.1-1.2x, docs/limit3d.md "bee33e")."""
    return bcentre_at(u0[0], u0[1], u0[2], e1[0], e1[1], e1[2], e2[0], e2[1], e2[2], d0, d1,
                      beta, fa[0], fa[1], fa[2], bhat[0], bhat[1], bhat[2], blen)  # fmt: skip


#: :func:`bcentre` inlined, for the draws' kernel (measured_limit.mixture_draws_kernel)
bcentre_inline = _inline_np(bcentre.py_func)


@_inline_np
def measured_prior(r, g, el, az, s_half, g_max, r_min, r_max, el_max, multi):
    """limit3d_exact.prior_density of a measured pair for one ball (no cones: the azimuth
    uniform on [0, pi]); 0 outside the support."""
    inside = r >= r_min and r <= r_max and g >= r * s_half and g <= g_max and g <= r
    if not (inside and abs(el) <= el_max and az >= 0.0 and az <= math.pi):
        return 0.0
    cel = math.cos(el)
    dens = r * r * cel if multi else 1.0
    dens = dens / ((g_max - r * s_half) * math.pi * r * r * cel)
    return dens if math.isfinite(dens) else 0.0


_GOLD = np.uint64(0x9E3779B97F4A7C15)
_M1 = np.uint64(0xBF58476D1CE4E5B9)
_M2 = np.uint64(0x94D049BB133111EB)


@_jit
def _mix64(z):
    """limit3d_proposal._mix of one uint64 (splitmix64's finaliser, wrapping)."""
    z = z + _GOLD
    z = (z ^ (z >> np.uint64(30))) * _M1
    z = (z ^ (z >> np.uint64(27))) * _M2
    return z ^ (z >> np.uint64(31))


@_jit
def uniforms_kernel(keys, m, streams, out):
    """limit3d_proposal._batch_uniforms: out (N, m * len(streams), k) uniforms in (0, 1),
    stream s's batch at columns s * m, each the same uint64 hash of the key and the
    counter as the reference's, so the same floats bit for bit."""
    k = out.shape[2]
    for n in range(keys.size):
        base = keys[n] * _M1
        for si in range(streams.size):
            off = np.uint64(streams[si]) << np.uint64(32)
            for j in range(m * k):
                z = _mix64(base + (np.uint64(j) + off))
                out[n, si * m + j // k, j % k] = (np.float64(z >> np.uint64(11)) + 0.5) * 2.0**-53


@_inline
def _cell_out(ax, half, lit, pad, n, vx, vy, vz, lim_f, lim_l, last):
    """direction_keep_kernel's test of one cell of key n (centre direction v): (dropped,
    the facet that settled it, else ``last``), the walk starting at facet ``last``."""
    top, bot = -np.inf, np.inf
    for j in range(ax.shape[1] + 1):
        k = last if j == 0 else j - 1
        if (j > 0 and k == last) or pad[n, k]:
            continue
        c = vx * ax[n, k, 0] + vy * ax[n, k, 1] + vz * ax[n, k, 2]
        ang = math.acos(min(max(c, -1.0), 1.0)) - half[n, k]
        if lit[n, k]:
            top = max(top, ang)
        else:
            bot = min(bot, ang)
        if top - bot > lim_f or top > lim_l:
            return True, k
    return False, last


@_jit
def direction_keep_kernel(ax, half, lit, pad, v, t, s, h, keep):
    """limit3d_provable.dir_region's test of its grid's cells: cell g of
    key n (centre direction v[n, g], half diagonal h[n]) is kept unless F > t + 2 h or L >
    s + h at its centre (F: the largest angle(a_i, v) - alpha_i of a lit facet less the
    smallest of an unlit one; L: the first term; a 1e-7 rad margin for arccos's
    rounding). Both terms only grow along the walk over the facets, so a cell is dropped
    at its first facet that settles it; each key's last such facet is tried first."""
    for n in range(v.shape[0]):
        last = 0
        lim_f = t[n] + 2.0 * h[n] + 1e-7
        lim_l = s[n] + h[n] + 1e-7
        for g in range(v.shape[1]):
            out, last = _cell_out(ax, half, lit, pad, n, v[n, g, 0], v[n, g, 1], v[n, g, 2],
                                  lim_f, lim_l, last)  # fmt: skip
            keep[n, g] = not out


@_jit
def dir_grid_kernel(ax, half, lit, pad, w0, e1, e2, t, s, lo, hi, g2, grid, levels, v, keep,
                    h, ok):  # fmt: skip
    """limit3d_provable.dir_region's zooming grids, key by key in one call: per level the
    cells of the box [lo, hi] (gnomonic, about w0 in the frame e1, e2; g2 the cells'
    centres in [0, 1]^2, ``grid`` a side), their centres' directions, the test of
    direction_keep_kernel, and the next box the kept cells' span (ok[n] False and the box
    kept where none is). v, keep and h are the last level's. The same arithmetic as the
    numpy loop there (its norm's sums in the same order), so the same cells bit for bit."""
    for n in range(w0.shape[0]):
        last = 0
        lo0, lo1, hi0, hi1 = lo[n, 0], lo[n, 1], hi[n, 0], hi[n, 1]
        for _ in range(levels):
            sp0, sp1 = hi0 - lo0, hi1 - lo1
            hn = 0.5 * math.hypot(sp0, sp1) / grid
            h[n] = hn
            lim_f = t[n] + 2.0 * hn + 1e-7
            lim_l = s[n] + hn + 1e-7
            hf0, hf1 = 0.5 * sp0 / grid, 0.5 * sp1 / grid
            n0, n1, x0, x1 = np.inf, np.inf, -np.inf, -np.inf
            some = False
            for g in range(g2.shape[0]):
                d0 = lo0 + sp0 * g2[g, 0]
                d1 = lo1 + sp1 * g2[g, 1]
                vx = w0[n, 0] + d0 * e1[n, 0] + d1 * e2[n, 0]
                vy = w0[n, 1] + d0 * e1[n, 1] + d1 * e2[n, 1]
                vz = w0[n, 2] + d0 * e1[n, 2] + d1 * e2[n, 2]
                nv = math.sqrt(vx * vx + vy * vy + vz * vz)
                vx, vy, vz = vx / nv, vy / nv, vz / nv
                v[n, g, 0], v[n, g, 1], v[n, g, 2] = vx, vy, vz
                out, last = _cell_out(ax, half, lit, pad, n, vx, vy, vz, lim_f, lim_l, last)
                keep[n, g] = not out
                if not out:
                    some = True
                    n0, n1 = min(n0, d0 - hf0), min(n1, d1 - hf1)
                    x0, x1 = max(x0, d0 + hf0), max(x1, d1 + hf1)
            if some:
                lo0, lo1, hi0, hi1 = n0, n1, x0, x1
            else:
                ok[n] = False


@_jit
def _cell_fails(pts, lit, n, k, cx, cy, cz, a, s):
    """Edge cell k of key n rules the cap (c, a) out (limit3d_proposal._prefilter): from
    its nearest boundary sample's distance ds, a lit cell needs a + gap(ds) + 1e-9 > ds,
    an unlit one a <= ds + 1e-9 (gap: _sample_gap, samples s apart)."""
    best = -np.inf
    for j in range(pts.shape[2]):
        dot = pts[n, k, j, 0] * cx + pts[n, k, j, 1] * cy + pts[n, k, j, 2] * cz
        best = max(best, dot)
    ds = math.acos(min(max(best, -1.0), 1.0))
    if lit[n, k]:
        d_lo = math.sqrt(max(ds * ds - 0.25 * s * s, 0.0))
        gap = 1.5 * (math.sqrt(d_lo * d_lo + 0.25 * s * s) - d_lo)
        return a + gap + 1e-9 <= ds
    return a > ds + 1e-9


@_jit
def prefilter_kernel(pts, lit, pad, row, c, alpha, s, ok):
    """limit3d_proposal._prefilter with an early exit: a draw (key row[i], cap centre
    c[i], radius alpha[i]) fails at its first edge cell that rules it out; each key's last
    such cell is tried first. The condition keeps a 1e-9 rad margin, far above the
    rounding in which this and the numpy reference differ (the order of a dot product's
    terms, acos), so both keep every draw the exact check accepts."""
    last = np.zeros(pts.shape[0], np.int64)
    for i in range(row.size):
        n = row[i]
        cx, cy, cz, a = c[i, 0], c[i, 1], c[i, 2], alpha[i]
        k0 = last[n]
        bad = not pad[n, k0] and _cell_fails(pts, lit, n, k0, cx, cy, cz, a, s)
        k = np.int64(0)  # as k0: one signature of _cell_fails (a literal 0 compiled another)
        while not bad and k < pts.shape[1]:
            if k != k0 and not pad[n, k] and _cell_fails(pts, lit, n, k, cx, cy, cz, a, s):
                bad = True
                last[n] = k
            k += 1
        ok[i] = not bad


@_jit
def constraining_kernel(ptr, ind, nb, seen, fac, lit, cnt):
    """limit3d_cones._Edges' constraining facets of each CSR row (ptr, ind) of an eye of
    ``seen.size`` facets: its lit facets in row order, then, ascending, the unlit facets
    within two rings of axis neighbours (nb (F, K)) of them; written row after row into
    fac and lit (capacity enough), each row's count in cnt. ``seen`` (F,) all -1 on entry
    (a row's stamps; the same facets and order as the numpy sets' way)."""
    at = 0
    for n in range(ptr.size - 1):
        start = at
        own, near = 2 * n, 2 * n + 1
        for q in range(ptr[n], ptr[n + 1]):
            seen[ind[q]] = own
        for q in range(ptr[n], ptr[n + 1]):
            fac[at] = ind[q]
            lit[at] = True
            at += 1
            for a in range(nb.shape[1]):
                j = nb[ind[q], a]
                if seen[j] != own:
                    seen[j] = near
                for b in range(nb.shape[1]):
                    k = nb[j, b]
                    if seen[k] != own:
                        seen[k] = near
        for i in range(seen.size):
            if seen[i] == near:
                fac[at] = i
                lit[at] = False
                at += 1
        cnt[n] = at - start


@_jit_np
def spread_rows_kernel(row, r, w, mean, sd, ess):
    """limit3d_rows._spread_flat's sums, each in storage order as ``np.bincount``'s: per row
    of the accepted draws (row, r, w) the weighted mean and standard deviation of r and
    the effective sample size; the same values bit for bit (NaN where a row has none)."""
    n = mean.size
    tot = np.zeros(n)
    sw2 = np.zeros(n)
    var = np.zeros(n)
    mean[:] = 0.0
    for d in range(row.size):
        tot[row[d]] += w[d]
        sw2[row[d]] += w[d] * w[d]
    for d in range(row.size):
        mean[row[d]] += w[d] / tot[row[d]] * r[d]
    for d in range(row.size):
        dr = r[d] - mean[row[d]]
        var[row[d]] += w[d] / tot[row[d]] * (dr * dr)
    for i in range(n):
        if tot[i] > 0.0:
            sd[i] = math.sqrt(max(var[i], 0.0))
            ess[i] = tot[i] * tot[i] / sw2[i]
        else:
            mean[i] = sd[i] = ess[i] = np.nan


@_jit
def same_rows_kernel(ptr, ind, kp, ki, row, same):
    """limit3d_exact.same_rows: CSR row i of (ptr, ind) equals the key's row ``row[i]``
    of (kp, ki); stops at a row's first difference."""
    for i in range(row.size):
        a0, r = ptr[i], row[i]
        b0 = kp[r]
        n = ptr[i + 1] - a0
        ok = n == kp[r + 1] - b0
        j = 0
        while ok and j < n:
            ok = ind[a0 + j] == ki[b0 + j]
            j += 1
        same[i] = ok


@_jit
def compact_draws_kernel(vals, iw, lo, hi, rows):
    """limit3d_rows._compact of the draws ``vals`` (a tuple of (N, M) arrays, the weights at
    ``iw``) in the columns lo .. hi - 1, the rows not ``rows`` (N,) weighing 0: per row the
    accepted draws (weight > 0) first, in draw order, padded to the widest row's count K
    (at least 1) with 0 for the weights and, for the others, the row's largest accepted
    value (1 where there is none, or where that is not finite: numpy's maximum, NaN
    wins); returns (len(vals), N, K)."""
    w = vals[iw]
    n = w.shape[0]
    cnt = np.zeros(n, np.int64)
    k = 1
    for i in range(n):
        if rows[i]:
            c = 0
            for j in range(lo, hi):
                if w[i, j] > 0.0:
                    c += 1
            cnt[i] = c
            k = max(k, c)
    at = np.empty((n, k), np.int64)  # each row's accepted columns
    for i in range(n):
        if cnt[i]:
            c = 0
            for j in range(lo, hi):
                if w[i, j] > 0.0:
                    at[i, c] = j
                    c += 1
    out = np.empty((len(vals), n, k))
    for q in range(len(vals)):
        v = vals[q]
        for i in range(n):
            top = -np.inf
            nan = False
            for o in range(cnt[i]):
                x = v[i, at[i, o]]
                out[q, i, o] = x
                if x != x:
                    nan = True
                elif x > top:
                    top = x
            pad = 1.0
            if q == iw:
                pad = 0.0
            elif cnt[i] > 0 and not nan and math.isfinite(top):
                pad = top
            for j in range(cnt[i], k):
                out[q, i, j] = pad
    return out


def warm() -> None:
    """Compile (or load from the cache) the kernels for their one signature each."""
    a2 = np.zeros((1, 1))
    out = np.zeros((1, 1))
    c = np.ones((1, 3))
    b = np.ones((1, 1), np.bool_)
    p3 = np.ones((1, 1, 3))
    cs = (p3, p3, a2 + 0.9, a2 + 0.1, b, ~b)
    cone_bounds_kernel(*cs, p3, out, out.copy())
    direction_keep_kernel(p3, a2, b, ~b, p3, np.ones(1), np.ones(1), np.ones(1), b.copy())
    one = np.ones(1)
    dir_grid_kernel(p3, a2, b, ~b, c, c, c, one, one, -c[:, :2], c[:, :2], np.full((1, 2), 0.5),
                    1, 1, p3.copy(), b.copy(), one.copy(), b[0].copy())  # fmt: skip
    uniforms_kernel(np.ones(1, np.uint64), 1, np.zeros(1, np.int64), np.empty((1, 1, 4)))
    pts = np.ones((1, 1, 2, 3))
    prefilter_kernel(pts, b, ~b, np.zeros(1, np.int64), c, np.ones(1), 0.01, b[0].copy())
    i1 = np.zeros(2, np.int64)
    same_rows_kernel(i1, i1[:0], i1, i1[:0], i1[:1], b[0])
    compact_draws_kernel(tuple(np.ones((1, 2)) for _ in range(8)), 7, 0, 2, b[0].copy())
    one = np.ones(1)
    spread_rows_kernel(i1[:1], one, one, one.copy(), one.copy(), one.copy())
    constraining_kernel(i1, i1[:0], np.zeros((1, 1), np.int64), np.full(1, -1, np.int64),
                        i1.copy(), b[0].copy(), i1[:1].copy())  # fmt: skip
