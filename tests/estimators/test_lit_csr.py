"""``lit_csr.as_csr`` on CSR rows: int32/int64 indices come back as given (no copy), other
integer types as int64; the blocked sortedness check accepts a drop only at a row start
(empty rows included) and refuses any other non-rising step, whatever block it falls in."""

from __future__ import annotations

import numpy as np
import pytest

from eyeviz.estimators import base, lit_csr
from eyeviz.estimators.base import as_csr

NPIX = 768


@pytest.mark.parametrize("dtype", [np.int32, np.int64])
def test_indices_kept_without_a_copy(dtype):
    ptr = np.array([0, 3, 3, 5])
    ind = np.array([4, 9, 700, 1, 2], dtype)
    p, i, single = as_csr("lit_a", (ptr, ind), NPIX)
    assert i is ind and not single
    assert p.dtype == np.int64 and np.array_equal(p, ptr)


@pytest.mark.parametrize("dtype", [np.uint16, np.int16, np.uint32])
def test_other_integer_types_become_int64(dtype):
    ind = np.array([4, 9, 1], dtype)
    _, i, _ = as_csr("lit_a", (np.array([0, 2, 3]), ind), NPIX)
    assert i.dtype == np.int64 and np.array_equal(i, [4, 9, 1])


@pytest.mark.parametrize(
    "ptr, ind",
    [
        ([0, 2], [5, 5]),  # repeat within a row
        ([0, 3], [5, 9, 6]),  # drop within a row
        ([0, 1, 1, 3], [9, 7, 3]),  # drop inside the row after an empty one
        ([0, 2, 2], [9, 3]),  # a drop at the end of a row (next row empty)
    ],
)
def test_non_rising_step_inside_a_row_is_refused(ptr, ind):
    for dtype in (np.int32, np.int64):
        with pytest.raises(ValueError, match="lit_b: indices must increase strictly"):
            as_csr("lit_b", (np.array(ptr), np.array(ind, dtype)), NPIX)


def test_drops_across_blocks(monkeypatch):
    monkeypatch.setattr(lit_csr, "_CHECK_BLOCK", 4)
    rng = np.random.default_rng(3)
    rows = [np.sort(rng.choice(NPIX, size=k, replace=False)) for k in (5, 0, 3, 7, 1, 0, 6)]
    ptr = np.concatenate([[0], np.cumsum([r.size for r in rows])])
    ind = np.concatenate(rows).astype(np.int32)
    as_csr("lit_a", (ptr, ind), NPIX)  # every drop is at a row start
    for j in range(1, ind.size):
        if j in set(ptr.tolist()):
            continue
        bad = ind.copy()
        bad[j] = bad[j - 1]
        with pytest.raises(ValueError, match="increase strictly"):
            as_csr("lit_a", (ptr, bad), NPIX)


def test_range_checked_by_min_and_max():
    with pytest.raises(ValueError, match=r"\[0, npix = 768\), got 768"):
        as_csr("lit_a", (np.array([0, 2]), np.array([3, 768], np.int32)), NPIX)
    with pytest.raises(ValueError, match="got -1"):
        as_csr("lit_a", (np.array([0, 2]), np.array([-1, 3], np.int32)), NPIX)


def test_check_indices_false_leaves_out_only_the_pass_over_the_indices():
    ptr, ind = np.array([0, 2]), np.array([9, 3], np.int32)  # falls within a row
    p, i, _ = as_csr("lit_a", (ptr, ind), NPIX, check_indices=False)
    assert i is ind and np.array_equal(p, ptr)
    with pytest.raises(ValueError, match="increase strictly"):
        as_csr("lit_a", (ptr, ind), NPIX)
    with pytest.raises(ValueError, match="indptr must start at 0"):
        as_csr("lit_a", (np.array([1, 2]), ind), NPIX, check_indices=False)
    with pytest.raises(ValueError, match="1-D integer"):
        as_csr("lit_a", (ptr, ind.astype(float)), NPIX, check_indices=False)


class _Unchecking(base.Estimator3D):
    """Claims to check the indices it is handed, and records them instead."""

    checks_indices = True

    def __init__(self):
        from eyeviz.core.domain import Domain3D

        super().__init__(Domain3D(nside=8))  # npix 768
        self.seen = []

    def _predict_csr(self, lit_a, lit_b):
        self.seen.append((lit_a[1].copy(), lit_b[1].copy()))
        n = lit_a[0].size - 1
        return np.zeros(n), np.zeros(n), np.zeros(n), np.zeros(n, bool)


def test_an_estimator_that_checks_indices_gets_them_unchecked_but_skipped_rows_are_checked():
    est = _Unchecking()
    lit_a = (np.array([0, 2, 3]), np.array([9, 3, 5]))  # row 0 falls: handed over
    lit_b = (np.array([0, 1, 2]), np.array([4, 6]))
    est.predict(lit_a, lit_b)
    assert np.array_equal(est.seen[0][0], [9, 3, 5])
    # row 1 of lit_b is empty, so row 1 is not handed over: predict checks it itself
    lit_a = (np.array([0, 1, 3]), np.array([4, 9, 3]))
    lit_b = (np.array([0, 1, 1]), np.array([4]))
    with pytest.raises(ValueError, match="lit_a: indices must increase strictly"):
        est.predict(lit_a, lit_b)
    lit_a = (np.array([0, 0, 1]), np.array([4]))  # row 0 empty
    lit_b = (np.array([0, 1, 2]), np.array([NPIX, 5]))
    with pytest.raises(ValueError, match=r"lit_b: indices must lie in \[0, npix = 768\), got 768"):
        est.predict(lit_a, lit_b)
