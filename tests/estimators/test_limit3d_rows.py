"""eyeviz.estimators.limit3d_rows: a chunk's accepted draws compacted into rows, and the
weighted spread the top-ups' stop rule reads."""

from __future__ import annotations

import numpy as np

from eyeviz.estimators.limit import weighted_median


def test_compact_keeps_the_accepted_draws_and_the_medians_read_no_padding():
    """limit3d_rows._compact: each row's accepted draws first, in draw order; the padding
    weighs 0 and holds the row's largest accepted value, so the weighted medians of the
    compacted rows are those of the accepted draws alone (a rejected draw's value between
    two accepted ones would move an interpolated median)."""
    from eyeviz.estimators.limit3d_rows import _compact

    rng = np.random.default_rng(3)
    n, m = 7, 60
    w = np.where(rng.random((n, m)) < 0.3, rng.random((n, m)), 0.0)
    w[0] = 0.0  # nothing accepted
    w[1] = 0.0
    w[1, 5] = 0.7  # one accepted draw
    r = rng.uniform(1.0, 5.0, (n, m))
    el = rng.normal(size=(n, m))
    c = _compact({"r": r, "el": el, "w": w})
    cnt = (w > 0).sum(axis=1)
    assert c["w"].shape[1] == cnt.max()
    for i in range(n):
        acc = w[i] > 0
        k = int(cnt[i])
        assert np.array_equal(c["r"][i, :k], r[i, acc]) and np.array_equal(c["w"][i, :k], w[i, acc])
        assert (c["w"][i, k:] == 0).all()
        assert (c["r"][i, k:] == (r[i, acc].max() if k else 1.0)).all()
        assert (c["el"][i, k:] == (el[i, acc].max() if k else 1.0)).all()
        if k:
            want = weighted_median(r[i, acc][None], (w[i, acc] / r[i, acc])[None])[0]
            assert weighted_median(c["r"][i : i + 1], (c["w"] / c["r"])[i : i + 1])[0] == want
            want = weighted_median(el[i, acc][None], w[i, acc][None])[0]
            assert weighted_median(c["el"][i : i + 1], c["w"][i : i + 1])[0] == want


def test_compact_keeps_each_rows_accepted_draws_in_order_then_its_largest_value():
    """limit3d_rows._compact against a row-by-row reading of its docstring: each row's draws
    of weight > 0 first, in draw order; then padding of weight 0 holding the row's
    largest accepted value of each quantity (1 where none is accepted), as wide as the
    most accepted draws of a row (at least 1). NaN and negative weights are not accepted;
    NaN values stay as they are."""
    from eyeviz.estimators.limit3d_rows import _compact

    rng = np.random.default_rng(3)
    for _ in range(200):
        n, m = int(rng.integers(0, 6)), int(rng.integers(1, 30))
        w = rng.random((n, m))
        w[rng.random((n, m)) < rng.random()] = 0.0
        w[rng.random((n, m)) < 0.05] = np.nan
        w[rng.random((n, m)) < 0.05] = -1.0
        r = np.where(rng.random((n, m)) < 0.1, np.nan, rng.normal(size=(n, m)))
        got = _compact({"r": r, "w": w})
        acc = w > 0
        k = max(1, int(acc.sum(axis=1).max()) if n else 1)
        for name, v in (("r", r), ("w", w)):
            assert got[name].shape == (n, k)
            for i in range(n):
                kept = v[i][acc[i]]
                pad = 0.0 if name == "w" else (np.max(kept) if kept.size else 1.0)
                pad = pad if np.isfinite(pad) else 1.0
                want = np.concatenate([kept, np.full(k - kept.size, pad)])
                assert np.array_equal(got[name][i], want, equal_nan=True), (name, i)


def test_compact_sparse_is_compact_of_the_dense_draws():
    """limit3d_rows._compact_sparse (a proposal's accepted draws alone, row by row in draw
    order) against limit3d_rows._compact of the same draws in dense rows: the same arrays bit
    for bit, rows with none accepted and NaN values included."""
    from eyeviz.estimators.limit3d_rows import _compact, _compact_sparse

    rng = np.random.default_rng(5)
    for _ in range(200):
        n, m = int(rng.integers(1, 6)), int(rng.integers(1, 30))
        w = np.where(rng.random((n, m)) < rng.random(), rng.random((n, m)) + 0.01, 0.0)
        r = np.where(rng.random((n, m)) < 0.1, np.nan, rng.normal(size=(n, m)))
        el = rng.normal(size=(n, m))
        want = _compact({"r": r, "el": el, "w": w})
        at = np.flatnonzero(w.ravel() > 0)
        got = _compact_sparse(n, at // m, {k: v.ravel()[at] for k, v in
                                           (("r", r), ("el", el), ("w", w))})  # fmt: skip
        assert list(got) == list(want)
        for k in want:
            assert np.array_equal(got[k], want[k], equal_nan=True), k


def test_spread_flat_is_spread_of_the_compacted_rows(monkeypatch):
    """limit3d_rows._spread_flat (the top-ups' decisions from the accepted draws alone, batch
    after batch, rows interleaved) against limit3d_rows._spread of the same draws compacted
    into rows: the same values to rounding, the same decisions of _needs_more_of and
    _more_batches_of, rows with nothing accepted (NaN, topped up by _TOPUP) included;
    compiled and in numpy (``np.bincount``) bit for bit."""
    from eyeviz.estimators import limit3d as l3
    from eyeviz.estimators import limit3d_rows as rows

    rng = np.random.default_rng(11)
    for _ in range(200):
        n, d = int(rng.integers(1, 7)), int(rng.integers(0, 200))  # 64 or more: compiled
        row = rng.integers(0, n, d)
        r = rng.uniform(5.0, 80.0, d)
        w = rng.random(d) + 1e-3
        by = np.argsort(row, kind="stable")
        dense = rows._compact_sparse(n, row[by], {"r": r[by], "w": w[by]})
        want = rows._spread(dense["r"], dense["w"])
        got = rows._spread_flat(n, row, r, w)
        for a, b in zip(got, want, strict=True):
            assert np.allclose(a, b, rtol=1e-12, atol=0.0, equal_nan=True)
        with monkeypatch.context() as m:
            m.setenv("EYEVIZ_JIT", "0")
            ref = rows._spread_flat(n, row, r, w)
        for a, b in zip(got, ref, strict=True):  # the kernel's sums are np.bincount's
            assert np.array_equal(a, b, equal_nan=True)
        done = rng.integers(1, 10, n)
        for target in (0.01, 0.05, 0.2):
            assert np.array_equal(l3._needs_more_of(*got, target), l3._needs_more_of(*want, target))
            assert np.array_equal(l3._more_batches_of(*got, target, done),
                                  l3._more_batches_of(*want, target, done))  # fmt: skip
