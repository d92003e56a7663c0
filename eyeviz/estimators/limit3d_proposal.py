"""The proposal of the spherical limit (:mod:`eyeviz.estimators.limit3d`), HEALPix only:
per key, each eye's feasible region of ball centres (the lit set's edge cells, the centre
search, the affine bounds and the box of centres), B's region along A's rays, the
necessary-condition prefilter before the exact check, and the key-hashed uniforms that
make a key's draws the same alone and in any batch. Module docstring of limit3d, steps
1-4, describes the construction."""

from __future__ import annotations

import math

import numpy as np

from eyeviz.core import kernels
from eyeviz.estimators.base import LitCSR

# _frame: also read from here by the measured model (limit3d_measured, _cones, _provable)
from eyeviz.estimators.limit3d_eye import _Eye, _frame, _sample_gap  # noqa: F401

#: directions of the bisection for the box of centres
NDIR = 8


_M1 = np.uint64(0xBF58476D1CE4E5B9)


_M2 = np.uint64(0x94D049BB133111EB)


_GOLD = np.uint64(0x9E3779B97F4A7C15)


def _mix(z: np.ndarray) -> np.ndarray:
    with np.errstate(over="ignore"):
        z = z + _GOLD
        z = (z ^ (z >> np.uint64(30))) * _M1
        z = (z ^ (z >> np.uint64(27))) * _M2
    return z ^ (z >> np.uint64(31))


def _key_hash(lit_a: LitCSR, lit_b: LitCSR) -> np.ndarray:
    out = np.zeros(lit_a[0].size - 1, np.uint64)
    for salt, (ptr, ind) in enumerate((lit_a, lit_b)):
        hv = _mix(ind.astype(np.uint64) + np.uint64(salt << 40))
        cnt = np.diff(ptr)
        sums = np.zeros(cnt.size, np.uint64)
        nz = cnt > 0
        with np.errstate(over="ignore"):
            sums[nz] = np.add.reduceat(hv, ptr[:-1][nz])
            out = _mix(out ^ sums ^ (cnt.astype(np.uint64) << np.uint64(48)))
    return out


def _uniforms(keys: np.ndarray, m: int, k: int, stream: int) -> np.ndarray:
    """(N, m, k) uniforms in (0, 1) from the key hashes."""
    j = np.arange(m * k, dtype=np.uint64) + np.uint64(stream << 32)
    with np.errstate(over="ignore"):
        z = _mix(keys[:, None] * _M1 + j[None, :])
    u = ((z >> np.uint64(11)).astype(np.float64) + 0.5) * 2.0**-53
    return u.reshape(keys.size, m, k)


def _batch_uniforms(keys: np.ndarray, m: int, k: int, streams) -> np.ndarray:
    """(N, m * len(streams), k) uniforms: :func:`_uniforms` of each stream (an int or a
    sequence of them), side by side: one call draws several batches, each the same as if
    drawn alone."""
    if isinstance(streams, int | np.integer):
        return _uniforms(keys, m, k, int(streams))
    return np.concatenate([_uniforms(keys, m, k, int(s)) for s in streams], axis=1)


def _prefilter(eye: _Eye, row: np.ndarray, c: np.ndarray, alpha: np.ndarray) -> np.ndarray:
    """A necessary condition for caps (c (D, 3) unit, alpha (D,)) of the keys ``row`` (D,)
    to light exactly the key's cells, on the eye's (pruned) edge cells, from their
    boundary samples' true distances: a lit cell needs alpha > dist(c, cell) >= d_s -
    gap (d_s: the nearest sample's distance, gap: :func:`_sample_gap`), an unlit one
    alpha <= dist(c, closure) <= d_s. Both with a 1e-9 rad margin for rounding. Draws
    failing it would fail the exact check; the survivors get that check. Compiled with
    an early exit unless ``EYEVIZ_JIT=0`` (the same survivors among the draws the exact
    check accepts: kernels.limit3d_region.prefilter_kernel)."""
    if kernels.use(row.size):
        from eyeviz.core.kernels.limit3d_region import prefilter_kernel

        ok = np.empty(row.size, np.bool_)
        prefilter_kernel(kernels.arg(eye.pts), kernels.arg(eye.lit),
                         kernels.arg(eye.pad), kernels.arg(row, np.int64),
                         kernels.arg(c, np.float64),
                         kernels.arg(alpha, np.float64), eye.step, ok)  # fmt: skip
        return ok
    return _prefilter_ref(eye, row, c, alpha)


def _prefilter_ref(eye: _Eye, row: np.ndarray, c: np.ndarray, alpha: np.ndarray) -> np.ndarray:
    """:func:`_prefilter` in numpy (the reference)."""
    ok = np.ones(row.size, bool)
    pp = eye.pts.shape[2]
    bounds = np.flatnonzero(np.diff(row)) + 1  # row is sorted: one product per key
    for idx in np.split(np.arange(row.size), bounds):
        if not idx.size:
            continue
        r = row[idx[0]]
        live = ~eye.pad[r]
        k = int(live.sum())
        pts = eye.pts[r][live].reshape(k * pp, 3)
        dots = (pts @ c[idx].T).reshape(k, pp, idx.size).max(axis=1)
        ds = np.arccos(np.clip(dots, -1.0, 1.0))  # (K, Dk)
        a = alpha[idx][None, :]
        lit = eye.lit[r][live][:, None]
        bad = np.where(lit, a + _sample_gap(eye.step, ds) + 1e-9 <= ds, a > ds + 1e-9)
        ok[idx] = ~bad.any(axis=0)
    return ok


def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


_GRIDS: dict[int, np.ndarray] = {}  # _grid's arrays, made once per n (read only by callers)


def _grid(n: int) -> np.ndarray:
    g = _GRIDS.get(n)
    if g is None:
        t = (np.arange(n) + 0.5) / n * 2 - 1
        a, b = np.meshgrid(t, t, indexing="ij")
        g = _GRIDS[n] = np.stack([a.ravel(), b.ravel()], axis=1)  # (n*n, 2) in (-1, 1)
    return g


_DIRS = np.stack([np.cos(np.arange(8) * math.pi / 4), np.sin(np.arange(8) * math.pi / 4)], axis=1)


def _locate(eye: _Eye, half: float, n: int, levels: int) -> None:
    """Move the eye's centre to the maximum of G (zooming grids of n x n about the best
    point, each a third as wide) and linearise there. Compiled unless ``EYEVIZ_JIT=0``
    (kernels.limit3d_locate.locate_kernel: the same formulas, in place)."""
    g0 = _grid(n)
    if kernels.use(eye.pts.shape[0] * eye.pts.shape[1]):
        from eyeviz.core.kernels.limit3d_locate import locate_kernel

        locate_kernel(eye.pts, eye.lit, eye.pad, eye.step, g0, half, levels, eye.c, eye.e1, eye.e2,
                      eye.d, eye.t, eye.a_lit, eye.t_lit, eye.a_unl, eye.t_unl, eye.lists,
                      np.empty(g0.shape[0]))  # fmt: skip
        return
    rows = np.arange(eye.c.shape[0])
    for _ in range(levels):
        g = g0[None] * half
        lo, hi = eye.bounds(np.broadcast_to(g, (rows.size, *g0.shape)))
        best = np.argmax(hi - lo, axis=1)
        eye.linearise(eye.direction(g[0][best][:, None, :])[:, 0])
        half = half / 3.0


def _extent(eye: _Eye, reach: float, slack, iters: int = 12, known=None) -> np.ndarray:
    """Half-widths (N, 2) of a box about the centre holding every delta with
    G(delta) >= -slack (bisection along NDIR directions: G is concave). The bisection is
    compiled unless ``EYEVIZ_JIT=0`` (kernels.limit3d_affine.extent_kernel, the same bits).
    ``known`` (same (N,), prev (N, 2)): the keys ``same`` take their rows of ``prev``, an
    earlier call's answer on the same model, reach and slack (the same bits: compiled,
    their bisection is skipped)."""
    n = eye.c.shape[0]
    dirs = _DIRS_NDIR
    lo = np.zeros((n, NDIR))
    hi = np.full((n, NDIR), reach)
    if kernels.use(n * NDIR * iters):
        from eyeviz.core.kernels.limit3d_affine import extent_kernel

        sl = kernels.arg(np.broadcast_to(slack, (n, 1))[:, 0], np.float64)
        todo = np.ones(n, np.bool_) if known is None else ~known[0]
        if not todo.any():
            return known[1].copy()
        extent_kernel(eye.a_lit, eye.t_lit, eye.a_unl, eye.t_unl, eye.lists, dirs,
                      float(reach), sl, iters, todo, hi)  # fmt: skip
        iters = 0
    for _ in range(iters):
        mid = 0.5 * (lo + hi)
        a, b = eye.bounds(mid[..., None] * dirs[None])
        inside = (b - a) >= -slack
        lo = np.where(inside, mid, lo)
        hi = np.where(inside, hi, mid)
    pts = hi[..., None] * dirs[None]  # (N, NDIR, 2): outside the region by < one step
    # the box of the boundary points, widened: a convex polygon between two of them
    # bulges out by at most tan(pi / NDIR) times their distance
    ext = np.abs(pts).max(axis=1) * (1.0 + math.tan(math.pi / NDIR))
    ext = np.maximum(ext, 1e-12)
    return ext if known is None else np.where(known[0][:, None], known[1], ext)


def _dirs(k: int) -> np.ndarray:
    t = np.arange(k) * 2 * math.pi / k
    return np.stack([np.cos(t), np.sin(t)], axis=1)


_DIRS_NDIR = _dirs(NDIR)  # the bisection's directions, made once

_BOX = np.array(
    [(x, y) for x in (-1.0, -0.5, 0.0, 0.5, 1.0) for y in (-1.0, 1.0)]
    + [(x, y) for x in (-1.0, 1.0) for y in (-0.5, 0.0, 0.5)]
)  # 16 points on the boundary of [-1, 1]^2, at most 1/2 apart along each edge


def _epipolar(v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(theta, phi) of unit vectors v (..., 3): theta = atan2(v_z, v_y), the angle of the
    plane through the baseline (the x-axis) and v, and phi the angle of v from +x. A ball's
    centre and both eyes' cap centres share one theta (the eyes lie on the x-axis)."""
    return np.arctan2(v[..., 2], v[..., 1]), np.arctan2(np.hypot(v[..., 1], v[..., 2]), v[..., 0])


def _angle_box(eye: _Eye, ext: np.ndarray) -> np.ndarray:
    """Bounds (N, 4) = (theta_lo, theta_hi, phi_lo, phi_hi) over the eye's box of centres
    (half-widths ``ext`` (N, 2) about its centre, gnomonic). theta and phi have no
    critical point off the x-axis, so their extremes lie on the box's boundary, whose
    edges are great-circle arcs: sampled at most s = ext / 2 apart, each is off by at
    most M s^2 / 8 with |theta''|, |phi''| <= M = 2 / sin(phi)^2 along a unit-speed arc;
    the pad is four times that. NaN where the box reaches y <= 0 or the x-axis."""
    pts = eye.direction(_BOX[None] * ext[:, None, :])  # (N, 16, 3)
    th, ph = _epipolar(pts)
    s = 0.5 * np.hypot(ext[:, 0], ext[:, 1])
    sin_min = np.sin(ph).min(axis=1) - 2.0 * s
    ok = (pts[..., 1].min(axis=1) > 0) & (sin_min > 1e-3)
    pad = s * s / np.where(ok, sin_min, 1.0) ** 2 + 1e-12
    out = np.stack(
        [th.min(axis=1) - pad, th.max(axis=1) + pad, ph.min(axis=1) - pad, ph.max(axis=1) + pad],
        axis=1,
    )
    return np.where(ok[:, None], out, np.nan)


def _ray_in_box(eye_b: _Eye, ca: np.ndarray, ext: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The interval (lo, hi) (N, M) of u = 1 / rho where the direction from B to
    A + c_A / u, proportional to v(u) = c_A + u (A - B), has gnomonic coordinates about
    B's centre inside the box |delta_i| <= ext_i (N, 2): with v . c_B > 0 each side is
    |v . e_i| <= ext_i v . c_B, two inequalities linear in u (ca: (N, M, 3))."""
    a = eye_b.a
    shape = ca.shape[:2]
    c = eye_b.c[:, None, :]
    cc = (ca * c).sum(-1)
    rows = [(-cc, np.broadcast_to(-(eye_b.c @ a)[:, None], shape))]  # v . c_B >= 0
    for e, x in ((eye_b.e1, ext[:, 0]), (eye_b.e2, ext[:, 1])):
        ce = (ca * e[:, None, :]).sum(-1)
        for sgn in (1.0, -1.0):  # sgn v . e - ext v . c_B <= 0
            k1 = sgn * (e @ a) - x * (eye_b.c @ a)
            rows.append((sgn * ce - x[:, None] * cc, np.broadcast_to(k1[:, None], shape)))
    lo = np.zeros(shape)
    hi = np.full(shape, np.inf)
    for k0, k1 in rows:  # k0 + u k1 <= 0
        with np.errstate(divide="ignore", invalid="ignore"):
            root = -k0 / k1
        hi = np.where(k1 > 0, np.minimum(hi, root), hi)
        lo = np.where(k1 < 0, np.maximum(lo, root), lo)
        lo = np.where((k1 == 0) & (k0 > 0), np.inf, lo)
    return lo, hi


def _ray_in_region(eye_b: _Eye, ca, lo, hi, slack, grid: int = 12, rounds: int = 2, aim=None):
    """Shrink each draw's u-interval [lo, hi] (N, M) to one holding every u whose view
    from B lies in B's modelled region G = min_unlit - max_lit >= -slack. G is concave
    and the view moves monotonically along a great circle, so those u form an interval:
    G on ``grid`` points, the interval from the grid point before the first inside to the
    one after the last (or the two neighbours of the best point when none is inside);
    ``rounds`` times. Returns (lo, hi). (No draw uses this search now: numpy only.) With
    ``aim`` = (A's sin(lo_A - s), sin(hi_A + s)) (N, M) each: the g test's gap instead,
    inside where above 0, and the inside run the draws' kernel's search finds
    (:func:`_ray_bracket`), not every inside point: the numpy reference of
    :func:`eyeviz.core.kernels.limit3d_draws.ray_region_kernel` (``_gap_g`` there)."""
    n, m = lo.shape
    t = np.linspace(0.0, 1.0, grid)
    for _ in range(rounds):
        uu = lo[..., None] + (hi - lo)[..., None] * t  # (N, M, grid)
        v = ca[:, :, None, :] + uu[..., None] * eye_b.a
        nrm = np.linalg.norm(v, axis=-1, keepdims=True)
        v = v / nrm
        with np.errstate(invalid="ignore", divide="ignore"):
            dl = eye_b.gnomonic(v.reshape(n, m * grid, 3))
            blo, bhi = eye_b.bounds(np.nan_to_num(dl, nan=1e3, posinf=1e3, neginf=-1e3))
        if aim is None:
            g = (bhi - blo).reshape(n, m, grid)
            inside = g >= -slack[..., None]
        else:
            k = nrm[..., 0]
            s3 = slack[..., None]
            with np.errstate(invalid="ignore"):
                sb_lo = np.sin(np.clip(blo.reshape(n, m, grid) - s3, 0.0, math.pi / 2))
                sb_hi = np.sin(np.clip(bhi.reshape(n, m, grid) + s3, 0.0, math.pi / 2))
                g = np.minimum(sb_hi, aim[1][..., None] / k)
                g = g - np.maximum(sb_lo, aim[0][..., None] / k)
            inside = g > 0.0
        if aim is None:
            anyin = inside.any(axis=2)
            first = np.where(anyin, inside.argmax(axis=2), g.argmax(axis=2))
            last = np.where(anyin, grid - 1 - inside[..., ::-1].argmax(axis=2), first)
        else:
            first, last = (x.reshape(n, m) for x in _ray_bracket(g.reshape(n * m, grid)))
        i0 = np.maximum(first - 1, 0)
        i1 = np.minimum(last + 1, grid - 1)
        lo, hi = (
            np.take_along_axis(uu, i0[..., None], 2)[..., 0],
            np.take_along_axis(uu, i1[..., None], 2)[..., 0],
        )
    return lo, hi


def _ray_bracket(g: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The inside run (first, last) (R,) that the draws' kernel's search along the ray
    finds (kernels.limit3d_draws._aim_next) on gap values g (R, grid), grid >= 2, all
    evaluated here: the middle pair, a binary search on the slope of pairs stopped at
    the first point inside (g > 0), the first maximum of the window it leaves where none
    is, then the run of inside points about the hit (without a hit: the maximum)."""
    r, grid = g.shape
    rows = np.arange(r)
    ins = g > 0.0
    m0 = (grid - 2) // 2
    hit = np.where(ins[:, m0], m0, np.where(ins[:, m0 + 1], m0 + 1, -1))
    up = g[:, m0] < g[:, m0 + 1]
    lo, hi = np.where(up, m0 + 1, 0), np.where(up, grid - 1, m0)
    while True:
        act = (hit < 0) & (hi - lo > 1)
        if not act.any():
            break
        mid = (lo + hi) // 2
        g0, g1 = g[rows, mid], g[rows, np.minimum(mid + 1, grid - 1)]
        hit = np.where(act & (g0 > 0.0), mid, np.where(act & (g1 > 0.0), mid + 1, hit))
        act &= hit < 0
        lo = np.where(act & (g0 < g1), mid + 1, lo)
        hi = np.where(act & ~(g0 < g1), mid, hi)
    best, scan = lo.copy(), hit < 0
    for j in range(grid):  # the window's points in turn: the first inside, else the maximum
        on = scan & (j >= lo) & (j <= hi)
        hit = np.where(on & ins[:, j], j, hit)
        best = np.where(on & ~ins[:, j] & (g[:, j] > g[rows, best]), j, best)
        scan &= ~(on & ins[:, j])
    first, last = hit.copy(), hit.copy()
    for _ in range(grid):
        first -= (first > 0) & ins[rows, np.maximum(first - 1, 0)]
        last += (last >= 0) & (last < grid - 1) & ins[rows, np.minimum(last + 1, grid - 1)]
    return np.where(hit >= 0, first, best), np.where(hit >= 0, last, best)
