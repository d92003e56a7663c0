"""The sparse 3D data set file: round trip, streamed and atomic writing, and a reader that
refuses every kind of damaged or hostile file with one line naming the member or row.

The rows here are made by hand (sorted random facet lists, centres in the ranges), so
the file format is tested apart from the sampler (tests/dataset/test_algorithm1_3d.py).
"""

from __future__ import annotations

import json
import math
import os
import pickle
import tracemalloc
import zipfile
from pathlib import Path

import numpy as np
import pytest

from eyeviz import EyevizError
from eyeviz.core.domain import Domain3D
from eyeviz.dataset import embedded_eyes, sparse3d
from eyeviz.dataset.records import Dataset3D, index_dtype, spherical_to_xyz

DOM = Domain3D(h=30, l=10, nside=4, r_min=100, r_max=400, g_max=60, el_max=0.4)
PARAMS = {"mode": "single", "seed": 3, "segments": None}
FIELDS = ("indptr_a", "indices_a", "indptr_b", "indices_b", *sparse3d.FLOATS)


def rows(n: int, seed: int = 0, dom: Domain3D = DOM) -> Dataset3D:
    """n hand-made valid rows (some with empty or whole-eye lit lists)."""
    rng = np.random.default_rng(seed)
    npix = dom.npix
    csr = []
    for _ in range(2):
        lens = rng.integers(0, 30, n)
        lens[:: max(1, n // 3)] = 0
        if n > 5:
            lens[5] = npix
        ptr = np.zeros(n + 1, np.int64)
        np.cumsum(lens, out=ptr[1:])
        ind = np.concatenate(
            [np.sort(rng.choice(npix, k, replace=False)) for k in lens] or [np.zeros(0)]
        ).astype(index_dtype(npix))
        csr.append((ptr, ind))
    r = rng.uniform(dom.r_min, dom.r_max, n)
    az = rng.uniform(0, math.pi, n)
    el = rng.uniform(-dom.el_max, dom.el_max, n)
    g = rng.uniform(1, dom.g_max, n)
    x, y, z = spherical_to_xyz(r, az, el)
    (pa, ia), (pb, ib) = csr
    return Dataset3D(pa, ia, pb, ib, r, az, el, g, x, y, z, dom, dict(PARAMS))


@pytest.fixture(autouse=True)
def _format_only(monkeypatch):
    """The rows here are hand-made lists, not the lit sets of their balls: the reader's
    re-computation of a few rows (tests/dataset/test_sparse3d_design_check.py) is off."""
    monkeypatch.setattr(embedded_eyes, "LIT_CHECK_ROWS", 0)


def chunks(ds: Dataset3D, size: int) -> list[Dataset3D]:
    out = []
    for s in range(0, len(ds), size):
        e = min(s + size, len(ds))
        part = {}
        for eye in ("a", "b"):
            ptr = getattr(ds, f"indptr_{eye}")
            ind = getattr(ds, f"indices_{eye}")
            part[f"indptr_{eye}"] = ptr[s : e + 1] - ptr[s]
            part[f"indices_{eye}"] = ind[ptr[s] : ptr[e]]
        floats = {k: getattr(ds, k)[s:e] for k in sparse3d.FLOATS}
        out.append(Dataset3D(**part, **floats, domain=ds.domain, params=ds.params))
    return out


def write(path: Path, ds: Dataset3D, size: int = 7) -> None:
    sparse3d.write_chunks3d(path, len(ds), ds.domain, PARAMS, chunks(ds, size))


def same(a: Dataset3D, b: Dataset3D) -> None:
    for k in FIELDS:
        x, y = getattr(a, k), getattr(b, k)
        assert x.dtype == y.dtype and np.array_equal(x, y), k
    assert a.domain == b.domain


@pytest.fixture
def small(tmp_path):
    ds = rows(40)
    path = tmp_path / "d.npz"
    write(path, ds)
    return path, ds


# --- round trip ------------------------------------------------------------------------


def test_round_trip_whole_and_in_blocks(small):
    path, ds = small
    back = sparse3d.load3d(path)
    same(back, ds)
    assert back.params == PARAMS and back.domain == DOM
    for block_rows, block_lit in ((1, 10**6), (3, 10**6), (40, 50), (1000, 1)):
        reader = sparse3d.Sparse3DReader(path, block_rows=block_rows, block_lit=block_lit)
        blocks = list(reader)
        assert all(len(b) <= block_rows for b in blocks)
        assert all(len(b) == 1 or b.indptr_a[-1] <= block_lit for b in blocks)
        same(Dataset3D.concat(blocks), ds)


def test_plain_numpy_reads_it_without_pickles(small):
    path, ds = small
    with np.load(path, allow_pickle=False) as z:
        assert sorted(z.files) == sorted(["meta", *FIELDS])
        for k in FIELDS:
            assert np.array_equal(z[k], getattr(ds, k))
        meta = json.loads(str(z["meta"]))
    assert meta["format"] == sparse3d.FORMAT and meta["version"] == sparse3d.VERSION
    assert meta["n"] == 40 and meta["nnz_a"] == int(ds.indptr_a[-1])
    assert Domain3D.from_dict(meta["domain"]) == DOM and meta["params"] == PARAMS
    assert meta["index_dtype"] == "int32"


def test_chunking_does_not_change_the_bytes(tmp_path):
    ds = rows(30)
    write(tmp_path / "a.npz", ds, size=1)
    write(tmp_path / "b.npz", ds, size=30)
    assert (tmp_path / "a.npz").read_bytes() == (tmp_path / "b.npz").read_bytes()


def test_dense_bitmaps_match_the_lists(small):
    _, ds = small
    oa, ob = ds.bitmaps(3, 9)
    for i in range(3, 9):
        la, lb = ds.lit(i)
        assert np.array_equal(np.flatnonzero(oa[i - 3]), la)
        assert np.array_equal(np.flatnonzero(ob[i - 3]), lb)


def test_only_npz_outputs(tmp_path):
    for name in ("d.csv", "d", "d.npy"):
        with pytest.raises(EyevizError, match=r"written as \.npz") as info:
            sparse3d.write3d(tmp_path / name, 5, DOM)
        assert "\n" not in str(info.value)
    assert list(tmp_path.iterdir()) == []


# --- atomic and bounded ---------------------------------------------------------------


def test_interruption_leaves_no_file_and_keeps_an_old_one(tmp_path):
    ds = rows(40)
    out = tmp_path / "d.npz"

    def interrupted():
        yield from chunks(ds, 10)[:2]
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        sparse3d.write_chunks3d(out, 40, DOM, PARAMS, interrupted())
    assert list(tmp_path.iterdir()) == []  # neither the zip nor a spool is left

    out.write_bytes(b"precious")

    def stop(k):
        raise OSError("No space left on device")

    with pytest.raises(OSError):
        sparse3d.write_chunks3d(out, 40, DOM, PARAMS, chunks(ds, 10), progress=stop)
    assert [p.name for p in tmp_path.iterdir()] == ["d.npz"]
    assert out.read_bytes() == b"precious"


def test_a_generator_giving_too_few_rows_keeps_nothing(tmp_path):
    with pytest.raises(EyevizError, match="gave 10 rows, not n=40"):
        sparse3d.write_chunks3d(tmp_path / "d.npz", 40, DOM, PARAMS, chunks(rows(10), 5))
    assert list(tmp_path.iterdir()) == []


def _peak(fn) -> int:
    tracemalloc.start()
    try:
        fn()
        return tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()


def test_writer_and_reader_memory_is_flat_in_n(tmp_path):
    part = rows(200, seed=5)

    def many(k):
        return (part for _ in range(k))

    def write_k(k):
        return lambda: sparse3d.write_chunks3d(tmp_path / f"{k}.npz", 200 * k, DOM, PARAMS, many(k))

    small_w, big_w = _peak(write_k(2)), _peak(write_k(40))
    assert big_w < 2 * small_w + 200_000, (small_w, big_w)

    def read(k):
        return lambda: sum(
            len(b) for b in sparse3d.Sparse3DReader(tmp_path / f"{k}.npz", block_rows=200)
        )

    small_r, big_r = _peak(read(2)), _peak(read(40))
    assert big_r < 2 * small_r + 200_000, (small_r, big_r)


# --- the reader refuses damaged and hostile files ---------------------------------------


def _members(ds: Dataset3D, meta: dict | None = None) -> dict[str, np.ndarray]:
    base = {
        "format": sparse3d.FORMAT,
        "version": sparse3d.VERSION,
        "n": len(ds),
        "nnz_a": int(ds.indptr_a[-1]),
        "nnz_b": int(ds.indptr_b[-1]),
        "index_dtype": "int32",
        "domain": ds.domain.to_dict(),
        "params": PARAMS,
    }
    out = {"meta": np.array(json.dumps({**base, **(meta or {})}))}
    out.update({k: getattr(ds, k).copy() for k in FIELDS})
    return out


def _zip(path: Path, members: dict, compress=zipfile.ZIP_STORED, pickles: bool = False):
    with zipfile.ZipFile(path, "w", compress) as zf:
        for name, arr in members.items():
            with zf.open(name + ".npy", "w") as f:
                np.lib.format.write_array(f, np.asanyarray(arr), allow_pickle=pickles)


def _refused(path: Path, *words: str) -> str:
    with pytest.raises(EyevizError) as info:
        sparse3d.load3d(path)
    text = str(info.value)
    assert "\n" not in text and str(path) in text, text
    for w in words:
        assert w in text, text
    return text


def _mutated(tmp_path: Path, how, meta: dict | None = None) -> Path:
    m = _members(rows(20, seed=2), meta)
    how(m)
    path = tmp_path / "bad.npz"
    _zip(path, m)
    return path


def test_the_hand_built_zip_is_valid(tmp_path):
    assert len(sparse3d.load3d(_mutated(tmp_path, lambda m: None))) == 20


@pytest.mark.parametrize("version", [(1, 0), (2, 0), (3, 0)])
def test_every_npy_header_version_numpy_writes_is_read(tmp_path, version):
    """numpy writes .npy headers 1.0, 2.0 (headers over 64 KiB) and 3.0 (utf-8 names);
    a file whose members use any of them reads back the same rows."""
    ds = rows(20, seed=2)
    path = tmp_path / "v.npz"
    with zipfile.ZipFile(path, "w", zipfile.ZIP_STORED) as zf:
        for name, arr in _members(ds).items():
            with zf.open(name + ".npy", "w") as f:
                np.lib.format.write_array(f, np.asanyarray(arr), version=version)
    same(sparse3d.load3d(path), ds)


def test_truncated_and_garbage_files(small, tmp_path):
    path, _ = small
    data = path.read_bytes()
    for cut in (10, len(data) // 2, len(data) - 30):
        bad = tmp_path / "cut.npz"
        bad.write_bytes(data[:cut])
        _refused(bad)
    bad.write_bytes(b"not a zip at all")
    _refused(bad, "not a readable .npz")


class _Boom:
    """Unpickling this would write a file: the reader must never unpickle."""

    def __reduce__(self):
        return (Path.touch, (Path(os.environ["EYEVIZ_PWNED"]),))


def test_pickled_object_member_is_never_unpickled(tmp_path, monkeypatch):
    flag = tmp_path / "pwned"
    monkeypatch.setenv("EYEVIZ_PWNED", str(flag))
    m = _members(rows(20, seed=2))
    m["indices_a"] = np.array([_Boom()] * int(m["indptr_a"][-1]), dtype=object)
    path = tmp_path / "pickled.npz"
    _zip(path, m, pickles=True)
    assert pickle.dumps(_Boom())  # the payload is real
    _refused(path, "indices_a", "not a plain array")
    assert not flag.exists()


def test_object_meta_is_refused(tmp_path):
    m = _members(rows(20))
    m["meta"] = np.array([{"n": 20}], dtype=object)
    path = tmp_path / "meta.npz"
    _zip(path, m, pickles=True)
    _refused(path)


def _dec_ptr(m):
    m["indptr_a"][4], m["indptr_a"][5] = m["indptr_a"][5], m["indptr_a"][4]


def _unsort(m):
    p = m["indptr_b"]
    i = int(np.flatnonzero(np.diff(p) >= 2)[0])
    a = int(p[i])
    m["indices_b"][a], m["indices_b"][a + 1] = m["indices_b"][a + 1], m["indices_b"][a]


def _dup(m):
    p = m["indptr_b"]
    i = int(np.flatnonzero(np.diff(p) >= 2)[0])
    m["indices_b"][int(p[i]) + 1] = m["indices_b"][int(p[i])]


@pytest.mark.parametrize(
    "how, words",
    [
        (_dec_ptr, ("indptr_a", "row 5", "must not decrease")),
        (lambda m: m["indptr_b"].__setitem__(0, 1), ("indptr_b", "row 1 starts at 1")),
        (lambda m: m["indices_a"].__setitem__(3, DOM.npix), ("indices_a", "outside [0, 192)")),
        (lambda m: m["indices_a"].__setitem__(0, -1), ("indices_a", "row", "outside")),
        (_unsort, ("indices_b", "not increasing")),
        (_dup, ("indices_b", "not increasing")),
        (lambda m: m["r"].__setitem__(2, np.nan), ("row 3", "r=nan")),
        (lambda m: m["g"].__setitem__(0, np.inf), ("row 1", "g=inf")),
        (lambda m: m["r"].__setitem__(7, 400.5), ("row 8", "r=400.5")),
        (lambda m: m["elevation"].__setitem__(1, 0.41), ("row 2", "elevation=0.41")),
        (lambda m: m["azimuth"].__setitem__(1, -0.1), ("row 2", "azimuth=-0.1")),
        (lambda m: m["g"].__setitem__(4, 0.0), ("row 5", "g=0.0")),
        (lambda m: m["x"].__setitem__(6, m["x"][6] + 1.0), ("row 7", "x=")),
        (lambda m: m.__setitem__("indices_a", m["indices_a"].astype(float)), ("indices_a",)),
        (lambda m: m.__setitem__("r", m["r"].astype(np.float32)), ("'r'", "float32")),
        (lambda m: m.__setitem__("indptr_a", m["indptr_a"][:-1]), ("indptr_a", "length 20")),
        (lambda m: m.__setitem__("g", m["g"].reshape(4, 5)), ("'g'", "expected 1-D")),
        (lambda m: m.pop("elevation"), ("'elevation' is missing",)),
        (lambda m: m.pop("meta"), ("'meta' is missing",)),
    ],
)
def test_damaged_members_are_named(tmp_path, how, words):
    _refused(_mutated(tmp_path, how), *words)


@pytest.mark.parametrize("name", ["x", "y", "z"])
def test_a_centre_a_millionth_off_its_r_azimuth_elevation_is_refused(tmp_path, name):
    # far inside any plotting tolerance, far outside float64 rounding (1e-9 r)
    def nudge(m):
        m[name][3] += 1e-6 * m["r"][3]

    _refused(_mutated(tmp_path, nudge), "row 4", f"{name}=")


@pytest.mark.parametrize(
    "meta, words",
    [
        ({"format": "other"}, ("bad meta", "format")),
        ({"version": 99}, ("bad meta", "version 99")),
        ({"n": 21}, ("indptr_a", "length 21")),
        ({"n": -1}, ("bad meta", "n must be an integer >= 0")),
        ({"n": "x"}, ("bad meta", "n must be")),
        ({"nnz_a": 10**30}, ("bad meta", "nnz_a")),
        ({"nnz_b": 3}, ("indices_b", "length 3")),
        ({"domain": {**DOM.to_dict(), "nside": 5}}, ("bad meta", "nside must be an even")),
        ({"domain": {**DOM.to_dict(), "el_max": 3.0}}, ("bad meta", "el_max")),
        ({"domain": {k: v for k, v in DOM.to_dict().items() if k != "h"}}, ("bad meta", "h")),
        ({"domain": [1, 2]}, ("bad meta", "domain is not an object")),
        ({"params": 5}, ("bad meta", "params")),
    ],
)
def test_bad_meta_is_one_line(tmp_path, meta, words):
    _refused(_mutated(tmp_path, lambda m: None, meta), *words)


def test_nnz_that_disagrees_with_indptr(tmp_path):
    def shift(m):  # a consistent member length, but the last row ends short of nnz
        m["indptr_a"][-1] -= 1

    _refused(_mutated(tmp_path, shift), "indptr_a ends at", "nnz_a")


def test_huge_declared_shapes_are_refused_before_allocating(tmp_path):
    """Headers declaring 10^9 rows (8 GB per member) over a few kB of data."""
    ds = rows(20)
    good = _members(ds)
    path = tmp_path / "bomb.npz"
    with zipfile.ZipFile(path, "w") as zf:
        for name, arr in good.items():
            with zf.open(name + ".npy", "w") as f:
                if name == "indptr_a":
                    hdr = {"descr": "<i8", "fortran_order": False, "shape": (10**9 + 1,)}
                    np.lib.format.write_array_header_1_0(f, hdr)
                    f.write(arr.tobytes())
                else:
                    np.lib.format.write_array(f, arr, allow_pickle=False)
    tracemalloc.start()
    try:
        _refused(path, "indptr_a", "declares shape (1000000001,)")
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 10_000_000


def test_compressed_and_lying_members(tmp_path):
    path = tmp_path / "z.npz"
    _zip(path, _members(rows(20)), compress=zipfile.ZIP_DEFLATED)
    _refused(path, "compressed")
    # a central directory declaring more bytes for member 'r' than the file holds
    _zip(path, _members(rows(20)))
    data = bytearray(path.read_bytes())
    at = 0
    while True:
        at = data.index(b"PK\x01\x02", at + 1)
        name_len = int.from_bytes(data[at + 28 : at + 30], "little")
        if data[at + 46 : at + 46 + name_len] == b"r.npy":
            break
    data[at + 20 : at + 28] = (10**8).to_bytes(4, "little") * 2
    path.write_bytes(bytes(data))
    _refused(path, "'r'", "declares 100000000 bytes the file lacks")


def test_non_regular_file_is_refused(tmp_path):
    with pytest.raises(EyevizError, match="not a regular file|not a readable"):
        sparse3d.load3d(tmp_path)


@pytest.mark.parametrize(
    "header",
    [
        {"descr": "<U100", "fortran_order": False, "shape": (10**9,)},
        {"descr": "<U100000000", "fortran_order": False, "shape": ()},
        {"descr": "<f8", "fortran_order": False, "shape": ()},
    ],
)
def test_a_meta_declaring_too_much_or_the_wrong_kind_is_refused(tmp_path, header):
    m = _members(rows(20))
    path = tmp_path / "meta.npz"
    with zipfile.ZipFile(path, "w") as zf:
        for name, arr in m.items():
            with zf.open(name + ".npy", "w") as f:
                if name == "meta":
                    np.lib.format.write_array_header_1_0(f, header)
                    f.write(b"\0" * 400)
                else:
                    np.lib.format.write_array(f, arr, allow_pickle=False)
    _refused(path, "'meta'")


def test_a_flipped_bit_that_keeps_the_rows_valid_fails_the_crc(small, tmp_path):
    path, ds = small
    data = bytearray(path.read_bytes())
    with zipfile.ZipFile(path) as zf:
        info = zf.getinfo("g.npy")
    name_len, extra_len = np.frombuffer(
        data[info.header_offset + 26 : info.header_offset + 30], "<u2"
    )
    start = info.header_offset + 30 + int(name_len) + int(extra_len)
    body = start + info.file_size - 8 * len(ds)  # after the .npy header: g[0]'s 8 bytes
    data[body] ^= 1  # the lowest mantissa bit of g[0]: still a valid g
    bad = tmp_path / "flip.npz"
    bad.write_bytes(bytes(data))
    _refused(bad, "member 'g' is damaged", "CRC-32")
    blocks = sparse3d.Sparse3DReader(bad, block_rows=7)
    with pytest.raises(EyevizError, match="CRC-32"):
        for _ in blocks:  # the last block is not handed out
            pass


def test_random_byte_damage_is_refused_in_one_line_or_harmless(small, tmp_path):
    path, ds = small
    data = path.read_bytes()
    rng = np.random.default_rng(0)
    bad = tmp_path / "fuzz.npz"
    for _ in range(120):
        b = bytearray(data)
        for _ in range(int(rng.integers(1, 4))):
            b[int(rng.integers(0, len(b)))] = int(rng.integers(0, 256))
        bad.write_bytes(bytes(b))
        try:
            back = sparse3d.load3d(bad)
        except EyevizError as exc:
            assert "\n" not in str(exc)
        else:  # zip metadata the reader does not use (times, the local CRC copies)
            same(back, ds)
