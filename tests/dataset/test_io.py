"""Hostile data set files (issue 13): every reader validates per row, names the first bad
line, bounds what a file declares, and streams in blocks (:func:`iter_blocks`)."""

from __future__ import annotations

import io
import json
import tracemalloc
import zipfile
from dataclasses import replace

import numpy as np
import pytest

from eyeviz import EyevizError
from eyeviz import dataset as D
from eyeviz.core.geometry import EyePair
from eyeviz.dataset import io as dio

EYES = EyePair(30.0, 10.0, 64)


@pytest.fixture(scope="module")
def small():
    return D.generate(700, eyes=EYES, r_min=100.0, r_max=400.0, g_max=60.0, seed=2)


def _csv_lines(ds, tmp_path):
    p = tmp_path / "d.csv"
    D.save(ds, p)
    return p, p.read_bytes().split(b"\n")[:-1]


def _write_npz(path, meta, rows_header, body: bytes, compress=zipfile.ZIP_STORED):
    with zipfile.ZipFile(path, "w", compression=compress) as zf:
        b = io.BytesIO()
        np.lib.format.write_array(b, np.array(json.dumps(meta)), allow_pickle=False)
        zf.writestr("meta.npy", b.getvalue())
        b = io.BytesIO()
        np.lib.format.write_array_header_1_0(b, rows_header)
        zf.writestr("rows.npy", b.getvalue() + body)


# --- CSV: per-row field counts -----------------------------------------------------------


def test_csv_extra_then_missing_field_is_refused_naming_the_line(small, tmp_path):
    p, lines = _csv_lines(small, tmp_path)
    # line 5 gets one extra field, line 6 loses one: the block's total count is unchanged
    lines[4] = lines[4] + b",99999"
    lines[5] = lines[5].rsplit(b",", 1)[0]
    p.write_bytes(b"\n".join(lines) + b"\n")
    with pytest.raises(EyevizError, match=r"line 5, column 68: expected 67 columns, found 68"):
        D.load(p)
    with pytest.raises(EyevizError, match=r"line 5"):
        for _ in dio.iter_blocks(p, block_rows=3):
            pass


def test_csv_bad_line_in_a_later_block_is_named_after_earlier_blocks(small, tmp_path):
    p, lines = _csv_lines(small, tmp_path)
    lines[650] = lines[650].replace(b"0,", b"3,", 1)
    p.write_bytes(b"\n".join(lines) + b"\n")
    got = []
    with pytest.raises(EyevizError, match=r"line 651, column \d+: bit must be 0 or 1, got '3'"):
        for b in dio.iter_blocks(p, block_rows=100):
            got.append(b.start)
    assert got == [0, 100, 200, 300, 400, 500]


@pytest.mark.parametrize(
    "field, msg",
    [(b"nan", "not a finite number"), (b"1e999", "not a finite number"), (b"x", "not a number")],
)
def test_csv_bad_float_named(small, tmp_path, field, msg):
    p, lines = _csv_lines(small, tmp_path)
    parts = lines[9].split(b",")
    parts[64] = field
    lines[9] = b",".join(parts)
    p.write_bytes(b"\n".join(lines) + b"\n")
    with pytest.raises(EyevizError, match=rf"line 10, column 65: {msg}"):
        D.load(p)


@pytest.mark.parametrize(
    "col, value", [(64, b"-5"), (64, b"1e308"), (64, b"1e16"), (65, b"100"), (66, b"-1")]
)
def test_csv_out_of_range_floats_refused(small, tmp_path, col, value):
    p, lines = _csv_lines(small, tmp_path)
    parts = lines[2].split(b",")
    parts[col] = value
    lines[2] = b",".join(parts)
    p.write_bytes(b"\n".join(lines) + b"\n")
    with pytest.raises(EyevizError, match=r"line 3: r, phi, g = .* \(need 0 <= r <= 1e\+15"):
        D.load(p)


def test_csv_long_field_message_is_short(small, tmp_path):
    p, lines = _csv_lines(small, tmp_path)
    parts = lines[0].split(b",")
    parts[64] = b"y" * 100000
    lines[0] = b",".join(parts)
    p.write_bytes(b"\n".join(lines) + b"\n")
    with pytest.raises(EyevizError) as ei:
        D.load(p)
    assert len(str(ei.value)) < 300 and "\n" not in str(ei.value)


# --- NPZ: declared shapes, short rows, malformed files ------------------------------------


def test_npz_short_packed_rows_refused(tmp_path):
    m = 64
    bad = np.dtype([("omega_a", "u1", (2,)), ("omega_b", "u1", (2,)), *[(f, "<f8") for f in "r"]])
    rows = np.zeros(3, bad)
    hdr = {"descr": np.lib.format.dtype_to_descr(bad), "fortran_order": False, "shape": (3,)}
    p = tmp_path / "short.npz"
    _write_npz(p, {"version": 1, "m": m, "n": 3, "params": {}}, hdr, rows.tobytes())
    with pytest.raises(EyevizError, match="expected"):
        D.load(p)


def test_npz_bomb_refused_before_allocating(tmp_path):
    m = 720
    dt = dio.npz_dtype(m)
    n = 30_000_000  # 30e6 * 114 bytes = 3.4 GB declared
    hdr = {"descr": np.lib.format.dtype_to_descr(dt), "fortran_order": False, "shape": (n,)}
    p = tmp_path / "bomb.npz"
    _write_npz(p, {"version": 1, "m": m, "n": n, "params": {}}, hdr, b"\0" * (3 << 20))
    tracemalloc.start()
    try:
        with pytest.raises(EyevizError, match="bytes but the member holds"):
            D.load(p)
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert peak < 50 << 20  # the 3.4 GB the header declares is never allocated


def test_npz_compressed_member_refused(small, tmp_path):
    p = tmp_path / "d.npz"
    D.save(small, p)
    q = tmp_path / "c.npz"
    with zipfile.ZipFile(p) as src, zipfile.ZipFile(q, "w", zipfile.ZIP_DEFLATED) as dst:
        for i in src.infolist():
            dst.writestr(i.filename, src.read(i))
    with pytest.raises(EyevizError, match="compressed"):
        D.load(q)


def _mutated(small, tmp_path, how):
    p = tmp_path / "d.npz"
    D.save(small, p)
    data = bytearray(p.read_bytes())
    how(data)
    q = tmp_path / "bad.npz"
    q.write_bytes(bytes(data))
    return q


@pytest.mark.parametrize(
    "meta",
    [
        {"version": 1, "n": 3},  # no m
        {"version": 1, "m": "x", "n": 3},
        {"version": 1, "m": 2**70, "n": 3},
        {"version": 1, "m": 64, "n": 3, "params": []},
        {"version": 1, "m": 64, "n": 3, "params": {"h": 1.0, "l": 5.0}},
        {"version": 1, "m": 64, "n": 3, "params": {"h": "nan"}},
        [1, 2],
    ],
)
def test_npz_bad_meta_one_line(tmp_path, meta):
    dt = dio.npz_dtype(64)
    hdr = {"descr": np.lib.format.dtype_to_descr(dt), "fortran_order": False, "shape": (3,)}
    p = tmp_path / "m.npz"
    _write_npz(p, meta, hdr, np.zeros(3, dt).tobytes())
    with pytest.raises(EyevizError) as ei:
        D.load(p)
    assert "\n" not in str(ei.value)


def test_npz_truncated_and_garbage_one_line(small, tmp_path):
    p = tmp_path / "d.npz"
    D.save(small, p)
    data = p.read_bytes()
    for k, blob in enumerate([data[: len(data) // 2], data[:100], b"PK\x03\x04" + b"\0" * 50]):
        q = tmp_path / f"t{k}.npz"
        q.write_bytes(blob)
        with pytest.raises(EyevizError, match="not an eyeviz NPZ"):
            D.load(q)
    # a member without meta
    q = tmp_path / "nometa.npz"
    with zipfile.ZipFile(q, "w") as zf:
        zf.writestr("rows.npy", b"")
    with pytest.raises(EyevizError, match="no member 'meta.npy'"):
        D.load(q)


def test_npz_nan_r_refused_naming_the_row(small, tmp_path):
    p = tmp_path / "d.npz"
    D.save(small, p)
    data = bytearray(p.read_bytes())
    off = data.index(np.float64(small.r[4]).tobytes())
    data[off : off + 8] = np.float64(np.nan).tobytes()
    q = tmp_path / "nan.npz"
    q.write_bytes(bytes(data))
    with pytest.raises(EyevizError, match=r"(row 5: r, phi, g = nan)|(Bad CRC)"):
        D.load(q)


def test_npz_design_h_l_checked(small, tmp_path):
    p = tmp_path / "d.npz"
    D.save(small, p)
    assert D.load(p, EYES).eyes == EYES
    with pytest.raises(EyevizError, match="made with h=30, l=10, but eyes have h=40, l=20"):
        D.load(p, EyePair(40.0, 20.0, 64))
    with pytest.raises(EyevizError, match="m=64, but eyes have m=720"):
        D.load(p, EyePair(40.0, 20.0, 720))


# --- save refuses what load refuses ---------------------------------------------------------


@pytest.mark.parametrize("fmt", ["csv", "npz"])
def test_save_refuses_nan_r_and_bad_bits(small, tmp_path, fmt):
    p = tmp_path / f"x.{fmt}"
    r = small.r.copy()
    r[3] = np.nan
    with pytest.raises(EyevizError, match="data set: row 4: r, phi, g = nan, "):
        D.save(replace(small, r=r), p)
    for v in (3, 255):
        oa = small.omega_a.astype(np.uint8)
        oa[7, 5] = v
        with pytest.raises(EyevizError, match=rf"omega_a row 8, bit 5: .*{v}.* is not 0 or 1"):
            D.save(replace(small, omega_a=oa), p)
    g = small.g.copy()
    g[0] = np.nan
    with pytest.raises(EyevizError, match="g must be finite, or NaN in every row"):
        D.save(replace(small, g=g), p)
    assert not p.exists() and not list(tmp_path.glob(".x*"))


# --- iter_blocks ---------------------------------------------------------------------------


@pytest.mark.parametrize("fmt", ["csv", "npz"])
@pytest.mark.parametrize("block_rows", [1, 7, 700, 10_000])
def test_iter_blocks_equals_load(small, tmp_path, fmt, block_rows):
    p = tmp_path / f"d.{fmt}"
    D.save(small, p)
    whole = D.load(p, EYES)
    reader = dio.iter_blocks(p, block_rows=block_rows, eyes=EYES)
    assert reader.eyes == EYES and reader.n == (700 if fmt == "npz" else None)
    if fmt == "npz":
        assert reader.params["h"] == 30.0
    blocks = list(reader)
    assert reader.n == 700
    assert [b.start for b in blocks] == list(range(0, 700, block_rows))
    assert all(len(b.r) <= block_rows for b in blocks)
    for f in ("omega_a", "omega_b", "r", "phi", "g"):
        got = np.concatenate([getattr(b, f) for b in blocks])
        np.testing.assert_array_equal(got, getattr(whole, f))
        np.testing.assert_array_equal(got, getattr(small, f))


def test_iter_blocks_bad_arguments(small, tmp_path):
    p = tmp_path / "d.csv"
    D.save(small, p)
    for bad in (0, -1, 1.5, None):
        with pytest.raises(EyevizError, match="block_rows"):
            dio.iter_blocks(p, block_rows=bad)
    with pytest.raises(EyevizError, match="no such data set"):
        dio.iter_blocks(tmp_path / "none.csv")


@pytest.mark.slow
def test_iter_blocks_memory_is_bounded(tmp_path):
    """Peak traced memory reading 20,000 rows (m = 720) in blocks of 500 stays a small
    fraction of load()'s."""
    ds = D.generate(20_000, seed=1)
    p = tmp_path / "big.csv"
    D.save(ds, p)
    del ds
    tracemalloc.start()
    total = 0
    for b in dio.iter_blocks(p, block_rows=500):
        total += int(b.omega_a.sum())
    _, peak_blocks = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    tracemalloc.start()
    whole = D.load(p)
    _, peak_load = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    assert total == int(whole.omega_a.sum())
    print(f"peak traced: blocks {peak_blocks / 1e6:.1f} MB, load {peak_load / 1e6:.1f} MB")
    assert peak_blocks * 10 < peak_load


@pytest.mark.slow
@pytest.mark.parametrize("fmt", ["csv", "npz"])
def test_wide_rows_written_in_blocks_give_the_same_bytes(tmp_path, monkeypatch, fmt):
    """Chunks are cut into blocks of at most _BLOCK_BYTES (memory bounded at any m); a
    tiny budget (blocks of a few rows, across chunk ends) writes the same file."""
    kw = dict(eyes=EYES, r_min=100.0, r_max=400.0, g_max=60.0, seed=5)
    whole, blocks = tmp_path / f"a.{fmt}", tmp_path / f"b.{fmt}"
    D.write(whole, 20_000, **kw)  # two generated chunks (CHUNK = 16384)
    monkeypatch.setattr(dio, "_BLOCK_BYTES", 700)  # 5 CSV rows, 7 NPZ rows at m = 64
    assert dio.block_rows(2 * EYES.m, 1 << 14) == 5
    D.write(blocks, 20_000, **kw)
    assert blocks.read_bytes() == whole.read_bytes()
    ds = D.load(whole)
    D.save(ds, saved := tmp_path / f"c.{fmt}")  # save() blocks the same way
    assert D.load(saved).r.tobytes() == ds.r.tobytes()


@pytest.mark.parametrize("fmt", ["csv", "npz"])
def test_generate_at_the_largest_m_stays_in_bounded_memory(tmp_path, fmt):
    """m = MAX_M used to need a 16384-row buffer of 2m bytes per row (32 GiB for
    CSV: `out of memory`); the write now works in blocks of <= 64 MiB."""
    from eyeviz.core.bounds import MAX_M

    m = MAX_M
    eyes = EyePair(40.0, 20.0, m)
    p = tmp_path / f"wide.{fmt}"
    tracemalloc.start()
    D.write(p, 3, eyes=eyes, seed=1)
    _, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    assert peak < 600 << 20, peak
    ds = D.load(p)
    assert ds.omega_a.shape == (3, m // 2) and ds.eyes.m == m
