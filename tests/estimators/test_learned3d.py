"""The learned 3D estimator: lit-set summaries, the shipped weights, the weights file's
checks, the design check, and fit (issue 23)."""

import json
import math
import zipfile
from pathlib import Path

import numpy as np
import pytest

from eyeviz import EyevizError
from eyeviz.core import healpix
from eyeviz.core.domain import Domain, Domain3D
from eyeviz.dataset.algorithm1_3d import generate3d
from eyeviz.estimators import learned3d, metrics
from eyeviz.estimators.learned3d_features import (
    N_FEATURES,
    eye_summaries,
    features,
)

SHIPPED = Path(learned3d.default_dir())
TEST_SEED = 9_023_001  # neither the shipped training nor its validation seed
SMALL = Domain3D(nside=16)


def _brute(nside, indptr, indices):
    """Per row: count, sum of centres, west/east cell-edge longitudes, z of first/last."""
    c = healpix.centers(nside, indices.astype(np.int64))
    _, _, num, _ = healpix.pix2ring(nside, indices.astype(np.int64))
    lon = np.arctan2(c[:, 1], c[:, 0]) % (2 * math.pi)
    half = math.pi / num
    rows = []
    for i in range(indptr.size - 1):
        s = slice(indptr[i], indptr[i + 1])
        rows.append(
            (
                indptr[i + 1] - indptr[i],
                c[s].sum(axis=0),
                (lon[s] - half[s]).min(),
                (lon[s] + half[s]).max(),
                c[s][0, 2],
                c[s][-1, 2],
            )
        )
    return rows


@pytest.mark.parametrize("nside", [16, 180])
def test_summaries_match_a_facet_by_facet_sum(nside):
    ds = generate3d(40, Domain3D(nside=nside), seed=TEST_SEED)
    s = eye_summaries(nside, ds.indptr_a, ds.indices_a)
    for i, (cnt, tot, w, e, zt, zb) in enumerate(_brute(nside, ds.indptr_a, ds.indices_a)):
        assert s.count[i] == cnt
        np.testing.assert_allclose(s.sum_xyz[i], tot, rtol=0, atol=1e-9 * cnt)
        assert s.lon_w[i] == pytest.approx(w, abs=1e-12)
        assert s.lon_e[i] == pytest.approx(e, abs=1e-12)
        assert (s.z_top[i], s.z_bottom[i]) == pytest.approx((zt, zb), abs=1e-12)
    assert np.isfinite(s.bounds).all() and (np.abs(s.bounds) <= 1).all()


def test_runs_across_rings_and_empty_rows():
    """A cap over the north pole lights whole rings: runs that cross ring boundaries are
    summed as tail + whole rings + head; an empty row has count 0 and NaN extents."""
    nside = 8
    rows = [np.arange(0, 60), np.array([], np.int64), np.array([3, 4, 5, 7, 100, 101])]
    indptr = np.r_[0, np.cumsum([r.size for r in rows])]
    indices = np.concatenate(rows).astype(np.int32)
    s = eye_summaries(nside, indptr, indices)
    full = [0, 2]
    want = _brute(nside, indptr[[0, 1]], indices[: indptr[1]]) + _brute(
        nside, np.array([0, 6]), indices[indptr[2] :]
    )
    for i, (cnt, tot, _, _, zt, zb) in zip(full, want, strict=True):
        assert s.count[i] == cnt
        np.testing.assert_allclose(s.sum_xyz[i], tot, atol=1e-10)
        assert (s.z_top[i], s.z_bottom[i]) == pytest.approx((zt, zb), abs=1e-12)
    assert s.count[1] == 0 and np.isnan(s.lon_w[1]) and not s.sum_xyz[1].any()


def test_features_shape_and_the_triangulation_they_start_from():
    ds = generate3d(200, Domain3D(), seed=TEST_SEED + 1)
    d = ds.domain
    sa = eye_summaries(d.nside, ds.indptr_a, ds.indices_a)
    sb = eye_summaries(d.nside, ds.indptr_b, ds.indices_b)
    x, log_r0, az0, el0, valid, flagged = features(sa, sb, d.h, d.nside, d.r_min, d.r_max)
    assert x.shape == (200, N_FEATURES) and x.dtype == np.float32
    assert valid.all() and not flagged.any() and np.isfinite(x).all()
    # the triangulation of the mean directions is already close (< 5 % DD, < 0.1 degree)
    assert metrics.mape(ds.r, np.exp(log_r0)) < 5
    assert np.degrees(np.abs(az0 - ds.azimuth)).max() < 0.2
    assert np.degrees(np.abs(el0 - ds.elevation)).max() < 0.2


# --- the shipped weights -------------------------------------------------------------


@pytest.fixture(scope="module")
def shipped():
    return learned3d.load()


@pytest.fixture(scope="module")
def fresh():
    return generate3d(1500, Domain3D(), seed=TEST_SEED)


def test_shipped_files_are_small_and_record_their_seeds():
    meta = json.loads((SHIPPED / learned3d.META_FILE).read_text())
    assert (SHIPPED / learned3d.WEIGHTS_FILE).stat().st_size < 200_000
    data = meta["data"]
    assert isinstance(data["train_seed"], int) and data["val_seed"] == data["train_seed"] + 1
    assert TEST_SEED not in (data["train_seed"], data["val_seed"])
    assert Domain3D.from_dict(data) == Domain3D()
    assert meta["train_seconds"] <= 600


def test_shipped_weights_predict_well_on_fresh_data(shipped, fresh):
    p = shipped.predict((fresh.indptr_a, fresh.indices_a), (fresh.indptr_b, fresh.indices_b))
    assert p.valid.all() and p.in_domain.all() and not p.flagged.any()
    r, az, el = p
    assert np.isfinite(r).all() and np.isfinite(az).all() and np.isfinite(el).all()
    dd = metrics.mape(fresh.r, r)
    assert dd < 2.0  # loose: the shipped weights measure about 1 %
    assert metrics.mape(fresh.azimuth, az) < 0.03
    assert np.degrees(np.mean(np.abs(el - fresh.elevation))) < 0.03
    # better than the triangulation it corrects
    d = shipped.domain
    sa = eye_summaries(d.nside, fresh.indptr_a, fresh.indices_a)
    sb = eye_summaries(d.nside, fresh.indptr_b, fresh.indices_b)
    _, log_r0, _, _, _, _ = features(sa, sb, d.h, d.nside, d.r_min, d.r_max)
    assert dd < metrics.mape(fresh.r, np.exp(log_r0)) - 0.2


def test_bitmaps_csr_single_row_and_empty_eye(shipped, fresh):
    k = 3
    csr = shipped.predict(
        (fresh.indptr_a[: k + 1], fresh.indices_a[: fresh.indptr_a[k]]),
        (fresh.indptr_b[: k + 1], fresh.indices_b[: fresh.indptr_b[k]]),
    )
    a, b = fresh.bitmaps(0, k)
    dense = shipped.predict(a, b)
    np.testing.assert_allclose(dense.r, csr.r, rtol=1e-12)
    np.testing.assert_allclose(dense.elevation, csr.elevation, rtol=0, atol=1e-12)
    one = shipped.predict(a[1], b[1])
    # float32 products may round differently for another batch size (the check battery's
    # tolerance: rtol 1e-6 on r)
    assert np.ndim(one.r) == 0 and one.r == pytest.approx(csr.r[1], rel=1e-6)
    a[2] = False
    p = shipped.predict(a, b)
    assert not p.valid[2] and np.isnan(p.r[2]) and p.valid[[0, 1]].all()


@pytest.mark.parametrize(
    ("lit_a", "match"),
    [
        ((np.array([0, 2]), np.array([5, 3])), "increase strictly"),
        ((np.array([0, 1]), np.array([12 * 180 * 180])), r"\[0, npix"),
        ((np.array([1, 2]), np.array([5, 6])), "indptr must start at 0"),
        ((np.array([0, 1, 2]), np.array([5, 6])), "different row counts"),
        (np.zeros((1, 100), bool), "npix = 388800"),
        (np.full((1, 388_800), 2), "0/1"),
    ],
)
def test_bad_input_is_refused_in_one_line(shipped, lit_a, match):
    lit_b = (np.array([0, 2]), np.array([5, 6]))
    with pytest.raises(ValueError, match=match) as exc:
        shipped.predict(lit_a, lit_b)
    assert "\n" not in str(exc.value)


# --- design checks --------------------------------------------------------------------


@pytest.mark.parametrize(
    ("domain", "match"),
    [
        (Domain3D(nside=64), "nside=180; the domain has .*nside=64"),
        (Domain3D(h=80.0), "h=40"),
        (Domain3D(r_max=8000.0), "r_max=5000"),
        (Domain3D(el_max=1.2), "el_max"),
        (Domain(), "must be a Domain3D"),
    ],
)
def test_design_mismatch_is_refused(domain, match):
    with pytest.raises(EyevizError, match=match) as exc:
        learned3d.load(domain=domain)
    assert "\n" not in str(exc.value)


def test_a_narrower_range_of_the_same_design_is_accepted():
    est = learned3d.load(domain=Domain3D(r_min=2000.0, r_max=4000.0, g_max=300.0))
    assert est.domain.r_max == 4000.0


# --- the weights file ------------------------------------------------------------------


def _copy(tmp_path: Path) -> Path:
    d = tmp_path / "m"
    d.mkdir(parents=True)
    for f in (learned3d.WEIGHTS_FILE, learned3d.META_FILE):
        (d / f).write_bytes((SHIPPED / f).read_bytes())
    return d


def _arrays():
    hidden, arrays = learned3d.read_weights(SHIPPED / learned3d.WEIGHTS_FILE)
    return hidden, arrays


def _rewrite(d: Path, **members):
    hidden, arrays = _arrays()
    out = {"hidden": np.array(hidden, np.int64), **arrays}
    for k, v in members.items():
        if v is None:
            out.pop(k)
        else:
            out[k] = v
    with open(d / learned3d.WEIGHTS_FILE, "wb") as f:
        np.savez(f, **out)


def test_shipped_weights_load_from_a_copy(tmp_path):
    d = _copy(tmp_path)
    est = learned3d.load(d)
    assert est.n_weights == learned3d.load().n_weights > 0


@pytest.mark.parametrize(
    ("change", "match"),
    [
        ({"hidden": np.array(5000, np.int64)}, "hidden width"),
        ({"hidden": np.array(7, np.int64)}, "net.0.weight.* (declares|has shape)"),
        ({"net.2.weight": np.zeros((3, 3), np.float32)}, "net.2.weight"),
        ({"net.0.bias": None}, "member 'net.0.bias' is missing"),
        ({"extra": np.zeros(3, np.float32)}, "unexpected members"),
        ({"net.4.bias": np.array([np.nan, 0, 0], np.float32)}, "NaN"),
        ({"x_scale": np.zeros(N_FEATURES, np.float32)}, "x_scale must be > 0"),
        ({"net.4.bias": np.zeros(3, np.float64)}, "dtype float64"),
        ({"net.4.bias": np.array([object(), 1, 2], object)}, "not a plain array"),
    ],
)
def test_bad_weights_files_are_refused_in_one_line(tmp_path, change, match):
    d = _copy(tmp_path)
    _rewrite(d, **change)
    with pytest.raises(EyevizError, match=match) as exc:
        learned3d.load(d)
    assert "\n" not in str(exc.value)


def test_damaged_weights_and_metadata_are_refused(tmp_path):
    d = _copy(tmp_path)
    w = d / learned3d.WEIGHTS_FILE
    raw = bytearray(w.read_bytes())
    with zipfile.ZipFile(w) as zf:
        info = zf.getinfo("net.2.weight.npy")
    raw[info.header_offset + 200] ^= 0xFF  # inside the member's data: CRC mismatch
    w.write_bytes(bytes(raw))
    with pytest.raises(EyevizError, match="damaged|not a readable") as exc:
        learned3d.load(d)
    assert "\n" not in str(exc.value)
    w.write_bytes(b"not a zip")
    with pytest.raises(EyevizError, match="not a readable .npz"):
        learned3d.load(d)
    d2 = _copy(tmp_path / "x")
    m = d2 / learned3d.META_FILE
    m.write_text("[1, 2]")
    with pytest.raises(EyevizError, match="expected a JSON object"):
        learned3d.load(d2)
    m.write_text(json.dumps({"format": "eyeviz.learned3d", "version": 99}))
    with pytest.raises(EyevizError, match="version 99"):
        learned3d.load(d2)
    with pytest.raises(EyevizError, match="weights not found"):
        learned3d.load(tmp_path / "nowhere")


# --- training -----------------------------------------------------------------------------


def test_fit_writes_weights_that_load_and_records_the_seeds(tmp_path):
    from eyeviz.estimators.learned3d_training import fit

    out = fit(None, tmp_path / "m", domain=SMALL, n=2048, n_val=256, seed=5, epochs=2, hidden=8)
    est = learned3d.load(out)
    meta = est.metadata
    assert meta["data"]["train_seed"] == 5 and meta["data"]["val_seed"] == 6
    assert est.domain == SMALL and est.hidden == 8
    ds = generate3d(50, SMALL, seed=TEST_SEED)
    p = est.predict((ds.indptr_a, ds.indices_a), (ds.indptr_b, ds.indices_b))
    assert p.valid.all() and np.isfinite(p.r).all()
    # nside 16 is coarse (its triangulation alone is about 30 % off); a loose bound
    assert metrics.mape(ds.r, p.r) < 60
    with pytest.raises(EyevizError, match="nside=16"):
        learned3d.load(out, domain=Domain3D())


def test_fit_on_a_given_data_set_and_from_a_planar_domain(tmp_path):
    from eyeviz.estimators.learned3d_training import fit

    ds = generate3d(1500, SMALL, seed=TEST_SEED + 2)
    out = fit(ds, tmp_path / "m", domain=SMALL, seed=3, epochs=1, hidden=4)
    meta = learned3d.load(out).metadata
    assert meta["data"]["train_seed"] == TEST_SEED + 2 and meta["data"]["n_train"] == 1350
    with pytest.raises(EyevizError, match="data design"):
        fit(ds, tmp_path / "n", domain=Domain3D(nside=18), epochs=1, hidden=4)
    # a sparse 3D data set file (eyeviz generate --nside), read block by block
    from eyeviz.dataset.sparse3d import write3d

    f = tmp_path / "d.npz"
    write3d(f, 1500, SMALL, seed=TEST_SEED + 3)
    meta = learned3d.load(fit(str(f), tmp_path / "f", domain=SMALL, epochs=1, hidden=4)).metadata
    assert meta["data"]["train_seed"] == TEST_SEED + 3 and meta["data"]["n_val"] == 150
    with pytest.raises(EyevizError, match="multiple of 4"):
        fit(None, tmp_path / "p", domain=Domain(m=722), n=2048)
    with pytest.raises(EyevizError, match="hidden"):
        fit(None, tmp_path / "q", domain=SMALL, hidden=0)


# --- the registry ---------------------------------------------------------------------


def test_registry_loads_the_shipped_weights_and_refuses_a_planar_domain():
    from eyeviz.estimators import registry

    assert "learned3d" in registry.available("spherical")
    assert "learned3d" not in registry.available()  # planar lists stay planar
    est = registry.load("learned3d", domain=Domain3D())
    assert isinstance(est, learned3d.Learned3DEstimator) and est.n_weights > 0
    with pytest.raises(EyevizError, match="Domain3D"):
        registry.load("learned3d", domain=Domain())


def test_registry_fit_takes_what_eyeviz_train_passes(tmp_path):
    """eyeviz train hands fit a planar Domain (--h ... --g-max) and the entry's options."""
    from eyeviz.estimators import registry

    entry = registry.get("learned3d")
    dests = {o.dest for o in entry.fit_options}
    assert {"n", "n_val", "epochs", "hidden", "patience", "seed", "nside", "el_max"} <= dests
    out = registry.fit(
        "learned3d",
        None,
        tmp_path / "m",
        domain=Domain(g_max=400.0),
        nside=16,
        el_max=20.0,
        n=2048,
        n_val=256,
        epochs=1,
        hidden=4,
        seed=11,
        threads=1,
        command="eyeviz train learned3d --nside 16",
    )
    est = registry.load("learned3d", path=out)
    assert est.domain == Domain3D(nside=16, g_max=400.0, el_max=math.radians(20.0))
    assert est.metadata["command"] == "eyeviz train learned3d --nside 16"
