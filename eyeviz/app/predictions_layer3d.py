"""The 3D view's predictions layer (:mod:`eyeviz.model.predictions3d`): the fast
estimators answer on every frame; the limit runs on the window's job runner after a drag,
for the latest ball only. A part of :class:`eyeviz.app.view3d.Scene3DHost` (its state:
``model``, ``actors``, ``predictor3d``, ``preds``, ``latest``, ``limit_jobs``, ``win``)."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from eyeviz.model.predictions3d import (
    LIMIT,
    Predictor3D,
    ball_key,
    domain_of,
    scene_predictions3d,
)

__all__ = ["Predictions3DLayer"]


class Predictions3DLayer:
    """The predictions layer's methods of the 3D page (see the module docstring)."""

    model: Any
    actors: Any
    win: Any
    predictor3d: Predictor3D | None
    preds: Any
    latest: Any
    limit_jobs: int
    active: bool
    _dirty: bool

    # the page's own (Scene3DHost)
    draw: Callable[[], None]
    refresh_panels: Callable[[], None]
    show_status: Callable[[], None]

    def _predictions(self) -> None:
        """The layer's content for the selected ball: the fast estimators now, the limit
        from the cache, or a job for it when no drag is open (latest key only)."""
        m, actors = self.model, self.actors
        assert m is not None and actors is not None
        if not m.scene.shows("predictions"):
            self.preds = None
            self.latest.want(None)
            actors.draw_predictions(None)
            return
        if self.predictor3d is None:
            self.predictor3d = Predictor3D()
        dragging = m.live_open
        preds = scene_predictions3d(
            m.scene, m.state, m.selected, self.predictor3d, limit="drag" if dragging else "cached"
        )
        self.preds = preds
        actors.draw_predictions(preds)
        wait = preds is not None and preds.answers.get(LIMIT) == "computing…"
        key = ball_key(m.state, preds.ball) if wait and preds is not None else None
        if self.latest.want(key):
            self._start_limit(key)

    def _start_limit(self, key: bytes | None) -> None:
        """A worker computes the limit for the selected ball, whose key is ``key``."""
        m = self.model
        assert m is not None and self.predictor3d is not None
        i = m.selected
        if key is None or i is None or ball_key(m.state, i) != key:
            self.latest.forget()  # the ball moved on: the next frame asks again
            return
        if self.predictor3d.cached(LIMIT, key) is not None:  # answered meanwhile
            self.latest.forget()
            self._dirty = True
            self.draw()
            return
        work = self.predictor3d.limit_job(domain_of(m.scene), m.state, i)
        if isinstance(work, str):
            self.latest.forget()
            return
        self.limit_jobs += 1
        predictor = self.predictor3d
        self.win.jobs.start(
            work,
            "limit3d: the posterior of the selected ball…",
            lambda res, k=key, p=predictor: self._limit_done(k, p, res),
            lambda exc, k=key: self._limit_failed(k, exc),
        )

    def _limit_done(self, key: bytes, predictor: Predictor3D, res) -> None:
        predictor.store_limit(key, res)
        if self.latest.finish(key) and self.active:  # still the ball shown: draw it
            self._dirty = True
            self.draw()
            self.refresh_panels()
        nxt = self.latest.start_pending()
        if nxt is not None and self.model is not None and self.active:
            self._start_limit(nxt)
        if self.active and not self.win.jobs.busy():  # the runner cleared the status line
            self.show_status()

    def _limit_failed(self, key: bytes, exc: BaseException) -> None:
        self.latest.finish(key)
        self.latest.forget()
        self.win.statusBar().showMessage(f"limit3d: {exc}", 8000)
