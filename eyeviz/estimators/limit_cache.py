"""The planar limit's cache of answered keys (:class:`eyeviz.estimators.limit.LimitEstimator`):
a bounded, least-recently-used map from packed key codes to answers, looked up a batch at
a time."""

from __future__ import annotations

import numpy as np


class _KeyCache:
    """A bounded map from packed int64 key codes to (r, phi, empty), built for batches.

    Most entries sit in sorted arrays, so a batch of rows is looked up with one
    ``searchsorted`` (no Python loop, no ``np.unique`` of the rows: the cached path is as
    cheap as the bayes table lookup). New entries go to a small dict first and are merged
    in bulk (one key at a time stays cheap). Each entry carries the tick of its last use;
    beyond ``size`` entries the least recently used are dropped, down to 7/8 of ``size``.
    """

    def __init__(self, size: int) -> None:
        self.size = max(1, int(size))
        self.codes = np.zeros(0, np.int64)
        self.values = np.zeros((0, 3))  # r, phi, empty (0/1)
        self.used = np.zeros(0, np.int64)
        self.recent: dict[int, tuple[float, float, float, int]] = {}
        self.tick = 0

    def __len__(self) -> int:
        return self.codes.size + len(self.recent)

    def lookup(self, code: np.ndarray) -> tuple[np.ndarray, np.ndarray, int]:
        """(values (N, 3), found (N,), distinct keys found) for the rows' codes."""
        self.tick += 1
        vals = np.empty((code.size, 3))
        found = np.zeros(code.size, bool)
        hits = 0
        if self.codes.size:
            # the rows' codes searched in sorted order (a sort plus a monotone search is
            # ~3x cheaper than a binary search from scratch per row, measured on 10^5 rows)
            order = np.argsort(code)
            at = np.searchsorted(self.codes, code[order])
            np.minimum(at, self.codes.size - 1, out=at)
            i = np.empty(code.size, np.intp)
            i[order] = at
            found = self.codes[i] == code
            vals = self.values[i]
            self.used[i[found]] = self.tick
            # distinct keys found: for a few rows, the changes along their (sorted)
            # entries; for many, the entries marked with this call's tick (no bincount)
            if code.size < self.codes.size // 4:
                at = at[found[order]]
                hits = int(at.size and 1 + np.count_nonzero(at[1:] != at[:-1]))
            else:
                hits = int(np.count_nonzero(self.used == self.tick))
        if self.recent and not found.all():
            miss = np.flatnonzero(~found)
            if miss.size == 1:  # one row (np.unique costs more than the rest here)
                uniq, inv = code[miss], np.zeros(1, np.intp)
            else:
                uniq, inv = np.unique(code[miss], return_inverse=True)
            got = np.zeros(uniq.size, bool)
            for j, c in enumerate(uniq.tolist()):
                hit = self.recent.get(c)
                if hit is not None:
                    self.recent[c] = (*hit[:3], self.tick)
                    vals[miss[inv == j]] = hit[:3]
                    got[j] = True
            found[miss] = got[inv]
            hits += int(got.sum())
        return vals, found, hits

    def get(self, code: int) -> tuple[float, float, float] | None:
        """One key's (r, phi, empty), marked used, or None; the call's tick must be new
        (as :meth:`lookup` makes it)."""
        if self.codes.size:
            i = int(np.searchsorted(self.codes, code))
            if i < self.codes.size and self.codes[i] == code:
                self.used[i] = self.tick
                r, phi, empty = self.values[i].tolist()
                return r, phi, empty
        hit = self.recent.get(code)
        if hit is None:
            return None
        self.recent[code] = (*hit[:3], self.tick)
        return hit[:3]

    def insert_one(self, code: int, value: tuple[float, float, float]) -> None:
        """One key absent from the cache, with its (r, phi, empty)."""
        self.recent[code] = (*value, self.tick)
        if len(self.recent) > min(4096, self.size // 8) or len(self) > self.size:
            self._merge()

    def insert(self, codes: np.ndarray, values: np.ndarray) -> None:
        """Distinct codes absent from the cache, with their (r, phi, empty) rows."""
        if codes.size > 256:  # a batch: straight into the sorted arrays (no Python loop)
            self._merge(codes, values)
            return
        for c, v in zip(codes.tolist(), values.tolist(), strict=True):
            self.recent[c] = (v[0], v[1], v[2], self.tick)
        if len(self.recent) > min(4096, self.size // 8) or len(self) > self.size:
            self._merge()

    def _merge(self, new_codes=None, new_values=None) -> None:
        rc = np.fromiter(self.recent.keys(), np.int64, len(self.recent))
        rv = np.array([v[:3] for v in self.recent.values()]).reshape(-1, 3)
        ru = np.fromiter((v[3] for v in self.recent.values()), np.int64, len(self.recent))
        self.recent = {}
        parts = [(self.codes, self.values, self.used), (rc, rv, ru)]
        if new_codes is not None:
            parts.append((new_codes, new_values, np.full(new_codes.size, self.tick)))
        codes, values, used = (np.concatenate(a) for a in zip(*parts, strict=True))
        if codes.size > self.size:  # drop the least recently used, down to 7/8 of size
            keep = np.argpartition(-used, self.size - self.size // 8 - 1)
            keep = keep[: max(1, self.size - self.size // 8)]
            codes, values, used = codes[keep], values[keep], used[keep]
        order = np.argsort(codes)
        self.codes, self.values, self.used = codes[order], values[order], used[order]
