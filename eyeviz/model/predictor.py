"""Estimators' answers for a scene's features (the predictions layer, docs/contract.md).

:class:`Predictor` keeps each estimator loaded once (``eyeviz.estimators`` is imported on
the first prediction, so torch only when the predictions layer is on and a network is
chosen). An estimator that cannot be loaded or cannot answer for the scene (weights
missing, other eyes) becomes a one-line message, never an exception. :func:`scene_predictions`
is the one place a scene's predictions are computed: the app model, the Frame (and so the
vector export) call it, and both renderers only draw its answers.

Eye designs (issue 10 item 4). Every answer is for the scene's eyes (h, l, m):

- an estimator that answers for any eyes (its registry entry says ``any_design``:
  analytic, limit) is loaded for ``Domain(h, l, m)`` of the scene, with Table 4's r and g
  ranges, once per design (a cache keyed by name and design);
- an estimator made for one design (compact, bayes, paper: trained on the paper's
  h = 40, l = 20, m = 720) answers only for that design; for other eyes its result is
  the line ``"cannot answer: trained for h = 40, l = 20, m = 720"``, never a silent
  answer for the wrong eyes.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from eyeviz.core.geometry import intervals_to_bitmap
from eyeviz.core.validation import num
from eyeviz.model.scene import Scene
from eyeviz.model.state import SceneState, compute_state

__all__ = ["Predictor", "Result", "Design", "design_of", "scene_predictions", "trained_for"]

Result = tuple[np.ndarray, np.ndarray] | str
Design = tuple[float, float, int]  # (h, l, m)


def design_of(obj: Any) -> Design | None:
    """(h, l, m) of an EyePair, scene Eyes, Domain or (h, l, m) triple; None for None."""
    if obj is None:
        return None
    if isinstance(obj, tuple | list):
        h, l, m = obj  # noqa: E741  (the paper's name)
    else:
        h, l, m = obj.h, obj.l, obj.m  # noqa: E741
    return (float(h), float(l), int(m))


def trained_for(est: Any) -> str:
    """The short line for an estimator made for other eyes ("trained for h = 40, ...")."""
    d = est.domain
    return f"trained for h = {num(d.h)}, l = {num(d.l)}, m = {int(d.m)}"


def _any_design(name: str) -> bool:
    from eyeviz.estimators import registry

    try:
        return bool(registry.get(name).any_design)
    except Exception:  # noqa: BLE001  (unknown names fail in load, with their message)
        return False


class Predictor:
    """name -> (r_hat, phi_hat) per feature, NaN outside the estimators' domain.

    ``_loaded`` / ``_failed`` hold each estimator as first loaded (the paper's design for
    the any-design ones; the app reads them to know what is still to load);
    ``_designs`` holds the any-design estimators loaded for other eyes.
    """

    ROW_CACHE_MAX = 4096  # answers kept per estimator (rows of distinct lit intervals)

    def __init__(self) -> None:
        self._loaded: dict[str, object] = {}
        self._failed: dict[str, str] = {}
        self._designs: dict[tuple[str, Design], object] = {}
        self._kinds: dict[str, bool] = {}
        # (estimator, design) -> {a row's (m, LA, RA, LB, RB) bytes: (r_hat, phi_hat)}: a
        # drag frame asks again for every feature; only the dragged one has new bitmaps.
        # Valid because every registered estimator answers each row alone and
        # deterministically (eyeviz.estimators.checks: check_rows_independent,
        # check_deterministic).
        self._rows: dict[tuple[str, Design | None], dict[bytes, tuple[float, float]]] = {}

    def peek(self, name: str):
        """The estimator if loaded, the reason if it failed, None if not tried yet: never
        loads (the GUI thread asks this; loading runs on a worker, issue 12 item 9)."""
        if name in self._loaded:
            return self._loaded[name]
        return self._failed.get(name)

    def any_design(self, name: str) -> bool:
        """Whether ``name`` answers for any eyes (loaded per design)."""
        if name not in self._kinds:
            self._kinds[name] = _any_design(name)
        return self._kinds[name]

    def _load(self, name: str, **kw):
        from eyeviz import estimators

        try:
            return estimators.load(name, **kw)
        except Exception as exc:  # noqa: BLE001  (any failure is shown, never raised)
            msg = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
            return f"unavailable: {msg}"

    def estimator(self, name: str, design: Any = None):
        """The loaded estimator for ``design`` (h, l, m; None: as first loaded), or a str
        saying why it is unavailable. Fixed-design estimators ignore ``design`` here
        (see :meth:`design_note`)."""
        if name in self._failed:
            return self._failed[name]
        if name not in self._loaded:
            est = self._load(name)
            if isinstance(est, str):
                self._failed[name] = est
                return est
            self._loaded[name] = est
        base = self._loaded[name]
        d = design_of(design)
        dom = getattr(base, "domain", None)
        if d is None or dom is None or not self.any_design(name) or design_of(dom) == d:
            return base
        key = (name, d)
        if key not in self._designs:
            from eyeviz.core.domain import Domain

            try:
                domain = Domain(d[0], d[1], d[2], dom.r_min, dom.r_max, dom.g_max)
            except Exception as exc:  # noqa: BLE001
                return f"cannot answer: {str(exc).splitlines()[0]}"
            kw = {"prior": base.prior} if hasattr(base, "prior") else {}
            self._designs[key] = self._load(name, domain=domain, **kw)
        return self._designs[key]

    def design_note(self, name: str, design: Any) -> str | None:
        """ "trained for h = 40, l = 20, m = 720" when ``name`` was made for other eyes
        than ``design``, else None (also None when it cannot be loaded at all)."""
        d = design_of(design)
        if d is None or self.any_design(name):
            return None
        est = self.estimator(name)
        if isinstance(est, str) or getattr(est, "domain", None) is None:
            return None
        return None if design_of(est.domain) == d else trained_for(est)

    def predict_bitmaps(self, name: str, oa: np.ndarray, ob: np.ndarray, design=None) -> Result:
        """(r_hat, phi_hat) for half bitmaps ``oa``, ``ob`` of eyes ``design`` (an EyePair,
        Eyes, Domain or (h, l, m); None: the estimator's own), or a one-line reason."""
        est = self.estimator(name, design)
        if isinstance(est, str):
            return est
        note = self.design_note(name, design)
        if note is not None:
            return f"cannot answer: {note}"
        try:
            r, phi = est.predict(oa, ob)
        except (ValueError, RuntimeError) as exc:
            return f"cannot answer: {str(exc).splitlines()[0]}"
        return np.asarray(r, dtype=np.float64), np.asarray(phi, dtype=np.float64)

    def predict(self, scene: Scene, state: SceneState) -> dict[str, Result]:
        """Each of the scene's estimators on the in-domain features' Omega (m/2 each), for
        the scene's eyes."""
        n, m = state.n, state.m
        design = design_of(scene.eyes)
        ok = np.flatnonzero(state.in_domain()) if n else np.zeros(0, int)
        out: dict[str, Result] = {}
        if ok.size:
            LA, RA, LB, RB = state.intervals()
            lr = np.column_stack([np.full(ok.size, m), LA[ok], RA[ok], LB[ok], RB[ok]])
            keys = [row.tobytes() for row in lr.astype(np.int64)]
        omega: dict[tuple[int, ...], tuple[np.ndarray, np.ndarray]] = {}  # rows -> bitmaps
        for name in scene.estimators:
            # an estimator that cannot answer for these eyes says so before any bitmap
            # is made (what predict_bitmaps would answer, without the m/2-wide rows)
            est = self.estimator(name, design)
            if isinstance(est, str):
                out[name] = est
                continue
            note = self.design_note(name, design)
            if note is not None:
                out[name] = f"cannot answer: {note}"
                continue
            r_hat, phi_hat = np.full(n, np.nan), np.full(n, np.nan)
            if ok.size:
                cache = self._rows.setdefault((name, design), {})
                if len(cache) + len(keys) > self.ROW_CACHE_MAX:
                    cache.clear()  # bounded: start again (this frame's rows recomputed)
                new = [j for j, k in enumerate(keys) if k not in cache]
                if new:
                    # Omega (m/2 each) of the rows the cache lacks only (a drag frame at
                    # m = 36,000 spent ~2 ms on the bitmaps of every feature)
                    if tuple(new) not in omega:
                        f = ok[new]
                        omega[tuple(new)] = (
                            intervals_to_bitmap(LA[f], RA[f], m, m // 2),
                            intervals_to_bitmap(LB[f], RB[f], m, m // 2),
                        )
                    oa, ob = omega[tuple(new)]
                    res = self.predict_bitmaps(name, oa, ob, design)
                    if isinstance(res, str):
                        out[name] = res
                        continue
                    for j, rr, pp in zip(new, res[0], res[1], strict=True):
                        cache[keys[j]] = (float(rr), float(pp))
                got = [cache[k] for k in keys]
                r_hat[ok] = [g[0] for g in got]
                phi_hat[ok] = [g[1] for g in got]
            out[name] = (r_hat, phi_hat)
        return out


def scene_predictions(
    scene: Scene, state: SceneState, predictor: Predictor | None = None
) -> dict[str, Result]:
    """Each of the scene's estimators on its in-domain features (:meth:`Predictor.predict`):
    name -> (r_hat, phi_hat) per feature (NaN outside the domain) or a one-line reason;
    {} when the scene does not show the predictions layer or has no feature.

    The one function that computes a scene's predictions: :class:`eyeviz.model.app_model.
    AppModel` caches its answer, :func:`eyeviz.model.frame.build_frame` carries it in the
    Frame, and the renderers draw the Frame. ``state`` without the intervals or the readout
    is recomputed for them; ``predictor`` (a new one when None) keeps the estimators loaded.
    """
    if not scene.shows("predictions") or not scene.features:
        return {}
    if state.LA is None or state.in_bfv is None:
        state = compute_state(scene, ["predictions"])
    predictor = Predictor() if predictor is None else predictor
    return predictor.predict(scene, state)
