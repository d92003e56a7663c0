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

    def __init__(self) -> None:
        self._loaded: dict[str, object] = {}
        self._failed: dict[str, str] = {}

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
        for name in scene.estimators:
            r_hat, phi_hat = np.full(n, np.nan), np.full(n, np.nan)
            if ok.size:
                res = self.predict_bitmaps(name, oa, ob)
                if isinstance(res, str):
                    out[name] = res
                    continue
                r_hat[ok], phi_hat[ok] = res
            else:
                est = self.estimator(name)
                if isinstance(est, str):
                    out[name] = est
                    continue
            out[name] = (r_hat, phi_hat)
        return out
