"""Graded responses beside the lit sets of a sparse data set (docs/responses.md).

``eyeviz generate --responses KIND`` stores, per eye, one float64 per lit index
(members ``values_a``, ``values_b``, aligned with ``indices_a``, ``indices_b``) and the
kind in the meta (``"responses"``). A reader checks every value (finite, in [0, 1]) and
re-computes a few rows' values with the eye model, as it re-computes their lit sets.
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator

import numpy as np

from eyeviz import EyevizError
from eyeviz.core.responses import KINDS_BY_MODEL
from eyeviz.dataset.embedded_eyes import LIT_CHECK_ROWS
from eyeviz.dataset.records import Dataset3D

__all__ = ["VALUE_MEMBERS", "check_kind", "with_values", "check_values", "check_value_rows"]

VALUE_MEMBERS = ("values_a", "values_b")
#: A stored value may differ from a re-computed one by this much (both certified to 1e-9).
TOLERANCE = 2e-9


def check_kind(model: str, kind: object) -> str:
    """The kind a data set of ``model`` eyes may store; EyevizError naming the ones it may."""
    kinds = KINDS_BY_MODEL.get(model, ())
    if kind not in kinds:
        raise EyevizError(
            f"responses of kind {kind!r} do not apply to {model} eyes "
            f"(they answer {' or '.join(kinds) if kinds else 'none yet'})"
        )
    return str(kind)


def with_values(chunks: Iterable[Dataset3D], eyes, kind: str) -> Iterator[Dataset3D]:
    """Each chunk with its values: ``eyes.responses`` on its balls, whose lit sets must be
    the chunk's (the same exact decision)."""
    for c in chunks:
        res = eyes.responses(c.x, c.y, c.z, c.g, kind=kind)
        for (ptr, idx, vals), e in zip(res, "ab", strict=True):
            same = np.array_equal(ptr, getattr(c, f"indptr_{e}")) and np.array_equal(
                idx, getattr(c, f"indices_{e}")
            )
            if not same:  # pragma: no cover - one exact decision behind both
                raise EyevizError(f"eye {e.upper()}: the responses' lit sets differ")
            setattr(c, f"values_{e}", vals)
        c.params = {**c.params, "responses": kind}
        yield c


def check_values(block: Dataset3D, start: int) -> str | None:
    """The first value of ``block`` (rows ``start ..``) not finite or outside [0, 1], as
    ``"values_a: row k: value v outside [0, 1]"`` (1-based), or None."""
    for e in "ab":
        vals = getattr(block, f"values_{e}")
        bad = ~((vals >= 0) & (vals <= 1))  # NaN too
        if bad.any():
            j = int(np.flatnonzero(bad)[0])
            ptr = getattr(block, f"indptr_{e}")
            row = start + int(np.searchsorted(ptr, j, side="right")) - 1 + 1
            return f"values_{e}: row {row}: value {float(vals[j])!r} outside [0, 1]"
    return None


def check_value_rows(eyes, block: Dataset3D, start: int, n: int, kind: str) -> str | None:
    """Re-compute the values of the rows of ``block`` that fall on the
    :data:`LIT_CHECK_ROWS` evenly spaced rows of the file; the first that differs by more
    than :data:`TOLERANCE`, or None. (Run after the lit sets were checked the same way.)"""
    want = np.unique(np.linspace(0, max(n - 1, 0), min(n, LIT_CHECK_ROWS)).astype(np.int64))
    rows = want[(want >= start) & (want < start + len(block))] - start
    if rows.size == 0:
        return None
    got = eyes.responses(block.x[rows], block.y[rows], block.z[rows], block.g[rows], kind=kind)
    for (ptr, _, vals), e in zip(got, "ab", strict=True):
        sptr, svals = getattr(block, f"indptr_{e}"), getattr(block, f"values_{e}")
        for j, i in enumerate(rows):
            stored = svals[sptr[i] : sptr[i + 1]]
            fresh = vals[ptr[j] : ptr[j + 1]]
            if stored.shape != fresh.shape or not (np.abs(stored - fresh) <= TOLERANCE).all():
                return (
                    f"row {start + int(i) + 1}: eye {e.upper()}'s {kind} responses are not "
                    f"the eyes' (re-computed from the stored ball)"
                )
    return None
