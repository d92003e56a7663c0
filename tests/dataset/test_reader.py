"""eyeviz.dataset.reader: reading every row at once is for NPZ data sets only."""

import pytest

from eyeviz import EyevizError
from eyeviz import dataset as D
from eyeviz.core.geometry import EyePair
from eyeviz.dataset.reader import iter_blocks

EYES = EyePair(30.0, 10.0, 64)


def test_read_all_refuses_a_csv_with_one_line_naming_the_file(tmp_path):
    ds = D.generate(40, eyes=EYES, r_min=100.0, r_max=400.0, g_max=60.0, seed=3)
    p = tmp_path / "d.csv"
    D.save(ds, p)
    reader = iter_blocks(p, eyes=EYES)
    with pytest.raises(EyevizError, match=r"d\.csv: reading every row at once needs an NPZ"):
        reader.read_all()  # before: np.empty(None) made a 0-d array and read garbage
    list(reader)  # after streaming, n is known, but it is still a CSV
    with pytest.raises(EyevizError, match="needs an NPZ"):
        reader.read_all()
    q = tmp_path / "d.npz"
    D.save(ds, q)
    rows = iter_blocks(q, eyes=EYES).read_all()
    assert len(rows) == 40


def _npz_with_meta_header(path, header: dict) -> None:
    """A data set NPZ whose meta member declares ``header`` over a few bytes of body."""
    import io
    import zipfile

    import numpy as np

    buf = io.BytesIO()
    np.lib.format.write_array_header_1_0(buf, header)
    buf.write(b"x" * 400)
    rows = io.BytesIO()
    np.save(rows, np.zeros(0, np.uint8))
    with zipfile.ZipFile(path, "w", zipfile.ZIP_STORED) as zf:
        zf.writestr("meta.npy", buf.getvalue())
        zf.writestr("rows.npy", rows.getvalue())


def test_a_meta_member_declaring_gigabytes_is_refused_before_allocating(tmp_path):
    path = tmp_path / "bomb.npz"
    _npz_with_meta_header(path, {"descr": "<U100", "fortran_order": False, "shape": (10**9,)})
    with pytest.raises(EyevizError, match="meta member is <U100 of shape") as exc:
        D.load(path)
    assert "\n" not in str(exc.value)


def test_a_spherical_data_set_is_named_as_such(tmp_path):
    path = tmp_path / "sky.npz"
    D.write3d(path, 5, domain=_small_domain3d(), seed=1)
    with pytest.raises(
        EyevizError,
        match=r"a sparse 3D data set \(spherical eyes\), not a planar one: .*kinds.open_reader",
    ):
        D.load(path)


def _small_domain3d():
    from eyeviz.core.domain import Domain3D

    return Domain3D(nside=8, r_min=100.0, r_max=300.0, g_max=30.0)


def test_a_number_with_an_underscore_is_refused_naming_its_line(tmp_path):
    """Python's float() reads "1_000"; no CSV writer means that."""
    ds = D.generate(3, seed=4)
    path = tmp_path / "d.csv"
    D.save(ds, path)
    lines = path.read_bytes().splitlines(keepends=True)
    fields = lines[1].rstrip(b"\n").split(b",")
    fields[-3] = b"1_000"  # r
    lines[1] = b",".join(fields) + b"\n"
    path.write_bytes(b"".join(lines))
    with pytest.raises(EyevizError, match=r"line 2.*not a number: .?1_000") as exc:
        D.load(path)
    assert "\n" not in str(exc.value)


def test_a_data_file_that_is_not_a_regular_file_is_named_so(tmp_path):
    link = tmp_path / "zero.csv"
    link.symlink_to("/dev/zero")
    with pytest.raises(EyevizError, match="is not a regular file"):
        D.load(link)
    with pytest.raises(EyevizError, match="no such data set file"):
        D.load(tmp_path / "missing.csv")
