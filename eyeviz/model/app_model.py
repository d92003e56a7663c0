"""The app's model, for every eye model: the open scene, the selection, the cameras, the
trajectory player and drags written as generators.

One :class:`AppModel` serves the planar page and the 3D page (issue 37.2). What differs
between the eye models is data, one :class:`StateFunction` per scene kind in
:data:`STATE_FUNCTIONS`: how the scene's state is computed (``compute_state`` of the
planar eyes; ``checked_state`` of the spherical side, HEALPix or measured eyes, refused
beyond what the 3D view can hold), whether a drag frame updates only the moved rows
(planar: :func:`eyeviz.model.state.update_state`) or recomputes the state at once and
puts a refused move back (spherical), which coordinates a drag changes, and the planar
page's cached overlays (predictions, the ambiguity region; the 3D page computes its
predictions on the window's job runner, :mod:`eyeviz.app.predictions_layer3d`).
The gestures themselves differ in their mathematics and stay apart: a planar drag
(:func:`drag_feature`, :mod:`eyeviz.model.interactions`) works in the plane's
coordinates, a 3D drag (:mod:`eyeviz.model.app_model3d`) along a camera's lines of sight.

Qt-free (napari's split): the window feeds mouse events in and listens for changes. Every
edit goes through :meth:`AppModel.commit` (one undo step; the window installs a
QUndoStack-backed ``push``). Live changes (a drag, a played trajectory) go through
:meth:`AppModel.live` inside ``begin_live`` / ``end_live``: the whole gesture is ONE undo
step from the scene at ``begin_live`` to the scene at ``end_live``; nothing is rewound.
Gestures on the view (wheel, pan, fit) are in :mod:`eyeviz.model.interactions`, their maths
in :mod:`eyeviz.model.camera`.
"""

from __future__ import annotations

import importlib
import math
from collections.abc import Callable, Generator
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Generic, TypeVar

from eyeviz import EyevizError
from eyeviz.model.edits import feature_value
from eyeviz.model.layers import Ref
from eyeviz.model.player import TrajectoryPlayer
from eyeviz.model.scene import OKABE_ITO, Feature, Scene, View
from eyeviz.model.typed3d import KEYS, typed_ball

if TYPE_CHECKING:
    from eyeviz.model.predictor import Predictor

__all__ = [
    "AppModel",
    "MouseEvent",
    "DRAG_THRESHOLD_PX",
    "STATE_FUNCTIONS",
    "StateFunction",
    "drag_feature",
    "hit_test",
]

DRAG_THRESHOLD_PX = 4.0  # a press released closer than this to where it started is a click
HANDLE_PX = 14.0  # radius of the grab zone of the radius handle (drawn at this size)
BODY_PX = 8.0  # grab margin around a disc (and the minimum grab radius for tiny features)
DOT_PX = 6.0  # radius of a feature's centre dot (drawn 11 px wide): a disc is at least this


@dataclass(frozen=True)
class StateFunction:
    """What :class:`AppModel` needs of one scene kind (see the module docstring).

    ``compute(scene)`` is the scene's whole state (EyevizError, one line, for a scene the
    view cannot hold); ``update(state, scene, rows)`` the state after the features
    ``rows`` moved, or None: a drag frame recomputes the state at once and a refused move
    puts the feature back; ``check_edits``: an edit is refused before it is pushed when
    ``compute`` refuses its scene; ``live_keys``: what a drag changes; ``radius``: what g
    is in a message; ``predictions`` and ``ambiguity``: the planar page's cached overlays
    (``scene_predictions(scene, state, predictor)``, ``ambiguity_of(pair, x, y, g, box)``),
    None where the page draws none."""

    compute: Ref
    update: Ref | None = None
    check_edits: bool = False
    live_keys: tuple[str, ...] = ("x", "y", "g")
    radius: str = "feature radius"
    predictions: Ref | None = None
    ambiguity: Ref | None = None


#: One state function per scene kind (``Scene.kind``); hooks are ``"module:attribute"``
#: strings resolved on first use, so a planar session imports nothing of the spherical side.
STATE_FUNCTIONS: dict[str, StateFunction] = {
    "planar": StateFunction(
        "eyeviz.model.state:compute_state",
        update="eyeviz.model.state:update_state",
        predictions="eyeviz.model.predictor:scene_predictions",
        ambiguity="eyeviz.model.frame:ambiguity_of",
    ),
    "spherical": StateFunction(
        "eyeviz.model.state3d:checked_state",
        check_edits=True,
        live_keys=("x", "y", "z", "g"),
        radius="ball radius",
    ),
}


def _hook(ref: Ref) -> Any:
    """The function a ``"module:attribute"`` hook names, looked up at each call (a test's
    monkeypatch of the module's attribute is seen), or the hook itself."""
    if not isinstance(ref, str):
        return ref
    mod, _, attr = ref.partition(":")
    return getattr(importlib.import_module(mod), attr)


S = TypeVar("S")  # the state of the scene's kind (SceneState, SceneState3D)


@dataclass
class _Live:
    before: Scene
    text: str
    owner: object


@dataclass
class MouseEvent:
    """One mouse event in model (x, y) and widget pixel (px, py) coordinates."""

    type: str  # "press" | "move" | "release"
    x: float
    y: float
    px: float
    py: float


class AppModel(Generic[S]):
    """The open scene plus the selection, for a scene of any kind (the state function of
    its kind in :data:`STATE_FUNCTIONS`); notifies listeners ``fn(what, index)``:
    "scene", "feature" (a live change of feature ``index``), "selection", "view",
    "player", "predictions"."""

    def __init__(self, scene: Scene):
        self.scene = scene.copy()
        self.selected: int | None = 0 if scene.features else None
        self.listeners: list[Callable[[str, int | None], None]] = []
        self._state: S | None = None
        self._moved: set[int] = set()  # rows of _state whose feature moved since (live)
        self._predictions: dict | None = None
        self._ambiguity: tuple[dict | None] | None = None  # None: not computed yet
        self.predictor: Predictor | None = None  # made on first use
        self.push: Callable[..., None] = self._push_plain
        self._live: _Live | None = None
        self.inset_view = View((0.0, 0.0), 1.0)  # the magnified eyes (camera.fit_inset)
        self.inset_auto = True  # the inset follows h and l until the user pans/zooms it
        self.player = TrajectoryPlayer(self)
        # set by the window: load estimators off the GUI thread (issue 12 item 9)
        self.load_in_background: Callable[[object, list[str]], None] | None = None
        self.loading = ""  # a message while estimators load

    # --- state ------------------------------------------------------------------------
    @property
    def functions(self) -> StateFunction:
        """The state function of the open scene's kind."""
        return STATE_FUNCTIONS[self.scene.kind]

    @property
    def state(self) -> S:
        fns = self.functions
        if self._state is None:
            self._state = _hook(fns.compute)(self.scene)
        elif self._moved and fns.update is not None:  # a drag frame: only the moved rows
            # cleared only once the update succeeded: a refused value raises on every read
            self._state = _hook(fns.update)(self._state, self.scene, self._moved)
            self._moved = set()
        assert self._state is not None
        return self._state

    @property
    def predictions(self) -> dict:
        """estimator -> (r_hat, phi_hat) per feature, or a one-line reason; {} when the
        predictions layer is off (nothing is imported then) or the page draws none.
        Computed by :func:`eyeviz.model.predictor.scene_predictions`, kept until the scene
        changes."""
        ref = self.functions.predictions
        if ref is None or not self.scene.shows("predictions") or not self.scene.features:
            return {}
        if self._predictions is None:
            from eyeviz.model.predictor import Predictor

            if self.predictor is None:
                self.predictor = Predictor()
            p = self.predictor
            missing = [n for n in self.scene.estimators if p.peek(n) is None]
            if missing and self.load_in_background is not None:
                # the window loads them on a worker thread and notifies "predictions" when
                # done; meanwhile each estimator is a one-line "loading" message
                if not self.loading:
                    self.loading = f"loading {', '.join(missing)}…"
                    self.load_in_background(p, missing)
                return {n: self.loading for n in self.scene.estimators}
            self._predictions = _hook(ref)(self.scene, self.state, p)
        return self._predictions

    @property
    def ambiguity(self) -> dict | None:
        """The selected feature's ambiguity region (eyeviz.model.frame.ambiguity_of)."""
        i, ref = self.selected, self.functions.ambiguity
        if ref is None or not self.scene.shows("ambiguity"):
            return None
        if i is None or i >= len(self.scene.features):
            return None
        if self._ambiguity is None:
            f, v = self.scene.features[i], self.scene.view
            half = 1.5 * v.width + math.hypot(f.x - v.center[0], f.y - v.center[1])
            box = (v.center[0] - half, v.center[0] + half, v.center[1] - half, v.center[1] + half)
            self._ambiguity = (_hook(ref)(self.scene.eyes.pair(), f.x, f.y, f.g, box),)
        return self._ambiguity[0]

    def _notify(self, what: str, index: int | None = None) -> None:
        if what == "feature" and index is not None:  # live(): only a feature's place changed
            if self._state is not None and self.functions.update is not None:
                self._moved.add(index)  # (without an update, live() computed the state)
            self._predictions = None
            if index == self.selected:  # the region is the selected feature's alone
                self._ambiguity = None
        elif what not in ("view", "player", "selection"):
            self._state = None
            self._moved = set()
            self._predictions = None
            self._ambiguity = None
        elif what == "selection":
            self._ambiguity = None
        for fn in list(self.listeners):
            fn(what, index)

    def notify_view(self, which: str = "main") -> None:
        """A camera moved (no scene edit, no undo step; derived state is kept)."""
        self._notify("view", 0 if which == "main" else 1)

    # --- edits --------------------------------------------------------------------------
    def _push_plain(self, before: Scene, after: Scene, text: str, merge_key=None) -> None:
        self.set_scene(after)

    def set_scene(self, scene: Scene, what: str = "scene") -> None:
        """Replace the scene (open, undo and redo land here)."""
        self.scene = scene.copy()
        n = len(self.scene.features)
        if self.selected is not None and self.selected >= n:
            self.selected = n - 1 if n else None
        if self.selected is None and n:
            self.selected = 0
        self._notify(what)
        self.player.scene_changed()

    def commit(self, after: Scene, text: str, before: Scene | None = None, merge_key=None) -> None:
        """One undoable edit from ``before`` (default: the current scene) to ``after``.

        Consecutive edits with the same ``merge_key`` (wheel steps, nudges) merge into one
        step. Where the kind checks its edits, a scene its state function refuses raises
        EyevizError (one line) and changes nothing.
        """
        live = self._live
        if live is not None:  # an edit during a gesture or a play: close its step first
            self.end_live(owner=live.owner)
        before = self.scene.copy() if before is None else before
        if after != before:
            if self.functions.check_edits:
                _hook(STATE_FUNCTIONS[after.kind].compute)(after)
            self.push(before, after.copy(), text, merge_key)
        if live is not None and live.owner is self.player and self.player.playing:
            self.begin_live(live.text, owner=live.owner)

    # --- live edits (one undo step per gesture) ----------------------------------------
    @property
    def live_open(self) -> bool:
        return self._live is not None

    def begin_live(self, text: str, owner: object = None) -> None:
        """Start a gesture: edits through :meth:`live` until :meth:`end_live` are ONE undo
        step named ``text``. A gesture still open is ended first."""
        if self._live is not None:
            self.end_live()
        self._live = _Live(self.scene.copy(), text, owner)

    def end_live(self, owner: object = None) -> bool:
        """End the open gesture (only ``owner``'s if given): push one undo step from the
        scene at :meth:`begin_live` to the current one; True if something changed."""
        live = self._live
        if live is None or (owner is not None and live.owner is not owner):
            return False
        self._live = None
        after = self.scene.copy()
        if after == live.before:
            return False
        self.push(live.before, after, live.text, None)
        return True

    def finish_gestures(self) -> None:
        """Before undo/redo or a file change: stop the player, end any gesture."""
        self.player.stop()
        self.end_live()

    def live(self, index: int, **values: float) -> None:
        """Move or resize a feature during a gesture (part of the gesture's one undo step);
        only the coordinates of the kind's ``live_keys`` (x, y and g; x, y, z and g in
        space). Planar: the state then updates that row alone; spherical: the state is
        computed now, and a move it refuses puts the ball back (ValueError, one line)."""
        fns = self.functions
        bad = set(values) - set(fns.live_keys)
        if bad:
            keys = ", ".join(fns.live_keys[:-1]) + " or " + fns.live_keys[-1]
            raise ValueError(f"live() changes {keys} only, got {', '.join(sorted(bad))}")
        # refused before any change
        checked = {k: feature_value(k, v, fns.radius) for k, v in values.items()}
        f = self.scene.features[index]
        old = {k: getattr(f, k) for k in checked}
        for k, v in checked.items():
            setattr(f, k, v)
        if fns.update is None:
            self._state = None
            try:
                self.state  # noqa: B018 (computed now: a refused move leaves the ball where it was)
            except EyevizError as exc:
                for k, v in old.items():
                    setattr(f, k, v)
                self._state = None
                raise ValueError(str(exc)) from None
        self._notify("feature", index)

    def select(self, index: int | None) -> None:
        self.player.user_selected()
        if index != self.selected:
            self.selected = index
            self._notify("selection", index)

    def set_eyes(self, h: float, l: float, m: int) -> None:
        """New planar eye parameters; ValueError (naming the parameter) leaves the scene as
        it was."""
        after = self.scene.copy()
        after.eyes.h, after.eyes.l, after.eyes.m = h, l, m
        pair = after.eyes.pair()  # EyePair's checks (m <= core.bounds.MAX_M): raises first
        after.eyes.h, after.eyes.l, after.eyes.m = pair.h, pair.l, pair.m
        self.commit(after, "Change eyes")

    def set_feature(self, index: int, **values) -> None:
        after = self.scene.copy()
        f = after.features[index]
        for k, v in values.items():
            if k == "name":
                v = str(v).strip()
                if not v:
                    raise ValueError("name must not be empty")
                if any(o.name == v for j, o in enumerate(after.features) if j != index):
                    raise ValueError(f"another feature is already named {v!r}")
            else:
                v = feature_value(k, v, self.functions.radius)
            setattr(f, k, v)
        self.commit(after, f"Edit {f.name}")

    def move(self, index: int, centre, text: str, merge_key=None) -> None:
        """Put ball ``index`` at ``centre`` (x, y, z) as one undo step."""
        after = self.scene.copy()
        f = after.features[index]
        r = self.functions.radius
        f.x, f.y, f.z = (feature_value(k, v, r) for k, v in zip("xyz", centre, strict=True))
        self.commit(after, text, merge_key=merge_key)

    def type_value(self, index: int, key: str, text: str) -> None:
        """Ball ``index``'s coordinate ``key`` (x, y, z, g, r, az, el) typed as ``text``:
        one undo step (:func:`eyeviz.model.typed3d.typed_ball`); a bad value raises
        ValueError (one line) and changes nothing."""
        f = self.scene.features[index]
        x, y, z, g = typed_ball(f, key, text)
        after = self.scene.copy()
        a = after.features[index]
        a.x, a.y, a.z, a.g = x, y, z, g
        try:
            self.commit(after, f"Type {KEYS[key]} of {f.name}")
        except EyevizError as exc:
            raise ValueError(str(exc)) from None

    def _new_name(self, base: str) -> str:
        names = {f.name for f in self.scene.features}
        i = 1
        while f"{base} {i}" in names:
            i += 1
        return f"{base} {i}"

    def _copy_name(self, name: str) -> str:
        """ "feature 1" -> "feature 1 (copy)", then "(copy 2)", ...; a copy of a copy keeps
        one suffix ("a (copy)" -> "a (copy 2)")."""
        base = name
        if base.endswith(")") and " (copy" in base:
            base = base[: base.rindex(" (copy")]
        names = {f.name for f in self.scene.features}
        cand, k = f"{base} (copy)", 2
        while cand in names:
            cand, k = f"{base} (copy {k})", k + 1
        return cand

    def _append(self, f: Feature, text: str) -> None:
        """Add ``f`` (one undo step) and select it."""
        after = self.scene.copy()
        after.features.append(f)
        self.commit(after, text)
        self.select(len(self.scene.features) - 1)

    def _color(self) -> str:
        return OKABE_ITO[len(self.scene.features) % len(OKABE_ITO)]

    def add_feature(self, x: float, y: float, g: float | None = None) -> None:
        if g is None:
            g = max(self.scene.view.width / 80.0, 1e-6)
        f = Feature(self._new_name("feature"), float(x), float(y), float(g), self._color())
        self._append(f, "Add feature")

    def add_ball(self, x: float, y: float, z: float, g: float) -> None:
        """A ball (the 3D page's feature) at (x, y, z), radius g, named "ball N"."""
        self._append(Feature(self._new_name("ball"), x, y, g, self._color(), z), "Add ball")

    def duplicate_feature(self, index: int) -> None:
        f = self.scene.features[index]
        dup = Feature(self._copy_name(f.name), f.x + 2.5 * f.g, f.y, f.g, self._color(), f.z)
        self._append(dup, f"Duplicate {f.name}")

    def duplicate_ball(self, index: int) -> None:
        """The 3D page's duplicate: named "<name> copy N" (the planar page's names
        "<name> (copy)"), 2.5 g along x."""
        f = self.scene.features[index]
        name = self._new_name(f"{f.name} copy")
        dup = Feature(name, f.x + 2.5 * f.g, f.y, f.g, self._color(), f.z)
        self._append(dup, f"Duplicate {f.name}")

    def delete_feature(self, index: int) -> None:
        after = self.scene.copy()
        name = after.features.pop(index).name
        self.commit(after, f"Delete {name}")

    delete_ball = delete_feature

    def set_layer(self, layer: str, on: bool) -> None:
        after = self.scene.copy()
        if on and layer not in after.layers:
            after.layers.append(layer)
        elif not on and layer in after.layers:
            after.layers.remove(layer)
        self.commit(after, f"{'Show' if on else 'Hide'} {layer}")


def hit_test(scene: Scene, selected: int | None, x: float, y: float, units_per_px: float):
    """(index, "handle"|"body") of what lies under (x, y), or (None, None).

    Tolerances are in pixels (``units_per_px`` converts them): a disc is grabbed within
    BODY_PX of its rim (tiny discs within BODY_PX of their centre), the topmost (last)
    first. The selected feature's radius handle (at (x + g, y), drawn HANDLE_PX wide) is
    grabbable only where it is drawn apart from its disc's centre (g >= HANDLE_PX on
    screen), when the cursor is within HANDLE_PX of it, nearer to it than to the centre,
    and not inside another disc as drawn (at least its DOT_PX centre dot): zoomed out, a
    press on a neighbour selects the neighbour instead of resizing the selected feature
    (issue 12, item 3).
    """
    fs = scene.features
    u = max(units_per_px, 1e-300)
    body = None
    for i in range(len(fs) - 1, -1, -1):
        f = fs[i]
        if math.hypot(x - f.x, y - f.y) <= max(f.g, 0.0) + BODY_PX * u:
            body = i
            break
    if selected is not None and 0 <= selected < len(fs):
        f = fs[selected]
        d_handle = math.hypot(x - f.x - f.g, y - f.y)
        if (
            f.g / u >= HANDLE_PX
            and d_handle <= HANDLE_PX * u
            and d_handle < math.hypot(x - f.x, y - f.y)
            and not (
                body is not None
                and body != selected
                and math.hypot(x - fs[body].x, y - fs[body].y) <= max(fs[body].g, DOT_PX * u)
            )
        ):
            return selected, "handle"
    return (body, "body") if body is not None else (None, None)


def drag_feature(
    model: AppModel, event: MouseEvent, index: int, part: str
) -> Generator[None, MouseEvent, None]:
    """A whole drag of feature ``index`` (napari-style): press, moves, release.

    Send each following event with ``gen.send(event)``. Moving the body keeps the grab
    offset; the handle sets the radius to the cursor's distance from the centre. Under
    DRAG_THRESHOLD_PX of travel it is a click (select only); a drag is ONE undo step
    (``begin_live`` at the first real move, ``end_live`` at the release).
    """
    model.select(index)
    f0 = model.scene.features[index]
    f0 = Feature(f0.name, f0.x, f0.y, f0.g, f0.color)
    x0, y0, px0, py0 = event.x, event.y, event.px, event.py
    dragging = False
    event = yield
    try:
        while event.type == "move":
            if not dragging and math.hypot(event.px - px0, event.py - py0) >= DRAG_THRESHOLD_PX:
                dragging = True
                model.begin_live(("Move " if part == "body" else "Resize ") + f0.name)
            if dragging:
                if part == "body":
                    model.live(index, x=f0.x + (event.x - x0), y=f0.y + (event.y - y0))
                else:
                    g = math.hypot(event.x - f0.x, event.y - f0.y)
                    model.live(index, g=max(g, f0.g * 1e-3, 1e-9))
            event = yield
    finally:
        if dragging:
            model.end_live()
