"""Per-eye summaries of HEALPix lit sets, from CSR rows: the analytic, limit and learned
estimators of the spherical eyes all read them (:mod:`eyeviz.estimators.triangulation`
turns them into rays; :mod:`eyeviz.estimators.learned3d_features` into the network's input).

A ball lights a spherical cap of HEALPix facets per eye (docs/spherical.md); a few
thousand RING indices per eye at nside 180. Reading every index per row through a
table of facet centres costs about 10^4 rows/s; this module reads each index once in a
single vectorised pass that finds the runs of consecutive indices (a cap meets each ring
in one run of cells, so a row holds one run per ring it crosses), and then works per run
(about 50 per eye and row):

- the sum of the facet centres of a run in closed form: on ring k the centres lie at
  z_k and longitudes phi0 + j * 2 pi / n_k, so the x and y sums are geometric sums,
  sin(n d / 2) / sin(d / 2) * (cos, sin)(phi0 + (a + b) d / 2); a run that crosses ring
  boundaries (only where a cap covers longitude 0 or a pole) is split into the tail of
  its first ring, whole rings (x and y sum to zero) and the head of its last ring;
- the longitudes of the run's outer cell edges (the widest run gives the cap's west and
  east extent, the 3D form of the planar lit interval's ends, Prop. 2, Eq. 11).

Per eye and row (:func:`eye_summaries`): the facet count, the sum of centres (its
direction is the solid-angle-weighted mean direction of the lit facets; every HEALPix
facet has the same solid angle 4 pi / (12 nside^2)), the smallest west and largest east
edge longitude, the z of the first and last ring, and bounds on the cap centre's
longitude from the runs' ends (:func:`_bounds`: each ring's two crossings with the cap's
boundary lie within a cell of the run's ends, so every ring bounds the centre; the
tightest bounds over many rings locate it several times more precisely than the mean
direction, as the set of caps consistent with the lit set does).

Speed (issue 23: the learned estimator's target is 10^5 rows/s at nside 180): the one
pass over the indices also reads each run's first and last index while its block is in
cache, and with a ``name`` it is the indices' only check (:func:`_check_runs`: range and
order from the runs' ends, as :func:`eyeviz.estimators.base.as_csr` would refuse them);
per run, the ring, the edge longitudes and the sums' sines and cosines are gathered from
per-pixel tables built once per nside (:class:`_PixelTables`, the same expressions
evaluated once per pixel, so the same floats); a row's runs come in ring order, so the
bounds reduce contiguous ranges of runs. ``scripts/bench_learned3d.py`` times the parts.
Imports numpy only. (Moved unchanged from the learned estimator's feature module.)
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from eyeviz.core import healpix

__all__ = ["BANDS", "N_BOUNDS", "OVERHANG", "EyeSummary", "eye_summaries"]

# indices per pass of the run finder (its temporaries stay in cache)
_BLOCK = 1 << 16
#: rows per pass of the per-run work (its temporaries stay in cache)
_ROWS = 2048
#: per-pixel tables (:class:`_PixelTables`) are kept for nside up to 256 (about 50 MB)
_TABLE_NPIX = 12 * 256 * 256


@dataclass(frozen=True)
class EyeSummary:
    """Per-row summaries of one eye's lit sets (arrays of length n rows).

    ``count``: lit facets; ``sum_xyz`` (n, 3): the sum of their centre unit vectors;
    ``lon_w``/``lon_e``: the smallest west and largest east cell-edge longitude over
    the row's runs (radians, in [0, 2 pi]); ``z_top``/``z_bottom``: z of the first and
    last lit ring (the cap's z-extent, to within a ring).
    """

    count: np.ndarray
    sum_xyz: np.ndarray
    lon_w: np.ndarray
    lon_e: np.ndarray
    z_top: np.ndarray
    z_bottom: np.ndarray
    bounds: np.ndarray


@dataclass(frozen=True)
class _PixelTables:
    """Tables of one nside, so that a run costs gathers instead of a ring search and four
    sines and cosines: the ring of each pixel (``ring``), and tables per class of rings
    with the same cell count and offset (so with the same step and phi0: the equatorial
    rings form two classes, a polar ring and its mirror one), reached through per-ring
    offsets. For a run of ring k from position a to b (pixels s and e):

    - ``west[w0[k] + s]``, ``east[w0[k] + e]``: phi0 + (a - 0.5) step, phi0 + (b + 0.5)
      step, the run's outer cell edges;
    - ``sin_half[n0[k] + n - 1]``: sin(step n / 2) for n = b - a + 1 cells (times amp[k],
      the amplitude of the sum of their centres);
    - ``cis_mid[c0[k] + s + e]``: cos + i sin of the middle longitude phi0 + step (a + b) / 2.

    Each entry is the expression :meth:`_Rings.partial` and :func:`eye_summaries` evaluate
    per run, on the same floats (a class's rings have the same step and phi0), so both
    give the same results. The class tables are small (in the paper's elevations every
    ring is equatorial: two classes of 4 nside cells), so their gathers stay in cache."""

    ring: np.ndarray
    w0: np.ndarray
    n0: np.ndarray
    c0: np.ndarray
    west: np.ndarray
    east: np.ndarray
    sin_half: np.ndarray
    cis_mid: np.ndarray

    @classmethod
    def build(cls, r: _Rings) -> _PixelTables:
        kk = np.arange(1, 4 * r.nside, dtype=np.int64)
        ring = np.repeat(kk, r.num[kk])
        key = 2 * r.num[kk] + (r.phi0[kk] != 0.0)
        _, first_of, cls_of = np.unique(key, return_index=True, return_inverse=True)
        rep = kk[first_of]  # a ring of each class
        cnum = r.num[rep]
        coff = np.r_[0, np.cumsum(cnum)[:-1]]
        cring = np.repeat(rep, cnum)
        j = np.arange(cring.size, dtype=np.int64) - np.repeat(coff, cnum)
        west = r.phi0[cring] + (j - 0.5) * r.step[cring]
        east = r.phi0[cring] + (j + 0.5) * r.step[cring]
        sin_half = np.sin(0.5 * r.step[cring] * (j + 1).astype(np.float64))
        cring2 = np.repeat(rep, 2 * cnum)
        j2 = np.arange(cring2.size, dtype=np.int64) - np.repeat(2 * coff, 2 * cnum)
        mid = r.phi0[cring2] + 0.5 * r.step[cring2] * j2
        cis = np.empty(mid.size, np.complex128)
        cis.real = np.cos(mid)
        cis.imag = np.sin(mid)
        w0 = np.zeros(r.num.size, np.int64)
        n0 = np.zeros(r.num.size, np.int64)
        c0 = np.zeros(r.num.size, np.int64)
        off = coff[cls_of.ravel()]
        w0[kk] = off - r.first[kk]
        n0[kk] = off
        c0[kk] = 2 * off - 2 * r.first[kk]
        return cls(ring, w0, n0, c0, west, east, sin_half, cis)


class _Rings:
    """Per-ring tables of one nside: first pixel, cells, longitude offset, z, sin(theta)
    and the prefix sums of n_k z_k (rings 0 .. 4 nside; 0 and 4 nside are empty)."""

    _cache: dict[int, _Rings] = {}

    def __init__(self, nside: int) -> None:
        k = np.arange(1, 4 * nside, dtype=np.int64)
        first, num, shifted = healpix.ring_info(nside, k)
        sth, z = healpix.ring_sz(nside, k)
        pad = np.zeros(1)
        self.nside = nside
        self.first = np.concatenate([[0], first, [12 * nside * nside]]).astype(np.int64)
        self.num = np.concatenate([[1], num, [1]]).astype(np.int64)
        self.last = self.first + self.num - 1  # last pixel of each ring
        self.step = 2.0 * math.pi / self.num
        self.phi0 = np.where(np.concatenate([[False], shifted, [False]]), 0.5 * self.step, 0.0)
        self.z = np.concatenate([[1.0], z, [-1.0]])
        self.sth = np.concatenate([pad, sth, pad])
        zsum = np.concatenate([pad, num * z, pad])
        self.zcum = np.concatenate([[0.0], np.cumsum(zsum)])  # zcum[k] = sum over rings < k
        self.amp = self.sth / np.sin(0.5 * self.step)
        self.theta = np.arctan2(self.sth, self.z)
        self._pixels: _PixelTables | None = None

    @classmethod
    def of(cls, nside: int) -> _Rings:
        r = cls._cache.get(nside)
        if r is None:
            if len(cls._cache) > 8:
                cls._cache.clear()
            r = cls._cache[nside] = cls(nside)
        return r

    def pixels(self) -> _PixelTables | None:
        """The per-pixel tables (built once), or None above :data:`_TABLE_NPIX` pixels."""
        if self._pixels is None and 12 * self.nside * self.nside <= _TABLE_NPIX:
            self._pixels = _PixelTables.build(self)
        return self._pixels

    def ring(self, pix: np.ndarray) -> np.ndarray:
        """Ring number (1 .. 4 nside - 1) of each pixel."""
        return np.searchsorted(self.first, pix, side="right") - 1

    def partial(self, k: np.ndarray, a: np.ndarray, b: np.ndarray) -> list[np.ndarray]:
        """Sums of the centres of cells a..b (positions in ring k, a <= b): [x, y, z]."""
        d = self.step[k]
        n = (b - a + 1).astype(np.float64)
        amp = self.amp[k] * np.sin(0.5 * d * n)
        mid = self.phi0[k] + 0.5 * d * (a + b)
        return [amp * np.cos(mid), amp * np.sin(mid), n * self.z[k]]


def _run_starts(flat: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(positions, first values, last values, int64) of the runs of consecutive values in
    ``flat`` (non-empty): a run starts at j = 0 and at every j with flat[j] !=
    flat[j - 1] + 1 (in the array's own integer arithmetic). One pass, in blocks whose
    temporaries stay in cache; a run's first and last value are read while their block
    is there, into arrays that grow as needed."""
    m = flat.size - 1  # steps
    cap = m // 16 + 1024
    at_all = np.empty(cap, np.int64)
    s_all = np.empty(cap, np.int64)
    e_all = np.empty(cap, np.int64)
    at_all[0], s_all[0], k = 0, flat[0], 1  # k runs so far; e_all[k - 1] still open
    if m > 0:
        dif = np.empty(min(_BLOCK, m), flat.dtype)
        brk = np.empty(min(_BLOCK, m), bool)
        for lo in range(0, m, _BLOCK):
            hi = min(lo + _BLOCK, m)
            blk = flat[lo : hi + 1]
            np.subtract(blk[1:], blk[:-1], out=dif[: hi - lo])
            np.not_equal(dif[: hi - lo], 1, out=brk[: hi - lo])
            at = np.flatnonzero(brk[: hi - lo])
            if k + at.size > cap:
                cap = 2 * (k + at.size)
                at_all, s_all, e_all = (np.resize(v, cap) for v in (at_all, s_all, e_all))
            e_all[k - 1 : k - 1 + at.size] = blk[at]
            at += 1
            s_all[k : k + at.size] = blk[at]
            at += lo
            at_all[k : k + at.size] = at
            k += at.size
    e_all[k - 1] = flat[-1]
    return at_all[:k], s_all[:k], e_all[:k]


def _runs(indptr: np.ndarray, indices: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(first run of each row, first index, last index of every run): the runs of
    consecutive indices in row order (a run never spans two rows); a row with no index
    has no run, and its first run is the next row's.

    One pass over the indices (:func:`_run_starts`); the row starts that do not already
    break a run are inserted afterwards."""
    base = int(indptr[0])
    nnz = int(indptr[-1]) - base
    rel = indptr - base
    if nnz == 0:
        e = np.zeros(0, np.int64)
        return np.zeros(indptr.shape[0] - 1, np.int64), e, e
    flat = indices[base : base + nnz]
    st, s, e = _run_starts(flat)
    rs = rel[:-1]
    # rows with an index (an empty row's start is the next row's, so keep each start once)
    rs = rs[(rs < nnz) & np.r_[True, rs[1:] != rs[:-1]]]
    pos = np.searchsorted(st, rs)
    miss = pos == st.size
    miss |= st[np.minimum(pos, st.size - 1)] != rs
    if miss.any():  # a row that goes on where the previous one ended: split its run
        q, p = rs[miss], pos[miss]
        st = np.insert(st, p, q)
        s = np.insert(s, p, flat[q].astype(np.int64))
        e = np.insert(e, p - 1, flat[q - 1].astype(np.int64))
    first_run = np.searchsorted(st, rel[:-1])
    return first_run, s, e


def eye_summaries(
    nside: int, indptr: np.ndarray, indices: np.ndarray, name: str = "", bounds: bool = True
) -> EyeSummary:
    """The summaries of every row of one eye's CSR lit sets (sorted RING indices).

    Rows with no lit facet get count 0, a zero sum and NaN longitudes and z. With a
    ``name``, the indices are checked (each row strictly increasing, every index in
    [0, 12 nside^2)) on the runs, at no cost per index: ValueError naming ``name``,
    with the messages of :func:`eyeviz.estimators.base.as_csr`. With ``bounds`` False
    the longitude bounds are not computed (left at -1 and 1: no bound; the other
    fields are the same), for callers that read only the count and the sum."""
    indptr = np.asarray(indptr, np.int64)
    indices = np.asarray(indices)
    if name and not (
        indices.dtype == np.int64 or (indices.dtype == np.int32 and indices.size < 2**31)
    ):
        indices = indices.astype(np.int64)  # so no run can wrap all the way round
    rings = _Rings.of(int(nside))
    n = indptr.shape[0] - 1
    count = np.diff(indptr)
    first_run, s, e = _runs(indptr, indices)
    if name:
        _check_runs(name, rings, count, first_run, s, e, indices.dtype)
    sum_xyz = np.zeros((n, 3))
    lon_w = np.full(n, np.nan)
    lon_e = np.full(n, np.nan)
    z_top = np.full(n, np.nan)
    z_bottom = np.full(n, np.nan)
    lon_bounds = np.empty((n, N_BOUNDS))
    lon_bounds[:, 0::2] = -_NO_BOUND
    lon_bounds[:, 1::2] = _NO_BOUND
    # rows in groups whose per-run temporaries stay in cache (every value is per run or
    # per row, so the grouping changes no float)
    for lo in range(0, n, _ROWS):
        hi = min(lo + _ROWS, n)
        r0, r1 = int(first_run[lo]), (int(first_run[hi]) if hi < n else s.size)
        if r1 == r0:
            continue
        fr = first_run[lo:hi] - r0
        out = (sum_xyz[lo:hi], lon_w[lo:hi], lon_e[lo:hi], z_top[lo:hi], z_bottom[lo:hi])
        runs = _summarise(rings, count[lo:hi], fr, s[r0:r1], e[r0:r1], out)
        if bounds:
            _bounds(rings, count[lo:hi], sum_xyz[lo:hi], fr, *runs, out=lon_bounds[lo:hi])
    return EyeSummary(count, sum_xyz, lon_w, lon_e, z_top, z_bottom, lon_bounds)


def _summarise(
    rings: _Rings,
    count: np.ndarray,
    first_run: np.ndarray,
    s: np.ndarray,
    e: np.ndarray,
    out: tuple[np.ndarray, ...],
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Fill ``out`` = (sum_xyz, lon_w, lon_e, z_top, z_bottom) of rows whose runs are
    (s, e) (the rows' first runs ``first_run``, relative to s); returns the per-run
    (ring, west, east, within one ring) that :func:`_bounds` reads."""
    sum_xyz, lon_w, lon_e, z_top, z_bottom = out
    px = rings.pixels()
    ks = px.ring[s] if px is not None else rings.ring(s)
    lastp = rings.last[ks]
    same = e <= lastp
    cross = None if same.all() else np.flatnonzero(~same)
    eb = e if cross is None else np.minimum(e, lastp)  # the run's end in its first ring
    if px is not None:
        span = eb - s
        amp = rings.amp[ks]
        amp *= px.sin_half[px.n0[ks] + span]
        mid = px.c0[ks]
        mid += s
        mid += eb
        cis = px.cis_mid[mid]
        tot = [amp * cis.real, amp * cis.imag, (span + 1).astype(np.float64)]
        tot[2] *= rings.z[ks]
        w0 = px.w0[ks]
        west = px.west[w0 + s]
        w0 += eb
        east = px.east[w0]
    else:
        a = s - rings.first[ks]
        b = eb - rings.first[ks]
        tot = rings.partial(ks, a, b)
        west = rings.phi0[ks] + (a - 0.5) * rings.step[ks]
        east = rings.phi0[ks] + (b + 0.5) * rings.step[ks]
    ke = ks
    if cross is not None:  # runs across ring boundaries: tail + whole rings + head
        kc = ks[cross]
        kd = rings.ring(e[cross])
        bd = e[cross] - rings.first[kd]
        for col, extra in zip(tot, rings.partial(kd, np.zeros_like(kd), bd), strict=True):
            col[cross] += extra
        tot[2][cross] += rings.zcum[kd] - rings.zcum[kc + 1]
        west[cross] = 0.0
        east[cross] = 2.0 * math.pi
        ke = ks.copy()
        ke[cross] = kd
    has = count > 0
    full: np.ndarray | slice = slice(None) if has.all() else has
    fr = first_run[full]
    for j, col in enumerate(tot):
        sum_xyz[full, j] = np.add.reduceat(col, fr)
    lon_w[full] = np.minimum.reduceat(west, fr)
    lon_e[full] = np.maximum.reduceat(east, fr)
    z_top[full] = rings.z[ks[fr]]
    last_run = np.r_[fr[1:] - 1, s.size - 1]
    z_bottom[full] = rings.z[ke[last_run]]
    return ks, west, east, same


#: The lit cap's radius from the count, 2 pi (1 - cos a) = count * 4 pi / npix, exceeds
#: the ball's by this many facet widths sqrt(4 pi / npix) on average (the boundary cells
#: are partly covered; measured: 0.635, sd 0.04, on paper-regime balls at nside 180).
OVERHANG = 0.635
#: Rings within this many alpha of the centre's colatitude cross the cap's boundary more
#: steeply than the cells' edges.
_STEEP = 0.7
#: Bands of the ring's colatitude offset from the centre, in units of alpha (above and
#: below the centre: an error in the centre's z shifts their half-widths oppositely).
BANDS = np.array([-_STEEP, 0.0, _STEEP])
N_BOUNDS = 4 * (len(BANDS) - 1)
_NO_BOUND = 1.0


# long: each run's two ends bound the longitude in one vectorised pass, the wrap and the poles
# included; split, the per-run arrays would pass between pieces
def _bounds(
    rings: _Rings,
    count: np.ndarray,
    sum_xyz: np.ndarray,
    first_run: np.ndarray,
    ks: np.ndarray,
    west: np.ndarray,
    east: np.ndarray,
    same: np.ndarray,
    out: np.ndarray,
) -> None:
    """Bounds on the cap centre's longitude from each run's two ends, into ``out`` (n,
    N_BOUNDS) (set beforehand to -1 and 1 in alternate columns).

    On a ring whose crossing with the cap's boundary is steeper than the cells' edges
    (the ring lies within _STEEP * alpha of the centre's colatitude), the west crossing
    lies between the west and the east vertex of the run's first cell and the east
    crossing between those of its last cell; with the half-width w_k of the cap on that
    ring (from the mean direction and the count's radius less :data:`OVERHANG`), the
    centre longitude lies in [west + w_k, west + d + w_k] and [east - d - w_k, east -
    w_k] (d the ring's cell width). Per row, the largest lower and smallest upper bound
    over the rings above and below the centre, for the west and east ends, relative to
    the mean direction's longitude in equatorial facet widths gamma, clipped to
    [-1, 1] (empty groups: -1 and 1): columns (west above lo, hi; west below lo, hi;
    east above lo, hi; east below lo, hi).

    A row's runs come in ring order, so each band of rings is a contiguous range of its
    runs, found per row on the ring table (:func:`_band_rings`): one reduction per
    column and band, no mask per band."""
    full = np.flatnonzero(count > 0)
    if ks.size == 0:
        return
    nside = rings.nside
    npix = 12 * nside * nside
    gamma = 2.0 * math.pi / (4 * nside)
    pix = math.sqrt(4.0 * math.pi / npix)
    cnt = np.maximum(count, 1).astype(np.float64)
    with np.errstate(invalid="ignore", divide="ignore"):
        norm = np.linalg.norm(sum_xyz, axis=1)
        z0 = np.clip(sum_xyz[:, 2] / norm, -1.0, 1.0)
        lon0 = np.arctan2(sum_xyz[:, 1], sum_xyz[:, 0]) % (2.0 * math.pi)
    cos_a = np.clip(1.0 - cnt * (4.0 * math.pi / npix) / (2.0 * math.pi), -1.0, 1.0)
    alpha = np.maximum(np.arccos(cos_a) - OVERHANG * pix, 0.5 * pix)
    theta0 = np.arccos(z0)
    lens = np.diff(np.r_[first_run, ks.size])
    sth0 = np.sqrt(1.0 - z0 * z0)
    with np.errstate(invalid="ignore", divide="ignore"):
        arg = np.repeat(np.cos(alpha), lens)
        t = rings.z[ks]
        t *= np.repeat(z0, lens)
        arg -= t
        np.take(rings.sth, ks, out=t)
        t *= np.repeat(sth0, lens)
        arg /= t
    use = np.abs(arg) < 1.0
    if not same.all():
        use &= same
    # w_k where the ring counts (|arg| < 1, the run within one ring), NaN elsewhere: the
    # reductions below skip NaN (fmax, fmin)
    w = np.full(arg.shape, np.nan)
    np.arccos(arg, out=w, where=use)
    # per row, the first run of each band
    kb = _band_rings(rings, theta0[full], alpha[full])  # (len(full), len(BANDS))
    at = _first_run_on(ks, first_run[full], first_run[full] + lens[full], kb)
    seg = at.ravel()
    # the four columns: max of base, min of base + d, max of top - d, min of top (the
    # upper bounds' maxima of the negated values are minus these minima), each with a
    # NaN after the last run (a band that reaches the end starts there)
    m = ks.size
    red = np.empty((full.size, len(BANDS), 4))
    reducers = (np.fmax, np.fmin, np.fmax, np.fmin)
    if ks.min() >= nside and ks.max() <= 3 * nside:
        # equatorial rings only: d is one step, and base = (west + w) - lon0, base + d,
        # top = (east - w) - lon0, top - d are non-decreasing functions of west + w and
        # east - w within a row (rounding is monotone), so each extreme is the function
        # of that extreme: two columns per run instead of four (the same floats)
        cols = np.empty((2, m + 1))
        cols[:, m] = np.nan
        np.add(west, w, out=cols[0, :m])
        np.subtract(east, w, out=cols[1, :m])
        for j, red_f in enumerate(reducers):
            red[:, :, j] = red_f.reduceat(cols[j // 2], seg).reshape(at.shape)
        d1 = rings.step[nside]
        red -= lon0[full][:, None, None]
        red[:, :, 1] += d1
        red[:, :, 2] -= d1
    else:
        d = rings.step[ks]
        lon0_r = np.repeat(lon0, lens)
        cols = np.empty((4, m + 1))
        cols[:, m] = np.nan
        base, base_d, top_d, top = cols[0, :m], cols[1, :m], cols[2, :m], cols[3, :m]
        np.add(west, w, out=base)
        base -= lon0_r
        np.subtract(east, w, out=top)
        top -= lon0_r
        np.add(base, d, out=base_d)
        np.subtract(top, d, out=top_d)
        for j, red_f in enumerate(reducers):
            red[:, :, j] = red_f.reduceat(cols[j], seg).reshape(at.shape)
    # band b: runs [at[:, b], at[:, b + 1]); columns 4 b + j
    bands = red[:, :-1, :].reshape(full.size, N_BOUNDS)
    ok = np.repeat(at[:, 1:] > at[:, :-1], 4, axis=1) & ~np.isnan(bands)
    got = out[full]
    np.copyto(got, np.clip(bands / gamma, -_NO_BOUND, _NO_BOUND), where=ok)
    out[full] = got


def _first_run_on(ks: np.ndarray, lo: np.ndarray, hi: np.ndarray, k: np.ndarray) -> np.ndarray:
    """(rows, j): per row, the first of its runs lo .. hi - 1 whose ring is >= k[:, j]
    (hi if none): a row's rings rise along its runs. Guessed as one run per ring from the
    row's first ring, which holds unless a ring has two runs (a cap across longitude 0)
    or a run spans rings; those rows are bisected."""
    lo, hi = lo[:, None], hi[:, None]
    n = hi - lo
    if ks.size == 0:
        return np.broadcast_to(lo, k.shape).copy()
    k0 = ks[np.minimum(lo, ks.size - 1)]
    at = lo + np.clip(k - k0, 0, n)
    before = ks[np.maximum(at - 1, 0)]
    here = ks[np.minimum(at, ks.size - 1)]
    bad = ((at > lo) & (before >= k)) | ((at < hi) & (here < k))
    if bad.any():
        r, c = np.nonzero(bad)
        a = np.broadcast_to(lo, k.shape)[r, c].copy()
        b = np.broadcast_to(hi, k.shape)[r, c].copy()
        want = k[r, c]
        while True:
            go = a < b
            if not go.any():
                break
            mid = (a + b) >> 1
            low = go & (ks[np.minimum(mid, ks.size - 1)] < want)
            a = np.where(low, mid + 1, a)
            b = np.where(go & ~low, mid, b)
        at[r, c] = a
    return at


def _band_rings(rings: _Rings, theta0: np.ndarray, alpha: np.ndarray) -> np.ndarray:
    """(rows, len(BANDS)): per row, the first ring k whose (theta_k - theta0) / alpha,
    evaluated as :func:`_bounds` would per run, exceeds each of :data:`BANDS` (4 nside + 1
    if none does): a row's runs in band b are those on rings [k_b, k_(b+1)). A guess from
    the ring table, then steps with that very expression (monotone in theta_k), so a
    run's band is the one its own comparison would give, ties included. NaN rows get
    4 nside + 1."""
    th = rings.theta
    m = th.size
    nb = BANDS.size
    t0 = np.repeat(theta0, nb)  # flat (row, band)
    al = np.repeat(alpha, nb)
    c = np.tile(BANDS, theta0.size)

    def passes(k: np.ndarray) -> np.ndarray:  # ring k's value exceeds the edge; k = m: yes
        v = th[np.minimum(k, m - 1)]
        v -= t0
        v /= al
        return (v > c) | (k >= m)

    with np.errstate(invalid="ignore"):
        # a guess from the sorted table, then exact steps down and up (0 or 1 usually)
        k = np.searchsorted(th, t0 + c * al, side="right")
        while True:
            down = (k > 0) & passes(k - 1)
            if not down.any():
                break
            k -= down
        while True:
            up = ~passes(k)
            if not up.any():
                break
            k += up
    return k.reshape(theta0.size, nb)


def _check_runs(
    name: str,
    rings: _Rings,
    count: np.ndarray,
    first_run: np.ndarray,
    s: np.ndarray,
    e: np.ndarray,
    dtype: np.dtype,
) -> None:
    """Within a run the indices rise by one (in the indices' own integer arithmetic); so
    a row is strictly increasing iff each run starts above the previous run's end, and
    in range iff its runs' ends are (a run whose end lies below its start wrapped past
    the dtype's largest value, which it then holds). The messages are
    :func:`eyeviz.estimators.base.as_csr`'s."""
    if s.size == 0:
        return
    npix = int(rings.first[-1])
    lo, hi = int(s.min()), int(e.max())
    wrapped = bool(np.any(e < s))
    if lo < 0 or hi >= npix or wrapped:
        # the smallest index if negative, else the largest (as_csr's choice); a wrapped
        # run holds both of the dtype's extremes
        info = np.iinfo(dtype)
        lo, hi = (int(info.min), int(info.max)) if wrapped else (lo, hi)
        bad = lo if lo < 0 else hi
        raise ValueError(f"{name}: indices must lie in [0, npix = {npix}), got {bad}")
    # runs that do not start above the previous run's end must each start a row
    j = np.flatnonzero(s[1:] <= e[:-1]) + 1
    if j.size:
        heads = first_run[count > 0]
        at = np.minimum(np.searchsorted(heads, j), heads.size - 1)
        if not np.array_equal(heads[at], j):
            raise ValueError(f"{name}: indices must increase strictly within a row")
