"""The trajectory player of Figure 14 as model state (no Qt): which feature plays, where.

The played feature is held by its name (names are unique in a scene, AppModel enforces
it), never by its index: deleting another feature cannot make the player animate a
neighbour, and deleting (or renaming) the played feature stops playback. A whole play is
one undo step (``AppModel.begin_live`` / ``end_live``). The window's timer only calls
:meth:`TrajectoryPlayer.tick`; the dock only displays :attr:`playing`.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:  # pragma: no cover
    from eyeviz.model.app_model import AppModel

__all__ = ["TrajectoryPlayer"]


class TrajectoryPlayer:
    """Play / pause / step a feature along ``path`` (an object with x, y, g, n)."""

    def __init__(self, model: AppModel):
        self.model = model
        self.feature: str | None = None  # the played feature's name
        self.playing = False
        self.pos = 0.0  # index along the path (fractional: a speed may be < 1 point a tick)
        self.speed = 4.0
        self.path = None
        self.message = ""
        self.gone = ""  # the played feature's name after its deletion, until a selection

    def index(self) -> int | None:
        """The played feature's current index in the scene, or None if it is gone."""
        if self.feature is None:
            return None
        for i, f in enumerate(self.model.scene.features):
            if f.name == self.feature:
                return i
        return None

    def set_path(self, path) -> None:
        if path is not self.path:
            self.path = path
            self.pos = 0.0

    def _choose(self) -> int | None:
        i = self.index()
        if i is None:
            sel = self.model.selected
            n = len(self.model.scene.features)
            i = sel if sel is not None and sel < n else (0 if n else None)
            self.feature = None if i is None else self.model.scene.features[i].name
        return i

    def start(self) -> bool:
        """Start playing the selected feature (or the one played before); False if there is
        no path or no feature (a reason in :attr:`message`)."""
        if self.playing:
            return True
        if self.path is None:
            self.message = "no trajectory to play"
            return False
        if self.gone and self.index() is None:
            # the played feature was deleted: Space does not pick another one by itself
            self.message = f"{self.gone} was deleted: select a feature to play it"
            return False
        i = self._choose()
        if i is None:
            self.message = "no feature to play"
            return False
        self.message = ""
        self.playing = True
        self.model.begin_live(f"Animate {self.feature}", owner=self)
        self.model._notify("player")
        return True

    def stop(self, reason: str = "") -> None:
        """Pause: the whole play becomes one undo step."""
        if not self.playing:
            return
        self.playing = False
        self.message = reason
        self.model.end_live(owner=self)
        self.model._notify("player")

    def toggle(self) -> bool:
        if self.playing:
            self.stop()
        else:
            self.start()
        return self.playing

    def step(self, points: float | None = None) -> tuple[float, float] | None:
        """Move the played feature ``points`` along the path (default: the speed); returns
        its new centre, or None (and stops) when the feature or the path is gone."""
        p = self.path
        if p is None or p.n == 0:
            self.stop("no trajectory to play")
            return None
        # outside a play, a first step picks the selected feature; a played feature that
        # was deleted is never replaced by another one behind the user's back
        i = self.index() if self.feature is not None else self._choose()
        if i is None:
            self.stop(f"{self.feature} was deleted: playback stopped")
            return None
        self.pos = (self.pos + (self.speed if points is None else points)) % p.n
        k = int(self.pos)
        x, y = float(p.x[k]), float(p.y[k])
        self.model.live(i, x=x, y=y, g=p.g)
        return x, y

    def tick(self) -> tuple[float, float] | None:
        """One timer tick while playing."""
        return self.step() if self.playing else None

    def scene_changed(self) -> None:
        """Called by the model after every scene replacement: stop if the feature left
        (and remember it: the next start waits for the user to select a feature)."""
        if self.playing and self.index() is None:
            self.gone = self.feature or ""
            self.stop(f"{self.feature} was deleted: playback stopped")
        elif self.gone and self.index() is not None:  # undo brought it back
            self.gone = ""

    def user_selected(self) -> None:
        """The user selected a feature: a start may play it (after a deletion too)."""
        self.gone = ""
