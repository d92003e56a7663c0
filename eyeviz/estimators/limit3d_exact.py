"""The two exact parts of the spherical limit (:mod:`eyeviz.estimators.limit3d`) that
every eye model's proposal shares: the prior density of Algorithm 1 in 3D
(:mod:`eyeviz.dataset.algorithm1_3d`) and the 0/1 likelihood, a draw being kept only when
the pair's own exact ``lit_csr`` gives both of the key's lit sets and ``in_bfv`` holds."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from eyeviz.core import kernels
from eyeviz.core.domain import Domain3D
from eyeviz.estimators.base import LitCSR
from eyeviz.estimators.lit_csr import take_rows

__all__ = ["band_pass", "exact_hits", "prior_density", "same_rows"]


def prior_density(domain: Domain3D, prior: str, r, g, el, az) -> np.ndarray:
    """The prior density of Algorithm 1 in 3D in (x, y, z, g), up to a constant, at balls
    of centre (r, az, el) (about :attr:`Domain3D.origin`) and radius g (0 outside its
    support; the field test and Definition 1 are not applied here).

    HEALPix eyes: in (r, g, el, az) the single-pass density is 1 / (g_max - r sin(gamma /
    2)) / (pi - 2 az0(r, g, el)) with cos(az0) = cos(psi + asin(g / r)) / cos(el); the
    multi-pass one r^2 cos(el) / (g_max - r sin(gamma / 2)) / (pi - 2 az0(r, g, el_max)).
    Measured eyes have no cones (az0 = 0, the azimuth uniform on [0, pi]). Both gain the
    Jacobian 1 / (r^2 cos el) in (x, y, z, g)."""
    d = domain
    s = math.sin(d.gamma / 2)
    measured = d.kind == "measured"
    with np.errstate(invalid="ignore", divide="ignore"):
        ok = (r >= d.r_min) & (r <= d.r_max) & (g >= r * s) & (g <= d.g_max) & (g <= r)
        ok &= np.abs(el) <= d.el_max
        cel = np.cos(el)
        if measured:
            cone = np.zeros_like(r)
        else:
            cone = d.psi + np.arcsin(np.minimum(g / r, 1.0))
            ok &= cone < math.pi / 2
        if prior == "multi":
            az0 = np.arccos(np.minimum(np.cos(cone) / math.cos(d.el_max), 1.0))
            dens = r * r * cel
        else:
            az0 = np.arccos(np.minimum(np.cos(cone) / cel, 1.0))
            dens = np.ones_like(r)
        if measured:
            az0 = np.zeros_like(r)
        ok &= (az >= az0) & (az <= math.pi - az0)
        dens = dens / ((d.g_max - r * s) * (math.pi - 2 * az0) * r * r * cel)
    return np.where(ok & np.isfinite(dens), dens, 0.0)


def same_rows(ptr: np.ndarray, ind: np.ndarray, key: LitCSR, row: np.ndarray) -> np.ndarray:
    """Whether each CSR row i of (ptr, ind) equals the key's row ``row[i]`` (compiled
    unless ``EYEVIZ_JIT=0``)."""
    kp, ki = key
    if kernels.use(row.size):
        from eyeviz.core.kernels.limit3d_region import same_rows_kernel

        out = np.empty(row.size, np.bool_)
        p_, i_, kp_, ki_, r_ = (kernels.arg(a, np.int64) for a in (ptr, ind, kp, ki, row))
        same_rows_kernel(p_, i_, kp_, ki_, r_, out)
        return out
    cnt = np.diff(ptr)
    kc = np.diff(kp)[row]
    same = cnt == kc
    sel = np.flatnonzero(same & (cnt > 0))
    if sel.size:
        lens = cnt[sel]
        starts = ptr[sel]
        kstarts = kp[row[sel]]
        off = np.arange(int(lens.sum())) - np.repeat(np.cumsum(lens) - lens, lens)
        a = ind[np.repeat(starts, lens) + off]
        b = ki[np.repeat(kstarts, lens) + off]
        bad = np.add.reduceat((a != b).astype(np.int64), np.cumsum(lens) - lens)
        same[sel] = bad == 0
    return same


def exact_hits(
    domain: Domain3D,
    p: np.ndarray,
    g: np.ndarray,
    row: np.ndarray,
    lit_a: LitCSR,
    lit_b: LitCSR,
    bands: tuple | None = None,
    matched: np.ndarray | None = None,
) -> np.ndarray:
    """The 0/1 likelihood of draws (centres p (D, 3), radii g (D,)) of the keys ``row``
    (D,): the pair's exact ``lit_csr`` gives both of the key's lit sets and the ball is in
    the binocular field (``in_bfv``, decided only on the draws that match). HEALPix
    ``bands``: per eye, the keys' band cells (limit3d_eye._Eye.band), which decide
    most draws first (:func:`_match_healpix`). ``matched`` (D,): whether each draw lights
    both lit sets, when the caller knows it already (only ``in_bfv`` is left)."""
    hit = np.zeros(row.size, bool)
    if not row.size:
        return hit
    x, y, z = p[:, 0], p[:, 1], p[:, 2]
    if matched is not None:
        match = matched
    elif domain.kind != "measured" and kernels.use(row.size):
        match = _match_healpix(domain.eyes, x, y, z, g, row, lit_a, lit_b, bands)
    else:
        (pa, ia), (pb, ib) = domain.eyes.lit_csr(x, y, z, g)
        match = same_rows(pa, ia, lit_a, row) & same_rows(pb, ib, lit_b, row)
    at = np.flatnonzero(match)
    if not at.size:
        return hit
    if domain.kind == "measured":
        # a measured pair's field (MeasuredEyePair.in_bfv): each eye lights two facets or
        # more, read here from the key (the ball's lit sets are the key's), and the ball
        # holds no lens
        ka, kb = (np.diff(k[0])[row[at]] >= 2 for k in (lit_a, lit_b))
        oa, ob = domain.eyes.overlaps_eye(x[at], y[at], z[at], g[at])
        hit[at] = ka & kb & ~oa & ~ob
    else:
        hit[at] = domain.eyes.in_bfv(x[at], y[at], z[at], g[at])
    return hit


def band_pass(eyes, p: np.ndarray, g: np.ndarray, row: np.ndarray, bands: tuple) -> np.ndarray:
    """The band check alone (kernels.healpix_match.edge_match_kernel, eye B only where A did
    not rule the ball out): per ball 1 both eyes light the key's sets, 0 one does not, 2
    not decided here."""
    from eyeviz.core.healpix_fast import _ring_info_tables, _ring_tables
    from eyeviz.core.kernels import healpix_match

    edge_kernel: Any = healpix_match.edge_match_kernel  # 25 arguments: the stub types fewer
    n = eyes.nside
    sth, zr, unit = _ring_tables(n)
    first, _, shifted = _ring_info_tables(n)[:3]
    xs, ys, zs = (kernels.arg(p[:, j], np.float64) for j in range(3))
    gs, rows = kernels.arg(g, np.float64), kernels.arg(row, np.int64)
    res = np.full(row.size, 2, np.int64)
    edge_kernel(n, xs, ys, zs, gs, -eyes.h, rows, *bands[0], sth, zr, unit, first, shifted, res)
    on = np.flatnonzero(res != 0)
    out = np.full(on.size, 2, np.int64)
    edge_kernel(n, xs[on], ys[on], zs[on], gs[on], eyes.h, rows[on], *bands[1], sth, zr, unit,
                first, shifted, out)  # fmt: skip
    res[on] = np.where(out == 0, 0, np.maximum(res[on], out))
    return res


def _match_healpix(
    eyes, x, y, z, g, row, lit_a: LitCSR, lit_b: LitCSR, bands: tuple | None = None
) -> np.ndarray:
    """``same_rows`` of the pair's ``lit_csr`` of the balls against the key's rows ``row``
    for both eyes, without the lit sets (eye B only for the balls eye A did not rule
    out): with ``bands``, from the key's band cells alone where the ball's cap lies
    between the key's inner and outer caps (kernels.healpix_match.edge_match_kernel);
    the other balls by the lit-set kernel's rings compared with the key's as they come,
    each ball given up at its first ring that differs (match_kernel); the balls that
    kernel hands to the reference (2) get ``lit_csr`` and ``same_rows``. The same answer
    for every ball (tests/estimators/test_limit3d_match.py)."""
    from eyeviz.core.healpix_fast import _ring_info_tables, _ring_tables
    from eyeviz.core.kernels import healpix_match

    # Any: the kernels take 19-24 arrays and numbers (numba's Dispatcher stub types fewer)
    match_kernel: Any = healpix_match.match_kernel
    edge_kernel: Any = healpix_match.edge_match_kernel

    xs, ys, zs, gs = (kernels.arg(v, np.float64) for v in (x, y, z, g))
    if not (np.isfinite(xs).all() and np.isfinite(ys).all() and np.isfinite(zs).all()
            and np.isfinite(gs).all() and (gs > 0).all()):  # fmt: skip
        (pa, ia), (pb, ib) = eyes.lit_csr(x, y, z, g)  # lit_csr's refusal, as before
        return same_rows(pa, ia, lit_a, row) & same_rows(pb, ib, lit_b, row)
    n = eyes.nside
    tabs = (*_ring_tables(n), *_ring_info_tables(n))
    rows = kernels.arg(row, np.int64)
    res = np.zeros(row.size, np.int64)
    todo = np.arange(row.size)
    vc = healpix_match.vertex_cache()
    for e, (cx, (kp, ki)) in enumerate(((-eyes.h, lit_a), (eyes.h, lit_b))):
        out = np.full(todo.size, 2, np.int64)
        xe, ye, ze, ge, re = xs[todo], ys[todo], zs[todo], gs[todo], rows[todo]
        if bands is not None:
            edge_kernel(n, xe, ye, ze, ge, float(cx), re, *bands[e], tabs[0], tabs[1],
                        tabs[2], tabs[3], tabs[5], out)  # fmt: skip
        left = np.flatnonzero(out == 2)
        if left.size:
            o2 = np.empty(left.size, np.int64)
            match_kernel(n, xe[left], ye[left], ze[left], ge[left], float(cx), re[left],
                         kernels.arg(kp, np.int64), kernels.arg(ki, np.int64), *tabs, vc,
                         o2)  # fmt: skip
            out[left] = o2
        # 0: this eye rules the ball out; 2 in either eye: the reference decides
        res[todo] = np.maximum(res[todo], out) if cx > 0 else out
        res[todo[out == 0]] = 0
        todo = todo[out != 0]
    match = res == 1
    ref = np.flatnonzero(res == 2)
    if ref.size:
        # the reference's exact path is slow (mpmath at ties): a ball in many rows once
        balls = np.stack((xs[ref], ys[ref], zs[ref], gs[ref]), axis=1)
        uniq, inv = np.unique(balls, axis=0, return_inverse=True)
        (pa, ia), (pb, ib) = eyes.lit_csr(*uniq.T)
        inv = inv.reshape(-1)
        pa, ia = take_rows(pa, ia, inv)
        pb, ib = take_rows(pb, ib, inv)
        match[ref] = same_rows(pa, ia, lit_a, row[ref]) & same_rows(pb, ib, lit_b, row[ref])
    return match
