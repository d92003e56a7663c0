"""The records of every eye model: one joining rule (eyeviz.dataset.records._Rows)."""

from __future__ import annotations

import numpy as np
import pytest

from eyeviz.core.domain import Domain3D
from eyeviz.core.geometry import EyePair
from eyeviz.dataset.records import Chunk, Dataset, Dataset3D


def _planar(rng, n, m=8):
    bits = rng.random((2, n, m // 2)) < 0.5
    return Dataset(bits[0], bits[1], *rng.random((3, n)), eyes=EyePair(40.0, 20.0, m),
                   params={"seed": n})  # fmt: skip


def _csr(rng, n, npix, values):
    counts = rng.integers(0, 4, n)
    indptr = np.concatenate([[0], np.cumsum(counts)]).astype(np.int64)
    indices = np.concatenate([[], *(np.sort(rng.choice(npix, c, replace=False)) for c in counts)])
    return indptr, indices.astype(np.int32), (rng.random(indices.size) if values else None)


def _sparse(rng, n, values=False):
    dom = Domain3D(nside=2)
    (pa, ia, va), (pb, ib, vb) = (_csr(rng, n, dom.npix, values) for _ in range(2))
    return Dataset3D(pa, ia, pb, ib, *rng.random((7, n)), domain=dom, params={"n": n},
                     values_a=va, values_b=vb)  # fmt: skip


def test_planar_rows_join_in_order_and_keep_the_first_parts_eyes():
    rng = np.random.default_rng(1)
    parts = [_planar(rng, n) for n in (3, 0, 5)]
    out = Dataset.concat(parts)
    assert len(out) == 8 and out.eyes is parts[0].eyes and out.params == {"seed": 3}
    assert out.params is not parts[0].params
    for k in ("omega_a", "omega_b", "r", "phi", "g"):
        assert np.array_equal(getattr(out, k), np.concatenate([getattr(p, k) for p in parts]))
    assert np.array_equal(out[3:].omega_a, parts[2].omega_a)


@pytest.mark.parametrize("values", [False, True])
def test_sparse_rows_join_with_shifted_pointers(values):
    rng = np.random.default_rng(2)
    parts = [_sparse(rng, n, values) for n in (4, 0, 3)]
    out = Dataset3D.concat(parts)
    assert len(out) == 7 and out.domain == parts[0].domain and out.params == {"n": 4}
    rows = [(p, i) for p in parts for i in range(len(p))]
    for j, (p, i) in enumerate(rows):
        for got, want in zip(out.lit(j), p.lit(i), strict=True):
            assert np.array_equal(got, want)
    assert out.indptr_a[-1] == out.indices_a.size and out.indptr_b.dtype == np.int64
    if values:
        assert np.array_equal(out.values_b, np.concatenate([p.values_b for p in parts]))
    else:
        assert out.values_a is None and out.values_b is None
    for k in ("r", "azimuth", "elevation", "g", "x", "y", "z"):
        assert np.array_equal(getattr(out, k), np.concatenate([getattr(p, k) for p in parts]))


def test_chunks_join_and_nothing_is_refused_in_one_line():
    rng = np.random.default_rng(3)
    a, b = (Chunk(*rng.random((3, n)), *rng.integers(0, 4, (4, n))) for n in (2, 3))
    out = Chunk.concat([a, b])
    assert len(out) == 5 and np.array_equal(out.rb, np.concatenate([a.rb, b.rb]))
    for cls in (Dataset, Dataset3D, Chunk):
        with pytest.raises(ValueError, match="^cannot concatenate an empty list of data sets$"):
            cls.concat([])
