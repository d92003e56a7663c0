"""eyeviz.files.npz: members read header-first, bounded, never unpickled."""

from __future__ import annotations

import io
import zipfile

import numpy as np
import pytest

from eyeviz import EyevizError
from eyeviz.files.npz import NpzReader, one_line


def _npz(path, **members) -> None:
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as zf:
        for k, v in members.items():
            buf = io.BytesIO()
            if isinstance(v, bytes):
                buf.write(v)
            else:
                np.lib.format.write_array(buf, v, allow_pickle=True)
            zf.writestr(k + ".npy", buf.getvalue())


def test_reads_a_plain_member(tmp_path):
    p = tmp_path / "a.npz"
    np.savez_compressed(p, a=np.arange(10, dtype=np.uint32), s=np.array("hi"))
    with NpzReader(p) as z:
        assert sorted(z.names) == ["a", "s"]
        np.testing.assert_array_equal(z.read_member("a", 10, ("uint32",), ndim=1), np.arange(10))
        assert str(z.read_member("s", 1, ("U",), ndim=0)[()]) == "hi"
        with pytest.raises(EyevizError, match="declares 10 elements, more than 9"):
            z.read_member("a", 9)
        with pytest.raises(EyevizError, match="dtype uint32, expected"):
            z.read_member("a", 10, ("int64",))
        with pytest.raises(EyevizError, match="shape"):
            z.read_member("a", 10, ndim=2)
        with pytest.raises(EyevizError, match="member 'b' is missing"):
            z.read_member("b", 10)


def test_declared_shape_beyond_the_data_is_refused_before_allocating(tmp_path):
    buf = io.BytesIO()
    np.lib.format.write_array(buf, np.zeros(4, np.float64))
    raw = buf.getvalue().replace(b"(4,)", b"(3000000000,)".ljust(4 + 9), 1)
    p = tmp_path / "bomb.npz"
    _npz(p, x=raw)
    with NpzReader(p) as z, pytest.raises(EyevizError, match="declares 3000000000 elements"):
        z.read_member("x", 10**9)
    with NpzReader(p) as z, pytest.raises(EyevizError, match=r"\(24000000000 bytes\) but holds"):
        z.read_member("x", 10**12, max_bytes=10**13)


def test_object_arrays_and_damage_are_one_line(tmp_path):
    p = tmp_path / "o.npz"
    _npz(p, x=np.array([{"a": 1}], dtype=object))
    with NpzReader(p) as z, pytest.raises(EyevizError, match="dtype object, not a plain"):
        z.read_member("x", 10)
    q = tmp_path / "d.npz"
    np.savez_compressed(q, a=np.arange(1000))
    blob = bytearray(q.read_bytes())
    blob[60:80] = b"\x00" * 20  # inside the deflate stream
    q.write_bytes(bytes(blob))
    with pytest.raises(EyevizError) as info:
        with NpzReader(q, "table") as z:
            z.read_member("a", 1000)
    assert str(info.value).startswith("table: ") and "\n" not in str(info.value)
    (tmp_path / "n.npz").write_bytes(b"not a zip")
    with pytest.raises(EyevizError, match="not a readable .npz"):
        NpzReader(tmp_path / "n.npz")


def test_one_line():
    assert one_line(ValueError("a\nb")) == "a"
    assert one_line(KeyError()) == "KeyError"
    assert one_line(ValueError("x" * 500), 10) == "x" * 10 + "..."
