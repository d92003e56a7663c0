"""The exact check of the spherical limit's HEALPix draws, compiled (numba): whether a
ball lights exactly a key's facets, from the lit-set kernel's rings compared with the
key's as they come (:func:`match_kernel`) or from the key's band cells alone
(:func:`edge_match_kernel`, :func:`band_bounds_kernel`); docs/kernels.md.

They call :mod:`.healpix_lit`'s and :mod:`.healpix_boundary`'s functions (``_ball``,
``_ring_at``, ``_decide_cell``, ...), so their numba cache is stamped with those modules'
source as well as their own (:func:`.healpix_boundary.stamp_with`): an edit of any of
them recompiles them, as if they were one module.
"""

from __future__ import annotations

import math

import numpy as np

from eyeviz.core.kernels import healpix_boundary, healpix_lit
from eyeviz.core.kernels.healpix_boundary import (
    _EPS,
    _cell_lons,
    _decide_fs,
    _edge_lower,
    _edge_m,
    _pix2xyf,
    _tol,
    stamp_with,
)
from eyeviz.core.kernels.healpix_lit import (
    _NO_MEMO,
    _ang2pix,
    _ball,
    _cap_steps,
    _jit,
    _ring_at,
)

# before the first kernel: its cache carries the source of the modules it calls as well
stamp_with(__file__, healpix_lit.__file__, healpix_boundary.__file__)

__all__ = [
    "match_kernel",
    "edge_match_kernel",
    "band_bounds_kernel",
    "band_order_kernel",
    "band_cells_kernel",
    "vertex_cache",
    "warm",
]


@_jit
def _angle(ch2):
    """The angle of a chord of length sqrt(ch2) on the unit sphere."""
    return 2.0 * math.asin(min(math.sqrt(max(ch2, 0.0)) * 0.5, 1.0))


@_jit
def _apart(c, u, k):
    """The angle between c and row k of u (unit vectors), from their chord."""
    dx, dy, dz = c[0] - u[k, 0], c[1] - u[k, 1], c[2] - u[k, 2]
    return _angle(dx * dx + dy * dy + dz * dz)


@_jit
def _cap(xb, yb, zb, gb, cx):
    """The steps of healpix_lit._ball that the band check reads (healpix_lit._cap_steps,
    the same bits): (kind 0 or 1 as there, the cap's centre c, alpha, pad, s2, ds2, ed, and
    the scaled centre (dx, dy, dz, d) for its pixel, :func:`_cap_pix`); not the rings'
    range, its trigonometry or the centre's pixel, which a ball decided by its band
    cells' bounds alone never needs. kind 1 also where _ball gives 3 (the ball holds the
    eye centre): the band check leaves both to the other checks."""
    kind, dx, dy, dz, d, ed, q, cosa, alpha, dcos, s2, ds2, dalpha = _cap_steps(xb, yb, zb, gb, cx)
    if kind != 0:
        return 1, (0.0, 0.0, 1.0), 0.0, 0.0, 0.0, 0.0, 0.0, dx, dy, dz, d
    pad_t = dalpha + 4 * ed + 1e-12
    c = (dx / d, dy / d, dz / d)
    return 0, c, alpha, pad_t, s2, ds2, ed, dx, dy, dz, d


@_jit
def _cap_pix(n, dx, dy, dz, d):
    """healpix_lit._ball's pixel of the cap's centre (its ``cpix``), from :func:`_cap`."""
    z_c = dz / d
    phi_c = math.atan2(dy, dx)
    return _ang2pix(n, min(max(z_c, -1.0), 1.0) if d > 0 else 1.0, phi_c)


@_jit
def band_cells_kernel(kp, ki, ip, ii, op, oi, small, pix, lit, rows):
    """limit3d_eye._Eye's band cells of each key r (CSR rows of strictly increasing
    indices: the key (kp, ki), the inner cap's lit set (ip, ii), the outer cap's (op, oi)):
    the key's cells not in the inner cap's set (all of them where ``small[r]``), lit,
    then the outer cap's cells not in the key, unlit, each in increasing order, as the
    numpy reference's set differences and stable sort by key give them; written to pix,
    lit, rows (each at least as long as ki and oi together). Returns their number."""
    m = 0
    for r in range(kp.size - 1):
        j, je = ip[r], ip[r + 1]
        for a in range(kp[r], kp[r + 1]):
            v = ki[a]
            if not small[r]:
                while j < je and ii[j] < v:
                    j += 1
                if j < je and ii[j] == v:
                    continue
            pix[m], lit[m], rows[m] = v, True, r
            m += 1
        j, je = kp[r], kp[r + 1]
        for a in range(op[r], op[r + 1]):
            v = oi[a]
            while j < je and ki[j] < v:
                j += 1
            if j < je and ki[j] == v:
                continue
            pix[m], lit[m], rows[m] = v, False, r
            m += 1
    return m


@_jit
def _cell_vertices(n, i, j, shifted, sth, zr, unit, v, k):
    """The N, W, S and E vertices of cell j of ring i into v[k] (4, 3), as
    healpix_boundary._cell_fs places them (its _vdist_at's products: the same bits)."""
    ui = unit[i]
    lw, ln, ls, un, us, pol = _cell_lons(n, i, j, shifted, ui)
    for q, r, lv, u in ((0, i - 1, ln, un), (1, i, lw, ui), (2, i + 1, ls, us), (3, i, lw + 2, ui)):
        ph = lv * u
        v[k, q, 0] = sth[r] * math.cos(ph)
        v[k, q, 1] = sth[r] * math.sin(ph)
        v[k, q, 2] = zr[r]
    return pol


@_jit
def _polar(n, i):
    """Whether ring i is polar, as healpix_boundary._cell_lons says (its ``pol``)."""
    return i <= n or i >= 3 * n


@_jit
def _chord2(v, k, q, c):
    """chord^2 from c to vertex q of row k of v (healpix_boundary._vdist's arithmetic)."""
    vx = v[k, q, 0] - c[0]
    vy = v[k, q, 1] - c[1]
    vz = v[k, q, 2] - c[2]
    return vx * vx + vy * vy + vz * vz


@_jit
def band_bounds_kernel(n, pix, ring, key, u0, sth, zr, unit, first_t, shifted_t, verts, have,
                       near, far):  # fmt: skip
    """For band cells ``pix`` (of rings ``ring``) of the keys ``key``: an upper bound
    ``near`` on the angle from the key's centre u0[key] to the cell's closure (its nearest
    vertex) and a lower bound ``far`` (the edges' lower bound of _decide_cell, less its
    rounding bounds; 0 for the cell holding u0), both widened by 1e-12 rad. (u0's pixel
    is found once for each run of cells of one key.) ``verts`` (T, 4, 3): the cells' N, W,
    S and E vertices, computed and written there unless ``have`` (then read: a second
    call on the same cells about other centres, limit3d_eye._Eye.band, skips their
    cosines and sines, two thirds of a call). A vertex is the same product of the same
    numbers either way, and its chord to the centre the same operations as
    healpix_boundary._cell_fs's, so the bounds are the same bits."""
    ed = 8 * _EPS
    last, cpix = -1, -1  # the key whose centre's pixel cpix is (cells come by key)
    for k in range(pix.shape[0]):
        i = ring[k]
        first = first_t[i]
        c = (u0[key[k], 0], u0[key[k], 1], u0[key[k], 2])
        if have:
            pol = _polar(n, i)
        else:
            pol = _cell_vertices(n, i, pix[k] - first, shifted_t[i], sth, zr, unit, verts, k)
        fN, fW = _chord2(verts, k, 0, c), _chord2(verts, k, 1, c)
        fS, fE = _chord2(verts, k, 2, c), _chord2(verts, k, 3, c)
        vmin = min(min(fN, fW), min(fS, fE))
        near[k] = _angle(vmin + _tol(vmin, 0.0, ed, 0.0)) + 1e-12
        ix, iy, face = _pix2xyf(n, pix[k], i, first)
        lo = np.inf
        for fa, fb, mf in ((fW, fN, _edge_m(n, pol, face, True, iy + 1, ix)),
                           (fS, fW, _edge_m(n, pol, face, False, ix, iy)),
                           (fS, fE, _edge_m(n, pol, face, True, iy, ix)),
                           (fE, fN, _edge_m(n, pol, face, False, ix + 1, iy))):  # fmt: skip
            low = _edge_lower(fa, fb, mf)
            low = low - _tol(max(low, 0.0), 0.0, ed, 0.0) - 8 * _EPS * (fa + fb + mf)
            lo = min(lo, low)
        if key[k] != last:
            last = key[k]
            cpix = _ang2pix(n, min(max(c[2], -1.0), 1.0), math.atan2(c[1], c[0]))
        far[k] = 0.0 if cpix == pix[k] else max(_angle(lo) - 1e-12, 0.0)


@_jit
def band_order_kernel(bp, pix, ring, lit, near, far, verts):
    """limit3d_eye._Eye.band's order of the band cells (CSR ``bp`` by key): per key its lit
    cells by ``near`` from the largest, then its unlit ones by ``far`` from the smallest,
    ties in their order (numpy's lexsort of (where(lit, -near, far), ~lit, key): stable
    sorts of -near and far, NaN last). Returns pix, ring, lit, near, far and verts in that
    order and bl (where each key's unlit cells start)."""
    nk = bp.size - 1
    order = np.empty(pix.size, np.int64)
    bl = np.empty(nk, np.int64)
    o = 0
    for i in range(nk):
        a, b = bp[i], bp[i + 1]
        idx = np.empty(b - a, np.int64)
        vals = np.empty(b - a)
        for phase in range(2):
            m = 0
            for j in range(a, b):
                if lit[j] == (phase == 0):
                    idx[m] = j
                    vals[m] = -near[j] if phase == 0 else far[j]
                    m += 1
            srt = np.argsort(vals[:m], kind="mergesort")
            for q in range(m):
                order[o] = idx[srt[q]]
                o += 1
            if phase == 0:
                bl[i] = o
    t = pix.size  # the gathers as loops (numba's fancy indexing costs twice as much)
    o_pix, o_ring, o_lit = np.empty(t, pix.dtype), np.empty(t, ring.dtype), np.empty(t, np.bool_)
    o_near, o_far, o_verts = np.empty(t), np.empty(t), np.empty((t, 4, 3))
    for k in range(t):
        j = order[k]
        o_pix[k], o_ring[k], o_lit[k] = pix[j], ring[j], lit[j]
        o_near[k], o_far[k] = near[j], far[j]
        for q in range(4):
            for c in range(3):
                o_verts[k, q, c] = verts[j, q, c]
    return o_pix, o_ring, o_lit, o_near, o_far, o_verts, bl


# long: one draw's containment test and its band cells' walk with its early exit
@_jit
def edge_match_kernel(n, x, y, z, g, cx, row, u_io, b_in, b_out, u0, bp, bl, pix, ring, lit,
                      near, far, verts, sth, zr, unit, first_t, shifted_t, out):  # fmt: skip
    """Whether ball b lights exactly key row[b]'s facets, from the key's band cells alone:
    out[b] 1 yes, 0 no, 2 not decided here (then :func:`match_kernel`).

    Per key, ``b_in`` and ``b_out`` are half-angles of an inner and an outer cap about
    u_io (I and O their lit sets), and the band cells (CSR ``bp``: ``pix``, rings, ``lit``:
    in the key K) are K - I (lit) and O - K (unlit). A ball whose cap (c, alpha) holds
    the inner cap (alpha >= b_in + |c - u_io|) and lies in the outer one (alpha + |c -
    u_io| <= b_out), each with 1e-9 rad to spare beyond the cap's error bound, lights
    every cell of I and none outside O (a cell is lit iff the cap reaches its closure:
    monotone in the cap; I lies in O), so it lights K iff each band cell is lit exactly
    when in K: K's cells in I are lit, and every other cell in K or in O is a band cell
    (a cell of I missing from K is in O - K; a cell of K outside O is in K - I and is
    then found unlit). A
    band cell is lit when even its nearest vertex from u0 (``near``) moved by |c - u0|
    lies inside the cap, unlit when the lower bound of its distance from u0 (``far``)
    less |c - u0| lies outside it; else :func:`_decide_cell` decides it (with the ball's
    own bounds, as lit_runs_kernel; its centre pixel is lit; from the cell's vertices
    ``verts`` (T, 4, 3) as band_bounds_kernel stored them, whose chords are _cell_fs's
    bit for bit: healpix_boundary._decide_fs, the same verdict), and a cell it leaves
    open leaves the ball to match_kernel. The first band cell that differs from the key rules
    the ball out.

    Each key's lit band cells come first (``bp[r]`` to ``bl[r]``), by ``near`` from the
    largest, then its unlit ones (to ``bp[r + 1]``) by ``far`` from the smallest
    (limit3d_eye._Eye.band). So the walk over the lit ones stops at the first with near +
    d0 < a_lo: every later one has a ``near`` as small, so its bound says lit too, as the
    key does; the walk over the unlit ones stops at the first with far - d0 > a_hi
    likewise (each would be found as the key has it). The cells skipped so are exactly
    those the full walk would find as the key has them from their bounds alone: the
    verdict 1 is the same; 0 and 2 may come in another order (a ball with a differing
    cell and an open one), and both are exact or left to match_kernel."""
    for b in range(x.shape[0]):
        r = row[b]
        kind, c, alpha, pad, s2, ds2, ed, dx, dy, dz, dd = _cap(x[b], y[b], z[b], g[b], cx)
        if kind != 0:
            out[b] = 2
            continue
        cpix = -1  # the centre's pixel, computed when first needed
        d_io = _apart(c, u_io, r) + 1e-12
        a_lo = alpha - pad - 1e-9
        a_hi = alpha + pad + 1e-9
        if not (a_lo - d_io >= b_in[r] and a_hi + d_io <= b_out[r]):
            out[b] = 2
            continue
        d0 = _apart(c, u0, r) + 1e-12
        res = 1
        k, lit_end, end = bp[r], bl[r], bp[r + 1]
        while k < end:
            if near[k] + d0 < a_lo:
                if k < lit_end:  # this and every later lit cell are lit
                    k = lit_end
                    continue
                on = 1
            elif far[k] - d0 > a_hi:
                if k >= lit_end:  # this and every later unlit cell are unlit
                    break
                on = 0
            else:
                if cpix < 0:
                    cpix = _cap_pix(n, dx, dy, dz, dd)
                if pix[k] == cpix:
                    on = 1
                else:
                    i = ring[k]
                    on = _decide_fs(n, i, pix[k], first_t[i], c, s2, ds2, ed,
                                    _chord2(verts, k, 0, c), _chord2(verts, k, 1, c),
                                    _chord2(verts, k, 2, c), _chord2(verts, k, 3, c),
                                    _polar(n, i))  # fmt: skip
                    if on == 2:
                        res = 2
                        break
            if on != lit[k]:
                res = 0
                break
            k += 1
        out[b] = res


def vertex_cache(size: int = 1 << 14) -> tuple[np.ndarray, np.ndarray]:
    """An empty vertex cache of ``size`` (a power of 2; 0: none) for :func:`match_kernel`:
    (tags, xyz), tags -1 where empty."""
    return np.full(size, -1, np.int64), np.empty((size, 3))


@_jit
def _piece(ki, k, end, s, length):
    """Whether the key's indices ki[k:end] begin with s, s + 1, ..., s + length - 1."""
    if k + length > end:
        return False
    for j in range(length):
        if ki[k + j] != s + j:
            return False
    return True


# long: lit_runs_kernel's ring loop, its runs compared with the key's as they come
@_jit
def match_kernel(n, x, y, z, g, cx, row, kp, ki, sth, zr, unit, first_t, nr_t, shifted_t,
                 delta_t, o_t, vc, out):  # fmt: skip
    """Whether each ball b lights exactly the facets of row ``row[b]`` of the CSR (kp, ki)
    (sorted indices) in this eye: out[b] 1 yes, 0 no, 2 the kernel cannot tell (a ball
    lit_runs_kernel hands to the reference, met before a mismatch). The same rings and
    decisions as :func:`lit_runs_kernel`, its runs compared with the key's as they come
    (no indices written) and a ball given up at its first ring that differs: a decided
    ring is the reference's, so a difference there is one of the exact lit sets. ``vc``:
    a vertex cache (:func:`vertex_cache`; the balls of a call lie near a few keys' balls,
    so their undecided cells share vertices)."""
    npix = 12 * n * n
    for b in range(x.shape[0]):
        k, end = kp[row[b]], kp[row[b] + 1]
        kind, par, i_min, i_max, _, _ = _ball(n, x[b], y[b], z[b], g[b], cx)
        if kind == 1:
            out[b] = 2
            continue
        if kind == 3:  # s an int64 as at the other call sites (a literal 0: a second compile)
            out[b] = 1 if _piece(ki, k, end, np.int64(0), npix) and end - k == npix else 0
            continue
        res = 1
        memo = _NO_MEMO
        for i in range(i_min, i_max + 1):
            kind, lo, hi, memo = _ring_at(n, i, par, sth, zr, unit, first_t, nr_t, shifted_t,
                                          delta_t, o_t, vc, memo)  # fmt: skip
            if kind == 2:
                res = 2
                break
            if kind == 0:
                continue
            f = first_t[i]
            nr = nr_t[i]
            lo_w = lo % nr
            length = hi - lo + 1
            e = lo_w + length
            if e > nr:  # the piece at the ring's start first
                ok = _piece(ki, k, end, f, e - nr) and _piece(ki, k + e - nr, end, f + lo_w,
                                                               nr - lo_w)  # fmt: skip
            else:
                ok = _piece(ki, k, end, f + lo_w, length)
            if not ok:
                res = 0
                break
            k += length
        if res == 1 and k != end:
            res = 0  # the key lights more
        out[b] = res


def warm() -> None:
    """Compile (or load from the cache) the kernels for their one signature each, on the
    ring tables of nside 4 (:func:`healpix_lit.warm_inputs`)."""
    n, tabs, (x, y, z, g) = healpix_lit.warm_inputs()
    sth, zr, unit, first, nr, shifted, delta, o = tabs
    i1 = np.zeros(1, np.int64)
    match_kernel(n, x, y, z, g, 40.0, i1, np.array([0, 1]), i1, sth, zr, unit, first, nr,
                 shifted, delta, o, vertex_cache(16), i1.copy())  # fmt: skip
    u = np.array([[0.0, 1.0, 0.0]])
    near, far = np.zeros(1), np.zeros(1)
    pix, ring = np.array([10]), np.array([2])
    band_bounds_kernel(n, pix, ring, i1, u, sth, zr, unit, first, shifted, np.empty((1, 4, 3)),
                       False, near, far)  # fmt: skip
    p2 = np.array([0, 1])
    band_order_kernel(p2, pix, ring, np.ones(1, np.bool_), near, far, np.zeros((1, 4, 3)))
    band_cells_kernel(p2, i1, p2, i1, p2, i1, np.zeros(1, np.bool_), i1.copy(),
                      np.zeros(1, np.bool_), i1.copy())  # fmt: skip
    edge_match_kernel(n, x, y, z, g, 40.0, i1, u, np.zeros(1), np.ones(1), u, np.array([0, 1]),
                      np.ones(1, np.int64), pix, ring, np.ones(1, np.bool_), near, far,
                      np.zeros((1, 4, 3)), sth, zr, unit, first, shifted, i1.copy())  # fmt: skip
