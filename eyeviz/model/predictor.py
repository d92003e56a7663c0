"""Estimators' answers for a scene's features (the predictions layer, DESIGN.md §3).

:class:`Predictor` keeps each estimator loaded once (``eyeviz.estimators`` is imported on
the first prediction, so torch only when the predictions layer is on and a network is
chosen). An estimator that cannot be loaded or cannot answer for the scene (weights
missing, another m) becomes a one-line message, never an exception. Used by the app and
by the vector export alike.
"""

from __future__ import annotations

import numpy as np

from eyeviz.core.geometry import intervals_to_bitmap
from eyeviz.model.scene import Scene
from eyeviz.model.state import SceneState

__all__ = ["Predictor", "Result"]

Result = tuple[np.ndarray, np.ndarray] | str


class Predictor:
    """name -> (r_hat, phi_hat) per feature, NaN outside the networks' domain."""

    ROW_CACHE_MAX = 4096  # answers kept per estimator (rows of distinct lit intervals)

    def __init__(self) -> None:
        self._loaded: dict[str, object] = {}
        self._failed: dict[str, str] = {}
        # estimator -> {a row's (m, LA, RA, LB, RB) bytes: (r_hat, phi_hat)}: a drag frame
        # asks again for every feature; only the dragged one has new bitmaps. Valid because
        # every registered estimator answers each row alone and deterministically
        # (eyeviz.estimators.checks: check_rows_independent, check_deterministic).
        self._rows: dict[str, dict[bytes, tuple[float, float]]] = {}

    def peek(self, name: str):
        """The estimator if loaded, the reason if it failed, None if not tried yet: never
        loads (the GUI thread asks this; loading runs on a worker, issue 12 item 9)."""
        if name in self._loaded:
            return self._loaded[name]
        return self._failed.get(name)

    def estimator(self, name: str):
        """The loaded estimator, or a str saying why it is unavailable."""
        if name in self._loaded:
            return self._loaded[name]
        if name in self._failed:
            return self._failed[name]
        from eyeviz import estimators

        try:
            est = estimators.load(name)
        except Exception as exc:  # noqa: BLE001  (any failure is shown, never raised)
            msg = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
            self._failed[name] = f"unavailable: {msg}"
            return self._failed[name]
        self._loaded[name] = est
        return est

    def predict_bitmaps(self, name: str, oa: np.ndarray, ob: np.ndarray) -> Result:
        est = self.estimator(name)
        if isinstance(est, str):
            return est
        try:
            r, phi = est.predict(oa, ob)
        except (ValueError, RuntimeError) as exc:
            return f"cannot answer: {str(exc).splitlines()[0]}"
        return np.asarray(r, dtype=np.float64), np.asarray(phi, dtype=np.float64)

    def predict(self, scene: Scene, state: SceneState) -> dict[str, Result]:
        """Each of the scene's estimators on the in-domain features' Omega (m/2 each)."""
        n, m = state.n, state.m
        ok = np.flatnonzero(state.in_domain()) if n else np.zeros(0, int)
        out: dict[str, Result] = {}
        if ok.size:
            oa = intervals_to_bitmap(state.LA[ok], state.RA[ok], m, m // 2)
            ob = intervals_to_bitmap(state.LB[ok], state.RB[ok], m, m // 2)
        keys: list[bytes] = []
        if ok.size:
            lr = np.column_stack([state.LA[ok], state.RA[ok], state.LB[ok], state.RB[ok]])
            lr = np.column_stack([np.full(ok.size, m), lr]).astype(np.int64)
            keys = [row.tobytes() for row in lr]
        for name in scene.estimators:
            r_hat, phi_hat = np.full(n, np.nan), np.full(n, np.nan)
            if ok.size:
                cache = self._rows.setdefault(name, {})
                if len(cache) + len(keys) > self.ROW_CACHE_MAX:
                    cache.clear()  # bounded: start again (this frame's rows recomputed)
                new = [j for j, k in enumerate(keys) if k not in cache]
                if new:
                    res = self.predict_bitmaps(name, oa[new], ob[new])
                    if isinstance(res, str):
                        out[name] = res
                        continue
                    for j, rr, pp in zip(new, res[0], res[1], strict=True):
                        cache[keys[j]] = (float(rr), float(pp))
                got = [cache[k] for k in keys]
                r_hat[ok] = [g[0] for g in got]
                phi_hat[ok] = [g[1] for g in got]
            else:
                est = self.estimator(name)
                if isinstance(est, str):
                    out[name] = est
                    continue
            out[name] = (r_hat, phi_hat)
        return out
