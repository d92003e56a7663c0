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
