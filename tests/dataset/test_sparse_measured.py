"""The sparse data set of a measured pair: the same format as the HEALPix one, with the
pair embedded; a reader that rebuilds it, checks its fingerprint and re-computes a few
rows' lit sets; the sampler's rows in the pair's binocular field; and the format registry
that picks a file's reader by the kind of its eye design."""

from __future__ import annotations

import io
import json
import math
import zipfile
from pathlib import Path

import numpy as np
import pytest

from eyeviz import EyevizError
from eyeviz.core.domain import Domain3D
from eyeviz.dataset import embedded_eyes, kinds, sparse3d
from eyeviz.dataset.algorithm1_3d import generate3d, make_params3d
from eyeviz.dataset.records import spherical_to_xyz


@pytest.fixture(scope="module")
def toy_file(tmp_path_factory, toy_pair):
    path = tmp_path_factory.mktemp("measured") / "toy.npz"
    dom = Domain3D.for_eyes(toy_pair)
    sparse3d.write3d(path, 24, dom, seed=5)
    return path, dom


def _members(path: Path) -> dict[str, bytes]:
    with zipfile.ZipFile(path) as zf:
        return {i.filename: zf.read(i) for i in zf.infolist()}


def _npy(a: np.ndarray) -> bytes:
    buf = io.BytesIO()
    np.lib.format.write_array(buf, a, allow_pickle=False)
    return buf.getvalue()


def _load_member(raw: bytes) -> np.ndarray:
    return np.lib.format.read_array(io.BytesIO(raw), allow_pickle=False)


def _rewrite(src: Path, dst: Path, **replace: np.ndarray) -> Path:
    """A copy of ``src`` with members replaced (valid zip, valid CRCs)."""
    members = _members(src)
    with zipfile.ZipFile(dst, "w", zipfile.ZIP_STORED) as zf:
        for name, raw in members.items():
            key = name.removesuffix(".npy")
            zf.writestr(name, _npy(replace[key]) if key in replace else raw)
    return dst


def test_round_trip_embeds_the_pair_bit_for_bit(toy_file, toy_pair):
    path, dom = toy_file
    ds = sparse3d.load3d(path)
    assert ds.domain == dom and ds.domain.kind == "measured" and len(ds) == 24
    members = _members(path)
    meta = json.loads(str(_load_member(members["meta.npy"])[()]))
    assert meta["domain"]["eye"] == toy_pair.fingerprint and "nside" not in meta["domain"]
    assert (meta["domain"]["n_a"], meta["domain"]["n_b"]) == toy_pair.facet_counts
    for e, eye in (("a", toy_pair.eye_a), ("b", toy_pair.eye_b)):
        for what in ("positions", "axes", "acceptance"):
            arr = _load_member(members[f"eye_{e}_{what}.npy"])
            assert arr.dtype == np.dtype("<f8") and arr.ndim == 1
            assert np.array_equal(arr, getattr(eye, what).reshape(-1))
    rebuilt = ds.domain.eyes
    assert rebuilt is not toy_pair and rebuilt.fingerprint == toy_pair.fingerprint
    # every row: in the pair's field, lit sets as the pair computes them, indices per eye
    assert toy_pair.in_bfv(ds.x, ds.y, ds.z, ds.g).all()
    (pa, ia), (pb, ib) = toy_pair.lit_csr(ds.x, ds.y, ds.z, ds.g)
    assert np.array_equal(pa, ds.indptr_a) and np.array_equal(ia, ds.indices_a)
    assert np.array_equal(pb, ds.indptr_b) and np.array_equal(ib, ds.indices_b)
    assert (np.diff(pa) >= 2).all() and (np.diff(pb) >= 2).all()
    # r, azimuth, elevation about the lens centroids' midpoint, in eyeviz's axes
    o = np.asarray(dom.origin)
    x, y, z = spherical_to_xyz(ds.r, ds.azimuth, ds.elevation)
    assert np.allclose(np.c_[ds.x, ds.y, ds.z] - o, np.c_[x, y, z], atol=1e-12)
    assert (ds.r >= dom.r_min).all() and (ds.r <= dom.r_max).all()
    assert (ds.azimuth >= 0).all() and (ds.azimuth <= math.pi).all()
    wa, wb = ds.bitmaps(0, 3)
    assert (wa.shape, wb.shape) == ((3, toy_pair.facet_counts[0]), (3, toy_pair.facet_counts[1]))


def test_the_same_seed_gives_the_same_bytes(tmp_path, toy_pair):
    dom = Domain3D.for_eyes(toy_pair)
    a, b = tmp_path / "a.npz", tmp_path / "b.npz"
    sparse3d.write3d(a, 9, dom, seed=8)
    sparse3d.write3d(b, 9, dom, seed=8)
    assert a.read_bytes() == b.read_bytes()


def test_the_sampler_draws_r_and_g_apart_and_keeps_the_ranges(toy_pair):
    dom = Domain3D.for_eyes(toy_pair)
    ds = generate3d(400, dom, seed=2)
    assert abs(np.corrcoef(ds.r, ds.g)[0, 1]) < 0.9  # g is not a function of r
    assert (ds.g >= ds.r * math.sin(dom.gamma / 2) - 1e-12).all() and (ds.g <= dom.g_max).all()
    multi = generate3d(400, dom, mode="multi", seed=2)
    assert np.median(multi.r) > np.median(ds.r)  # density proportional to r^2
    with pytest.raises(EyevizError, match="no feature can be visible"):
        make_params3d(Domain3D.for_eyes(toy_pair, g_max=1e-6))


def test_reader_refuses_embedded_eyes_that_are_not_the_fingerprints(toy_file, tmp_path):
    path, _ = toy_file
    pos = _load_member(_members(path)["eye_a_positions.npy"]).copy()
    pos[0] += 1e-9
    bad = _rewrite(path, tmp_path / "moved.npz", eye_a_positions=pos)
    with pytest.raises(EyevizError) as info:
        sparse3d.Sparse3DReader(bad)
    text = str(info.value)
    assert "\n" not in text and "fingerprint" in text and "do not belong together" in text
    pos[0] = np.nan  # the model's own checks run before the fingerprint
    bad = _rewrite(path, tmp_path / "nan.npz", eye_a_positions=pos)
    with pytest.raises(EyevizError, match="eye A: ommatidium 0: lens position is not finite"):
        sparse3d.Sparse3DReader(bad)


def test_reader_refuses_embedded_eyes_of_the_wrong_size_or_missing(toy_file, tmp_path):
    path, _ = toy_file
    pos = _load_member(_members(path)["eye_b_acceptance.npy"])
    bad = _rewrite(path, tmp_path / "short.npz", eye_b_acceptance=pos[:-1])
    with pytest.raises(EyevizError, match="member 'eye_b_acceptance' has dtype float64 length"):
        sparse3d.Sparse3DReader(bad)
    members = _members(path)
    gone = tmp_path / "gone.npz"
    with zipfile.ZipFile(gone, "w") as zf:
        for name, raw in members.items():
            if name != "eye_a_axes.npy":
                zf.writestr(name, raw)
    with pytest.raises(EyevizError, match="member 'eye_a_axes' is missing"):
        sparse3d.Sparse3DReader(gone)


def test_reader_refuses_lit_sets_that_the_embedded_eyes_do_not_light(toy_file, tmp_path):
    """A lit set edited to another valid one (sorted, in range, same length) is caught by
    re-computing it from the embedded eyes."""
    path, _ = toy_file
    members = _members(path)
    ind = _load_member(members["indices_b.npy"]).copy()
    ptr = _load_member(members["indptr_b.npy"])
    n_b = int(json.loads(str(_load_member(members["meta.npy"])[()]))["domain"]["n_b"])
    last = slice(int(ptr[-2]), int(ptr[-1]))  # the last row: always among the checked
    unlit = np.setdiff1d(np.arange(n_b), ind[last])
    ind[int(ptr[-1]) - 1] = (
        unlit[-1] if unlit[-1] > ind[int(ptr[-1]) - 2] else ind[int(ptr[-1]) - 1]
    )
    assert not np.array_equal(ind, _load_member(members["indices_b.npy"]))
    bad = _rewrite(path, tmp_path / "lit.npz", indices_b=ind)
    with pytest.raises(EyevizError) as info:
        sparse3d.load3d(bad)
    text = str(info.value)
    assert "\n" not in text and "lit sets do not match the embedded eyes: row 24: eye B" in text


def test_reader_checks_the_centre_about_the_origin(toy_file, tmp_path):
    path, dom = toy_file
    x = _load_member(_members(path)["x.npy"]).copy()
    x[3] -= dom.origin[0] + 1e-6  # as if measured from (0, 0, 0): off by a micrometre
    bad = _rewrite(path, tmp_path / "x.npz", x=x)
    with pytest.raises(EyevizError, match="row 4: .* the centre of r, azimuth, elevation about"):
        sparse3d.load3d(bad)


# --- the format registry -------------------------------------------------------------


def test_kind_of_reads_the_design_from_the_meta(toy_file, tmp_path):
    from eyeviz import dataset as planar_io

    path, _ = toy_file
    assert kinds.kind_of(path) == "measured"
    heal = tmp_path / "h.npz"
    sparse3d.write3d(heal, 3, Domain3D(nside=4, r_min=100, r_max=400, g_max=60), seed=1)
    assert kinds.kind_of(heal) == "spherical"
    planar = tmp_path / "p.npz"
    planar_io.write(planar, 5, seed=1)
    csv = tmp_path / "p.csv"
    planar_io.write(csv, 5, seed=1)
    assert kinds.kind_of(planar) == kinds.kind_of(csv) == "planar"
    junk = tmp_path / "junk.npz"
    junk.write_bytes(b"not a zip")
    assert kinds.kind_of(junk) == "planar"  # the planar reader says what is wrong
    assert isinstance(kinds.open_reader(path), sparse3d.Sparse3DReader)
    assert isinstance(kinds.open_reader(heal), sparse3d.Sparse3DReader)
    assert kinds.open_reader(planar).eyes.m == 720
    with pytest.raises(
        EyevizError,
        match=r"no data set format for eyes of kind 'cubic' "
        r"\(known kinds: measured, planar, spherical\)$",
    ):
        kinds.open_reader(path, kind="cubic")
    with pytest.raises(ValueError, match="module:callable"):
        kinds.register_reader("cubic", "nowhere")


def test_embedded_eye_members_are_the_documented_ones(toy_pair):
    arrays = embedded_eyes.eye_arrays(toy_pair)
    assert tuple(arrays) == embedded_eyes.EYE_MEMBERS
    n_a, n_b = toy_pair.facet_counts
    assert {k: v.size for k, v in arrays.items()} == embedded_eyes.expected_lengths(n_a, n_b)
    back = embedded_eyes.pair_from_arrays(arrays, toy_pair.fingerprint)
    assert back.fingerprint == toy_pair.fingerprint


def test_each_eyes_indices_range_over_its_own_facet_count(tmp_path, toy_pair):
    """Eyes of different sizes: eye B's indices stop at n_B, eye A's at n_A, in the
    sampler, the file, the reader's bounds and the estimator's."""
    from eyeviz.core.measured import MeasuredEye, MeasuredEyePair
    from eyeviz.estimators import registry

    b = toy_pair.eye_b
    keep = slice(0, b.n - 40)
    small_b = MeasuredEye(b.positions[keep], b.axes[keep], b.acceptance[keep], name="B")
    pair = MeasuredEyePair(toy_pair.eye_a, small_b)
    n_a, n_b = pair.facet_counts
    assert n_b == n_a - 40
    dom = Domain3D.for_eyes(pair)
    path = tmp_path / "uneven.npz"
    sparse3d.write3d(path, 30, dom, seed=3)
    ds = sparse3d.load3d(path)
    assert ds.domain.facet_counts == (n_a, n_b) and ds.indices_b.max() < n_b
    wa, wb = ds.bitmaps(0, 2)
    assert wa.shape == (2, n_a) and wb.shape == (2, n_b)
    est = registry.load("analytic3d", domain=ds.domain)
    assert est.predict_dataset(ds).valid.all()
    with pytest.raises(ValueError, match=f"lit_b: indices must lie in \\[0, npix = {n_b}\\)"):
        est.predict((np.array([0, 1]), np.array([n_b])), (np.array([0, 1]), np.array([n_b])))
    # an index valid in eye A but past eye B's last facet: refused in the file, naming it
    members = _members(path)
    ind = _load_member(members["indices_b.npy"]).copy()
    ptr = _load_member(members["indptr_b.npy"])
    ind[int(ptr[1]) - 1] = n_b  # row 1's last index
    bad = _rewrite(path, tmp_path / "past.npz", indices_b=ind)
    with pytest.raises(EyevizError, match=f"indices_b: row 1: index {n_b} outside \\[0, {n_b}\\)"):
        sparse3d.load3d(bad)


def test_interrupted_writing_leaves_nothing_and_the_space_estimate_covers_it(tmp_path, toy_pair):
    dom = Domain3D.for_eyes(toy_pair)

    def stop(k):
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        sparse3d.write3d(tmp_path / "d.npz", 20, dom, progress=stop)
    assert list(tmp_path.iterdir()) == []
    out = tmp_path / "e.npz"
    sparse3d.write3d(out, 200, dom, seed=1)
    need = 2 * out.stat().st_size  # spools and zip side by side
    assert need <= sparse3d.estimated_bytes3d(200, dom) <= 6 * need
