"""The fast path of the learned 3D estimator's summaries (issue 23's speed target) against
the implementation it replaced, kept below as the reference: every summary and every
prediction must be the same float (the shipped weights were trained on the reference's
features). Also the checks of the indices that the run finder makes instead of
``lit_csr.as_csr``'s separate pass: the same inputs refused, with the same messages."""

from __future__ import annotations

import dataclasses
import math
import threading

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from eyeviz.core import healpix
from eyeviz.core.domain import Domain3D
from eyeviz.dataset.algorithm1_3d import generate3d
from eyeviz.estimators import healpix_summaries as lf
from eyeviz.estimators import learned3d, lit_csr
from eyeviz.estimators.healpix_summaries import (
    BANDS,
    N_BOUNDS,
    OVERHANG,
    EyeSummary,
    eye_summaries,
)
from eyeviz.estimators.learned3d_features import features

SEED = 9_023_555  # neither the shipped training nor its validation seed
_NO_BOUND = 1.0

# --- the reference: learned3d_features before the fast path (per-run ring search,
# sines and cosines, a mask per band), verbatim but for the names --------------------

_REF_BLOCK = 1 << 18


class _RefRings:
    """Per-ring tables of one nside: first pixel, cells, longitude offset, z, sin(theta)
    and the prefix sums of n_k z_k (rings 0 .. 4 nside; 0 and 4 nside are empty)."""

    _cache: dict[int, _RefRings] = {}

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
    def of(cls, nside: int) -> _RefRings:
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


def _ref_runs(indptr: np.ndarray, indices: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
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
    brk = np.empty(min(_REF_BLOCK, nnz), bool)
    dif = np.empty(min(_REF_BLOCK, nnz), indices.dtype)
    starts: list[np.ndarray] = []
    flat = indices[base : base + nnz]
    for lo in range(0, nnz, _REF_BLOCK):
        hi = min(lo + _REF_BLOCK, nnz)
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


def ref_eye_summaries(nside: int, indptr: np.ndarray, indices: np.ndarray) -> EyeSummary:
    """The summaries of every row of one eye's CSR lit sets (sorted RING indices).

    Rows with no lit facet get count 0, a zero sum and NaN longitudes and z."""
    indptr = np.asarray(indptr, np.int64)
    indices = np.asarray(indices)
    rings = _RefRings.of(int(nside))
    n = indptr.shape[0] - 1
    count = np.diff(indptr)
    first_run, s, e = _ref_runs(indptr, indices)
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
    bounds = _ref_bounds(rings, count, sum_xyz, first_run, ks, west, east, same)
    return EyeSummary(count, sum_xyz, lon_w, lon_e, z_top, z_bottom, bounds)


def _ref_bounds(
    rings: _RefRings,
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


# --- the fast path against the reference ---------------------------------------------

FIELDS = ("count", "sum_xyz", "lon_w", "lon_e", "z_top", "z_bottom", "bounds")


def _assert_same(got: EyeSummary, want: EyeSummary) -> None:
    """Bit for bit (NaN where the reference has NaN)."""
    for f in FIELDS:
        g, w = getattr(got, f), getattr(want, f)
        assert g.shape == w.shape, f
        if not np.array_equal(g, w, equal_nan=True):
            diff = np.nanmax(np.abs(g - w)) if np.isfinite(g).any() else "NaN pattern"
            raise AssertionError(f"{f} differs from the reference (max |diff| {diff})")


def _csr(rows, dtype=np.int32):
    ptr = np.r_[0, np.cumsum([len(r) for r in rows])].astype(np.int64)
    ind = np.concatenate([np.asarray(r, np.int64) for r in rows] + [np.zeros(0, np.int64)])
    return ptr, ind.astype(dtype)


@pytest.mark.parametrize("nside", [16, 180])
def test_summaries_are_the_reference_floats(nside):
    ds = generate3d(300, Domain3D(nside=nside), seed=SEED)
    for ptr, ind in ((ds.indptr_a, ds.indices_a), (ds.indptr_b, ds.indices_b)):
        want = ref_eye_summaries(nside, ptr, ind)
        _assert_same(eye_summaries(nside, ptr, ind), want)
        _assert_same(eye_summaries(nside, ptr, ind, name="lit_a"), want)
        _assert_same(eye_summaries(nside, ptr, ind.astype(np.int64)), want)
        # without the longitude bounds (cap_estimates): the rest the same, no bound
        got = eye_summaries(nside, ptr, ind, bounds=False)
        assert np.all(got.bounds == np.where(np.arange(got.bounds.shape[1]) % 2, 1.0, -1.0))
        _assert_same(dataclasses.replace(got, bounds=want.bounds), want)


@pytest.mark.parametrize("tables", [True, False])
def test_small_blocks_groups_and_the_path_without_tables(monkeypatch, tables):
    """The run finder's blocks and the groups of rows change no float, nor does an nside
    above the tables' limit (the per-run formulas)."""
    monkeypatch.setattr(lf, "_BLOCK", 37)
    monkeypatch.setattr(lf, "_ROWS", 5)
    monkeypatch.setattr(lf._Rings, "_cache", {})
    if not tables:
        monkeypatch.setattr(lf, "_TABLE_NPIX", 0)
    nside = 16
    ds = generate3d(120, Domain3D(nside=nside), seed=SEED + 1)
    ptr, ind = ds.indptr_a, ds.indices_a
    _assert_same(eye_summaries(nside, ptr, ind, name="lit_a"), ref_eye_summaries(nside, ptr, ind))
    assert (lf._Rings.of(nside).pixels() is not None) == tables


def _hand_made_rows(nside):
    """Rows that reach every branch: empty rows (first, inside, last), one index, a row
    that goes on where the previous one ended (its start splits a run), the whole eye,
    a cap over each pole (runs across ring boundaries), a run across one ring boundary,
    two runs on one ring across longitude 0, one whole ring, scattered indices."""
    npix = 12 * nside * nside
    k = np.arange(1, 4 * nside)
    first, num, _ = healpix.ring_info(nside, k)
    r = nside + 3  # an equatorial ring
    f, m = int(first[r - 1]), int(num[r - 1])
    rng = np.random.default_rng(5)
    q = npix // 3
    return [
        [],
        [7],
        [q, q + 1, q + 2],
        [q + 3, q + 4],  # goes on from the previous row
        [q + 5],
        [],
        list(range(npix)),
        list(range(0, 4 * nside + 9)),  # north cap: whole rings then part of the next
        list(range(npix - 30, npix)),  # south cap
        list(range(f - 3, f + 4)),  # across one ring boundary
        [f, f + 1, f + 2, f + m - 2, f + m - 1],  # across longitude 0 on one ring
        list(range(f, f + m)),  # one whole ring
        sorted(rng.choice(npix, 40, replace=False).tolist()),
        [npix - 1],
        [],
    ]


@pytest.mark.parametrize("nside", [2, 8, 64])
@pytest.mark.parametrize("dtype", [np.int32, np.int64])
def test_hand_made_rows_are_the_reference_floats(monkeypatch, nside, dtype):
    monkeypatch.setattr(lf, "_ROWS", 4)  # groups that start and end on empty rows
    ptr, ind = _csr(_hand_made_rows(nside), dtype)
    with np.errstate(all="ignore"):
        want = ref_eye_summaries(nside, ptr, ind)
    _assert_same(eye_summaries(nside, ptr, ind, name="lit_b"), want)
    # and an indptr that does not start at 0 (a slice of a larger CSR)
    _assert_same(eye_summaries(nside, ptr[3:], ind), _sub(nside, ptr[3:], ind))


def _sub(nside, ptr, ind):
    with np.errstate(all="ignore"):
        return ref_eye_summaries(nside, ptr, ind)


def test_many_short_runs_grow_the_run_arrays():
    """Every other pixel lit: a run per index, more than the run finder first allots."""
    nside = 64
    npix = 12 * nside * nside
    ptr, ind = _csr([np.arange(0, npix, 2), [5], np.arange(1, npix, 3)])
    _assert_same(eye_summaries(nside, ptr, ind, name="lit_a"), _sub(nside, ptr, ind))


def test_band_rings_are_the_per_run_comparison():
    """_band_rings' first ring of each band is where (theta_k - theta0) / alpha, as the
    reference evaluates it per run, first exceeds the band's edge, ties included."""
    rings = lf._Rings.of(16)
    th = rings.theta
    rng = np.random.default_rng(11)
    theta0 = np.r_[rng.uniform(0, math.pi, 500), th[5], th[40], np.nan]
    alpha = np.r_[rng.uniform(1e-3, 0.5, 500), (th[9] - th[5]) / 0.7, 0.01, 0.1]
    got = lf._band_rings(rings, theta0, alpha)
    with np.errstate(invalid="ignore"):
        v = (th[None, :] - theta0[:, None]) / alpha[:, None]
    for j, c in enumerate(BANDS):
        above = v > c
        want = np.where(above.any(axis=1), above.argmax(axis=1), th.size)
        np.testing.assert_array_equal(got[:, j], want)


def test_first_run_on_a_ring_is_a_search_within_each_row():
    """Rows with one run per ring (the guess), two runs on a ring, rings skipped (a run
    across rings) and empty rows, against a search row by row."""
    rng = np.random.default_rng(4)
    rows = []
    for i in range(300):
        k0 = int(rng.integers(1, 40))
        if i % 3 == 0:
            rings = np.arange(k0, k0 + rng.integers(0, 12))
        else:
            rings = np.sort(rng.integers(k0, k0 + 15, rng.integers(0, 12)))
        rows.append(rings)
    ks = np.concatenate(rows).astype(np.int64)
    lo = np.r_[0, np.cumsum([r.size for r in rows])[:-1]]
    hi = lo + [r.size for r in rows]
    k = rng.integers(0, 60, (len(rows), 3))
    got = lf._first_run_on(ks, lo, hi, k)
    for i, r in enumerate(rows):
        np.testing.assert_array_equal(got[i], lo[i] + np.searchsorted(r, k[i]))


def _reference_predict(est, ds):
    d = est.domain
    sa = ref_eye_summaries(d.nside, ds.indptr_a, ds.indices_a)
    sb = ref_eye_summaries(d.nside, ds.indptr_b, ds.indices_b)
    x, log_r0, az0, el0, ok, _ = features(sa, sb, d.h, d.nside, d.r_min, d.r_max)
    assert ok.all()
    out = est.network(x).astype(np.float64)
    return (
        np.exp(log_r0 + out[:, 0]),
        az0 + learned3d.AZ_SCALE * out[:, 1],
        el0 + learned3d.EL_SCALE * out[:, 2],
    )


@pytest.mark.slow
def test_shipped_predictions_are_the_reference_floats():
    """More rows than one batch of the network (16,384): predict's blocks of 32,768 rows
    still feed it the batches it had (the reference's network chunks them the same way),
    with one thread and with two."""
    est = learned3d.load()
    ds = generate3d(learned3d._BLOCK + 300, est.domain, seed=SEED + 2)
    want = _reference_predict(est, ds)
    for threads in (1, 2):
        est.threads = threads
        got = est.predict_dataset(ds)
        for g, w in zip(got, want, strict=True):
            assert np.max(np.abs(g - w)) == 0.0
        assert got.valid.all()


def test_network_batches_do_not_depend_on_predict_s_blocks(monkeypatch, shipped, rows):
    monkeypatch.setattr(learned3d, "_BLOCK", 2)
    lit_a, lit_b = rows  # 6 rows: batches of 2 rows
    est = learned3d.load()
    est.block_rows = 2
    one = est.predict(lit_a, lit_b)
    est.block_rows = 6
    for g, w in zip(est.predict(lit_a, lit_b), one, strict=True):
        assert np.array_equal(g, w)


# --- the indices' checks on the runs ---------------------------------------------------


def _message(f, *args):
    try:
        f(*args)
    except ValueError as exc:
        return str(exc)
    return None


@pytest.fixture(scope="module")
def shipped():
    return learned3d.load()


@pytest.fixture(scope="module")
def rows(shipped):
    ds = generate3d(6, shipped.domain, seed=SEED + 3)
    return (ds.indptr_a, ds.indices_a), (ds.indptr_b, ds.indices_b)


def test_every_single_corruption_is_refused_as_as_csr_refuses_it(shipped, rows):
    """One index changed at a time (to its predecessor, to its successor's value, past
    npix, below 0, swapped with its neighbour; at run starts, inside runs, at row starts
    and ends): predict refuses exactly when as_csr's own pass does, with its message."""
    (pa, ia), lit_b = rows
    npix = shipped.domain.npix
    starts = np.flatnonzero(np.diff(ia) != 1) + 1
    pos = np.unique(np.r_[pa[1:-1], pa[1:-1] - 1, starts[::7], starts[::7] - 1, 1, 5, 900])
    pos = pos[(pos > 0) & (pos < ia.size - 1)]
    n_refused = 0
    for j in pos:
        for kind in ("prev", "next", "npix", "neg", "swap"):
            bad = ia.copy()
            if kind == "prev":
                bad[j] = bad[j - 1]
            elif kind == "next":
                bad[j] = bad[j + 1]
            elif kind == "npix":
                bad[j] = npix + j % 3
            elif kind == "neg":
                bad[j] = -1 - j % 3
            else:
                bad[j], bad[j + 1] = bad[j + 1], bad[j]
            want = _message(lit_csr.as_csr, "lit_a", (pa, bad), npix)
            got = _message(shipped.predict, (pa, bad), lit_b)
            assert got == want, (j, kind)
            n_refused += want is not None
    assert n_refused > 3 * pos.size  # most corruptions are refused


@pytest.mark.parametrize("dtype", [np.int32, np.int64])
def test_a_run_that_wraps_past_the_dtype_is_refused(shipped, dtype):
    info = np.iinfo(dtype)
    lit_a = (np.array([0, 4]), np.array([info.max - 1, info.max, info.min, info.min + 1], dtype))
    lit_b = (np.array([0, 2]), np.array([5, 6]))
    want = _message(lit_csr.as_csr, "lit_a", lit_a, shipped.domain.npix)
    assert want is not None and f"got {info.min}" in want
    assert _message(shipped.predict, lit_a, lit_b) == want


def test_rows_not_handed_to_the_network_are_still_checked(shipped):
    """A row where the other eye lit nothing never reaches the summaries; predict checks
    its indices itself."""
    lit_a = (np.array([0, 2, 4]), np.array([9, 8, 5, 6]))  # row 0 falls
    lit_b = (np.array([0, 0, 2]), np.array([5, 6]))  # row 0 empty
    assert "lit_a: indices must increase strictly" in _message(shipped.predict, lit_a, lit_b)
    lit_b = (np.array([0, 2, 2]), np.array([5, 400_000]))
    lit_a = (np.array([0, 0, 2]), np.array([5, 6]))
    assert _message(shipped.predict, lit_a, lit_b) == (
        "lit_b: indices must lie in [0, npix = 388800), got 400000"
    )


def test_two_threads_give_the_same_floats_and_lit_a_s_error_first(monkeypatch, shipped, rows):
    monkeypatch.setattr(learned3d, "_THREAD_ROWS", 0)  # threads even for these few rows
    lit_a, lit_b = rows
    one = learned3d.load()
    one.threads = 1
    one = one.predict(lit_a, lit_b)
    two = learned3d.load()
    two.threads = 2
    names = []
    summaries = learned3d.eye_summaries

    def recorded(*args, **kw):
        names.append(threading.current_thread().name)
        return summaries(*args, **kw)

    monkeypatch.setattr(learned3d, "eye_summaries", recorded)
    got = two.predict(lit_a, lit_b)
    assert len(names) == 2 and any(n.startswith("eyeviz-learned3d") for n in names)
    for g, w in zip(got, one, strict=True):
        assert np.array_equal(g, w)
    pa, ia = lit_a
    pb, ib = lit_b
    bad_a = (pa, np.r_[ia[1], ia[1:]])  # the first row falls
    bad_b = (pb, np.r_[ib[:-1], shipped.domain.npix])
    assert "lit_a: indices must increase" in _message(two.predict, bad_a, bad_b)
    assert "lit_b: indices must lie" in _message(two.predict, lit_a, bad_b)


@pytest.mark.parametrize("n_empty", [1, 2, 3])
def test_empty_rows_between_consecutive_indices_are_not_refused(n_empty):
    """A row that goes on where an earlier one ended, with empty rows between them (their
    starts repeat): the check on the runs accepts it as as_csr does, and every row's
    summaries are those of the row alone."""
    nside = 4
    ptr = np.r_[0, [1] * (n_empty + 1), 3].astype(np.int64)  # [84], empty..., [85, 86]
    ind = np.array([84, 85, 86], np.int64)
    lit_csr.as_csr("lit_a", (ptr, ind), 12 * nside * nside)  # valid
    got = eye_summaries(nside, ptr, ind, name="lit_a")
    for row, want_ind in ((0, [84]), (ptr.size - 2, [85, 86])):
        want = eye_summaries(nside, np.array([0, len(want_ind)]), np.array(want_ind))
        for f in ("count", "sum_xyz", "lon_w", "lon_e", "z_top", "z_bottom", "bounds"):
            assert np.array_equal(getattr(got, f)[row], getattr(want, f)[0], equal_nan=True), f
    assert np.all(got.count[1 : 1 + n_empty] == 0)


@pytest.mark.parametrize("threads", [0, -1, 1.5, "2", None, True])
def test_threads_must_be_a_positive_integer(shipped, rows, threads):
    est = learned3d.load()
    est.threads = threads
    with pytest.raises(ValueError, match=r"^threads must be an integer >= 1, got ") as exc:
        est.predict(*rows)
    assert "\n" not in str(exc.value)


@pytest.mark.parametrize("block_rows", [0, -5, 1.5, "3", None])
def test_block_rows_must_be_a_positive_integer(shipped, rows, block_rows):
    """-5 used to give NaN for every row (an empty range of blocks), 0 a range() error."""
    est = learned3d.load()
    est.block_rows = block_rows
    with pytest.raises(ValueError, match=r"^block_rows must be an integer >= 1, got "):
        est.predict(*rows)
    est.block_rows = 1 << 62  # huge: one block
    assert np.isfinite(est.predict(*rows).r).all()


_DTYPES = [np.int64, np.int32, np.int16, np.int8, np.uint8, np.uint16, np.uint64, ">i4", ">i8"]


@settings(max_examples=400, deadline=None, derandomize=True, database=None)
@given(
    st.lists(st.lists(st.integers(-3, 12 * 4 * 4 + 3), max_size=8), min_size=1, max_size=6),
    st.sampled_from(_DTYPES),
    st.booleans(),
)
def test_the_check_on_the_runs_is_as_csr_s_on_any_rows(rows, dtype, tidy):
    """Random rows (empty ones among them; sorted and distinct, or as drawn) in any
    integer dtype: eye_summaries(name=...) refuses exactly when as_csr's own pass does,
    with its message."""
    nside, npix = 4, 12 * 4 * 4
    if tidy:
        rows = [sorted(set(r)) for r in rows]
    ptr = np.r_[0, np.cumsum([len(r) for r in rows])].astype(np.int64)
    with np.errstate(all="ignore"):
        ind = np.array([v for r in rows for v in r], np.int64).astype(dtype)
    want = _message(lit_csr.as_csr, "lit_a", (ptr, ind), npix)
    p, i, _ = lit_csr.as_csr("lit_a", (ptr, ind), npix, check_indices=False)
    assert _message(eye_summaries, nside, p, i, "lit_a") == want
