"""Summaries of the spherical eyes' lit sets, from CSR rows, for the learned 3D estimator.

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
direction, as the set of caps consistent with the lit set does). :func:`features` turns
both eyes' summaries into the network's input and the triangulation it corrects.
Imports numpy only.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from eyeviz.core import healpix

__all__ = [
    "N_FEATURES",
    "EyeSummary",
    "eye_summaries",
    "features",
    "triangulate",
]

# indices per pass of the run finder (temporaries stay in cache)
_BLOCK = 1 << 18


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
        self.step = 2.0 * math.pi / self.num
        self.phi0 = np.where(np.concatenate([[False], shifted, [False]]), 0.5 * self.step, 0.0)
        self.z = np.concatenate([[1.0], z, [-1.0]])
        self.sth = np.concatenate([pad, sth, pad])
        zsum = np.concatenate([pad, num * z, pad])
        self.zcum = np.concatenate([[0.0], np.cumsum(zsum)])  # zcum[k] = sum over rings < k
        self.amp = self.sth / np.sin(0.5 * self.step)
        self.theta = np.arctan2(self.sth, self.z)

    @classmethod
    def of(cls, nside: int) -> _Rings:
        r = cls._cache.get(nside)
        if r is None:
            if len(cls._cache) > 8:
                cls._cache.clear()
            r = cls._cache[nside] = cls(nside)
        return r

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


def _runs(indptr: np.ndarray, indices: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(first run of each row, first index, last index of every run): the runs of
    consecutive indices in row order (a run never spans two rows); a row with no index
    has no run, and its first run is the next row's.

    One pass over the indices, in blocks whose temporaries stay in cache."""
    base = int(indptr[0])
    nnz = int(indptr[-1]) - base
    rel = indptr - base
    if nnz == 0:
        e = np.zeros(0, np.int64)
        return np.zeros(indptr.shape[0] - 1, np.int64), e, e
    row_start = np.zeros(nnz + 1, bool)
    row_start[rel[:-1]] = True  # an empty row marks the next row's start (or nnz)
    brk = np.empty(min(_BLOCK, nnz), bool)
    dif = np.empty(min(_BLOCK, nnz), indices.dtype)
    starts: list[np.ndarray] = []
    flat = indices[base : base + nnz]
    for lo in range(0, nnz, _BLOCK):
        hi = min(lo + _BLOCK, nnz)
        k = hi - lo
        b = brk[:k]
        if lo == 0:
            b[0] = True
        else:
            b[0] = flat[lo] != flat[lo - 1] + 1
        np.subtract(flat[lo + 1 : hi], flat[lo : hi - 1], out=dif[: k - 1])
        np.not_equal(dif[: k - 1], 1, out=b[1:])
        np.logical_or(b, row_start[lo:hi], out=b)
        starts.append(np.flatnonzero(b) + lo)
    s = np.concatenate(starts) if len(starts) > 1 else starts[0]
    ends = np.empty_like(s)
    ends[:-1] = s[1:] - 1
    ends[-1] = nnz - 1
    first_run = np.searchsorted(s, rel[:-1])
    return first_run, flat[s].astype(np.int64), flat[ends].astype(np.int64)


def eye_summaries(
    nside: int, indptr: np.ndarray, indices: np.ndarray, name: str = ""
) -> EyeSummary:
    """The summaries of every row of one eye's CSR lit sets (sorted RING indices).

    Rows with no lit facet get count 0, a zero sum and NaN longitudes and z. With a
    ``name``, the indices are checked (each row strictly increasing, every index in
    [0, 12 nside^2)) on the runs, at no cost per index: ValueError naming ``name``."""
    indptr = np.asarray(indptr, np.int64)
    indices = np.asarray(indices)
    rings = _Rings.of(int(nside))
    n = indptr.shape[0] - 1
    count = np.diff(indptr)
    first_run, s, e = _runs(indptr, indices)
    if name:
        _check_runs(name, rings, count, first_run, s, e)
    ks = rings.ring(s)
    a = s - rings.first[ks]
    b = e - rings.first[ks]
    last = rings.num[ks] - 1
    same = b <= last
    tot = rings.partial(ks, a, np.minimum(b, last))
    west = rings.phi0[ks] + (a - 0.5) * rings.step[ks]
    east = rings.phi0[ks] + (b + 0.5) * rings.step[ks]
    ke = ks
    if not same.all():  # runs across ring boundaries: tail + whole rings + head
        cross = np.flatnonzero(~same)
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
    full = count > 0
    sum_xyz = np.zeros((n, 3))
    lon_w = np.full(n, np.nan)
    lon_e = np.full(n, np.nan)
    z_top = np.full(n, np.nan)
    z_bottom = np.full(n, np.nan)
    if s.size:
        fr = first_run[full]
        sum_xyz[full] = np.stack([np.add.reduceat(col, fr) for col in tot], axis=1)
        lon_w[full] = np.minimum.reduceat(west, fr)
        lon_e[full] = np.maximum.reduceat(east, fr)
        z_top[full] = rings.z[ks[fr]]
        last_run = np.r_[fr[1:] - 1, s.size - 1]
        z_bottom[full] = rings.z[ke[last_run]]
    bounds = _bounds(rings, count, sum_xyz, first_run, ks, west, east, same)
    return EyeSummary(count, sum_xyz, lon_w, lon_e, z_top, z_bottom, bounds)


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
N_FEATURES = 20 + 2 * N_BOUNDS
_NO_BOUND = 1.0


def _bounds(
    rings: _Rings,
    count: np.ndarray,
    sum_xyz: np.ndarray,
    first_run: np.ndarray,
    ks: np.ndarray,
    west: np.ndarray,
    east: np.ndarray,
    same: np.ndarray,
) -> np.ndarray:
    """Bounds on the cap centre's longitude from each run's two ends (n, N_BOUNDS).

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
    east above lo, hi; east below lo, hi)."""
    n = count.shape[0]
    out = np.empty((n, N_BOUNDS))
    out[:, 0::2] = -_NO_BOUND
    out[:, 1::2] = _NO_BOUND
    full = np.flatnonzero(count > 0)
    if ks.size == 0:
        return out
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
    row = np.repeat(np.arange(n), lens)
    zk = rings.z[ks]
    t = rings.theta[ks] - theta0[row]
    sth0 = np.sqrt(1.0 - z0 * z0)
    d = rings.step[ks]
    big = 1e300
    fr = first_run[full]
    with np.errstate(invalid="ignore", divide="ignore"):
        arg = (np.cos(alpha)[row] - zk * z0[row]) / (rings.sth[ks] * sth0[row])
    use = same & (np.abs(arg) < 1.0)
    w = np.arccos(np.clip(arg, -1.0, 1.0))
    base = west + w - lon0[row]
    top = east - w - lon0[row]
    band = np.searchsorted(BANDS, t / alpha[row]) - 1  # -1 / len(BANDS) - 1: outside
    # lower bounds as they are, upper bounds negated: a maximum per band and column
    cols = (base, -(base + d), top - d, -top)
    for b in range(len(BANDS) - 1):
        grp = use & (band == b)
        for j, v in enumerate(cols):
            red = np.maximum.reduceat(np.where(grp, v, -big), fr)
            ok = red > -big
            sign = 1.0 if j % 2 == 0 else -1.0
            out[full[ok], 4 * b + j] = np.clip(sign * red[ok] / gamma, -_NO_BOUND, _NO_BOUND)
    return out


def _check_runs(
    name: str,
    rings: _Rings,
    count: np.ndarray,
    first_run: np.ndarray,
    s: np.ndarray,
    e: np.ndarray,
) -> None:
    """Within a run the indices rise by one; so a row is strictly increasing iff each run
    starts above the previous run's end, and in range iff its runs are."""
    if s.size == 0:
        return
    npix = int(rings.first[-1])
    if s.min() < 0 or e.max() >= npix or np.any(e < s):
        raise ValueError(f"{name}: indices must lie in [0, npix = {npix})")
    later = np.ones(s.size, bool)
    later[first_run[count > 0]] = False
    j = np.flatnonzero(later)
    if np.any(s[j] <= e[j - 1]):
        raise ValueError(f"{name}: indices must increase strictly within a row")


def triangulate(
    u: np.ndarray, v: np.ndarray, h: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(x, y, z, ok): the midpoint of the closest approach of the rays A + s u and B + t v
    from A = (-h, 0, 0) and B = (h, 0, 0) (unit directions (n, 3)); ``ok`` is False where
    they do not meet in front of both eyes (s or t <= 0, or parallel), and the point is
    then far along the mean of u and v (the 3D form of the planar triangulation)."""
    b = np.einsum("ij,ij->i", u, v)
    d = -2.0 * h * u[:, 0]  # u . (A - B)
    e = -2.0 * h * v[:, 0]
    den = 1.0 - b * b
    with np.errstate(divide="ignore", invalid="ignore"):
        s = (b * e - d) / den
        t = (e - b * d) / den
    ok = (den > 1e-15) & (s > 0) & (t > 0) & np.isfinite(s) & np.isfinite(t)
    s = np.where(ok, s, 1.0)
    t = np.where(ok, t, 1.0)
    x = 0.5 * (s * u[:, 0] + t * v[:, 0])
    y = 0.5 * (s * u[:, 1] + t * v[:, 1])
    z = 0.5 * (s * u[:, 2] + t * v[:, 2])
    return x, y, z, ok


def features(
    sa: EyeSummary, sb: EyeSummary, h: float, nside: int, r_min: float, r_max: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(X float32 (n, N_FEATURES), log r0, azimuth0, elevation0, valid, flagged).

    r0, azimuth0, elevation0 are the triangulation of the two mean directions, r0 clipped
    to [r_min, r_max] (where the rays do not meet: r_max); the network corrects them.
    Columns: per eye the mean direction's longitude and z, the angular radius of the
    lit cap from the count (count * 4 pi / npix = 2 pi (1 - cos alpha)) and from the
    mean vector's length ((1 + cos alpha) / 2 for a uniform cap), the west and east edge
    longitudes about the mean, the z-extent about the mean and the centre longitude's
    bounds (:func:`_bounds`); then the disparities of the mean longitudes and of the two
    edges, the triangulation, its 1 / disparity and the difference of the cap radii.
    ``valid`` is False where an eye lit nothing (the features are then NaN);
    ``flagged`` where the rays do not meet in front of both eyes."""
    npix = 12 * nside * nside
    omega = 4.0 * math.pi / npix
    cols = []
    dirs = []
    for s in (sa, sb):
        cnt = s.count.astype(np.float64)
        with np.errstate(divide="ignore", invalid="ignore"):
            norm = np.linalg.norm(s.sum_xyz, axis=1)
            u = s.sum_xyz / norm[:, None]
            lon = np.arctan2(u[:, 1], u[:, 0]) % (2.0 * math.pi)
            cos_a_count = 1.0 - cnt * omega / (2.0 * math.pi)
            alpha_count = np.arccos(np.clip(cos_a_count, -1.0, 1.0))
            cos_a_mean = np.clip(2.0 * norm / cnt - 1.0, -1.0, 1.0)
            alpha_mean = np.arccos(cos_a_mean)
        dirs.append((u, lon, alpha_count))
        cols += [
            lon - 0.5 * math.pi,
            u[:, 2],
            alpha_count,
            alpha_mean - alpha_count,
            (lon - s.lon_w) - alpha_count,
            (s.lon_e - lon) - alpha_count,
            0.5 * (s.z_top + s.z_bottom) - u[:, 2],
            *s.bounds.T,
        ]
    (u, lon_a, al_a), (v, lon_b, al_b) = dirs
    x, y, z, ok = triangulate(u, v, h)
    rho = np.sqrt(x * x + y * y + z * z)
    r0 = np.where(ok, np.clip(rho, r_min, r_max), r_max)
    mean_dir = u + v
    with np.errstate(invalid="ignore", divide="ignore"):
        mean_dir /= np.linalg.norm(mean_dir, axis=1, keepdims=True)
        az0 = np.where(ok, np.arctan2(y, x), np.arctan2(mean_dir[:, 1], mean_dir[:, 0]))
        el0 = np.where(ok, np.arcsin(np.clip(z / rho, -1.0, 1.0)), np.arcsin(mean_dir[:, 2]))
    disp = lon_b - lon_a
    log_r0 = np.log(r0)
    gamma = 2.0 * math.pi / (4 * nside)
    cols += [
        disp / gamma,
        (sb.lon_w - sa.lon_w) / gamma,
        (sb.lon_e - sa.lon_e) / gamma,
        log_r0 - 0.5 * math.log(r_min * r_max),
        1.0 / (np.abs(disp) / gamma + 1.0),
        al_a - al_b,
    ]
    X = np.stack(cols, axis=1).astype(np.float32)
    valid = (sa.count > 0) & (sb.count > 0) & np.isfinite(X).all(axis=1)
    return X, log_r0, az0, el0, valid, ~ok
