"""A measured eye pair embedded in a sparse data set, so the file is self-contained.

A data set of measured eyes (``eyeviz generate --eye``, :mod:`eyeviz.dataset.sparse3d`)
stores the pair beside the lit sets, as float64 ``.npy`` members, one-dimensional as every
member of the format: ``eye_a_positions`` and ``eye_a_axes`` (3 n_A values: row-major
(n_A, 3), millimetres, eyeviz's frame), ``eye_a_acceptance`` (n_A full angles, radians),
and the same for eye B. The meta's domain carries the pair's fingerprint (``eye``, the
sha256 of these arrays, :attr:`eyeviz.core.measured.MeasuredEyePair.fingerprint`) and its
facet counts (``n_a``, ``n_b``). The reader rebuilds the pair with the model's own checks
(:class:`eyeviz.core.measured.MeasuredEye`), refuses it unless its fingerprint is the
meta's, and re-computes the lit sets of a few rows (:func:`check_lit_rows`): a file whose
arrays or lit sets were edited apart is refused in one line.
"""

from __future__ import annotations

import numpy as np

from eyeviz import EyevizError
from eyeviz.core.measured import MAX_FACETS, MeasuredEye, MeasuredEyePair

__all__ = ["EYE_MEMBERS", "LIT_CHECK_ROWS", "check_lit_rows", "eye_arrays", "pair_from_arrays"]

#: The members holding the pair: per eye A, B its lens positions, axes, acceptance angles.
EYE_MEMBERS = tuple(
    f"eye_{e}_{what}" for e in ("a", "b") for what in ("positions", "axes", "acceptance")
)
#: Rows per file whose lit sets the reader re-computes from the embedded eyes (evenly
#: spaced, the first and last included): enough to catch a file whose eyes and lit sets
#: do not belong together, at a cost of a few lit-set calls.
LIT_CHECK_ROWS = 8


def eye_arrays(pair: MeasuredEyePair) -> dict[str, np.ndarray]:
    """The members of :data:`EYE_MEMBERS`, float64 little-endian, 1-D."""
    out: dict[str, np.ndarray] = {}
    for e, eye in (("a", pair.eye_a), ("b", pair.eye_b)):
        for what in ("positions", "axes", "acceptance"):
            out[f"eye_{e}_{what}"] = np.ascontiguousarray(getattr(eye, what), "<f8").reshape(-1)
    return out


def expected_lengths(n_a: int, n_b: int) -> dict[str, int]:
    """Member lengths for facet counts (n_A, n_B)."""
    per = {"positions": 3, "axes": 3, "acceptance": 1}
    return {
        f"eye_{e}_{what}": k * n for e, n in (("a", n_a), ("b", n_b)) for what, k in per.items()
    }


def check_counts(n_a, n_b) -> tuple[int, int]:
    """The meta's facet counts, each an integer in [1, MAX_FACETS]."""
    from eyeviz.core.validation import check_int

    return (
        check_int("n_a", n_a, ge=1, le=MAX_FACETS),
        check_int("n_b", n_b, ge=1, le=MAX_FACETS),
    )


def pair_from_arrays(arrays: dict[str, np.ndarray], fingerprint: str) -> MeasuredEyePair:
    """The pair of the members ``arrays``; EyevizError unless the model accepts them and
    their fingerprint is ``fingerprint``."""
    eyes = []
    for e in ("a", "b"):
        pos = arrays[f"eye_{e}_positions"].reshape(-1, 3)
        ax = arrays[f"eye_{e}_axes"].reshape(-1, 3)
        acc = arrays[f"eye_{e}_acceptance"]
        eyes.append(MeasuredEye(pos, ax, acc, name=e.upper()))
    pair = MeasuredEyePair(eyes[0], eyes[1], name="embedded", source="data set")
    if pair.fingerprint != fingerprint:
        raise EyevizError(
            f"the embedded eyes' fingerprint {pair.fingerprint[:16]}... is not the meta's "
            f"{str(fingerprint)[:16]}... (eyes and data set do not belong together)"
        )
    return pair


def check_lit_rows(pair, block, start: int, n: int) -> str | None:
    """Re-compute the lit sets of the rows of ``block`` (a Dataset3D of rows ``start ..``
    of ``n``) that fall on :data:`LIT_CHECK_ROWS` evenly spaced rows of the file, with
    ``pair.lit_csr`` (any eye model of the seam: the embedded measured pair, or the
    HEALPix eyes of the file's design); the first mismatch as ``"row k: eye A lights
    ..."`` (1-based), saying so when the file's eye A and B lists are swapped; or None."""
    want = np.unique(np.linspace(0, max(n - 1, 0), min(n, LIT_CHECK_ROWS)).astype(np.int64))
    rows = want[(want >= start) & (want < start + len(block))] - start
    if rows.size == 0:
        return None
    got = pair.lit_csr(block.x[rows], block.y[rows], block.z[rows], block.g[rows])

    def stored(e: str, i: int) -> np.ndarray:
        sptr, sidx = getattr(block, f"indptr_{e}"), getattr(block, f"indices_{e}")
        return sidx[sptr[i] : sptr[i + 1]].astype(np.int64)

    def fresh(k: int, j: int) -> np.ndarray:
        ptr, idx = got[k]
        return idx[ptr[j] : ptr[j + 1]]

    for j, i in enumerate(rows):
        same = [np.array_equal(stored(e, i), fresh(k, j)) for k, e in enumerate(("a", "b"))]
        if all(same):
            continue
        row = start + int(i) + 1
        if np.array_equal(stored("a", i), fresh(1, j)) and np.array_equal(
            stored("b", i), fresh(0, j)
        ):
            return f"row {row}: the file's eye A and eye B lit sets are swapped"
        k = same.index(False)
        e = "AB"[k]
        return (
            f"row {row}: eye {e} lights {fresh(k, j).size} facets, the file lists "
            f"{stored(e.lower(), i).size} (or other ones)"
        )
    return None
