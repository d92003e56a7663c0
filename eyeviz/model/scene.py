"""Scenes: what the app shows and what a figure exports (docs/contract.md, scene files).

A :class:`Scene` is plain data: the eye pair's parameters (h, l, m of Table 3), circular
features (name, centre, radius g, colour), the layers to show, the estimators of the
predictions layer, the view and an optional trajectory (Figure 14). It is read from and
written to TOML; every rule is checked at this boundary and a broken one raises
:class:`SceneError` naming the file, the key (with its line when it can be found) and the
rule.

Bounds (issue 13, :mod:`eyeviz.files.limits`): a scene file is a regular file of at most
MAX_SCENE_BYTES; m within the model's one bound (:data:`eyeviz.core.bounds.MAX_M`, as for
every entry point); at most MAX_FEATURES features; coordinates, radii and the
view width within [-MAX_SCENE_COORD, MAX_SCENE_COORD] (the view width at least
MIN_VIEW_WIDTH); names without control characters (a newline or NUL could never be saved
and would break an SVG) and at most MAX_NAME_CHARS long.

Spherical scenes (issue 22, docs/spherical.md): ``[eyes] h, l, nside`` (instead of m)
makes the scene's eyes the HEALPix pair :class:`eyeviz.core.geometry3d.EyePair3D`
(:meth:`Eyes.model`); a scene giving both m and nside is refused (no m and no nside is the
planar default, m = 720, as before). Features carry ``z`` (default 0.0), written only in a
spherical scene, so a planar scene loads and saves exactly as before; a planar feature with
z != 0 is refused. nside is bounded by :func:`eyeviz.core.bounds.check_nside`, z like x and
y. A spherical scene may show only the layers in :data:`SPHERICAL_LAYERS` (eyes, features,
bfv, bitmaps, readout, labels, and in the app's 3D view tangents: the tangent cones from
each eye centre to each ball, and plane: the plane z = 0, a layer of spherical scenes only,
:data:`SPHERICAL_ONLY`; and predictions: the spherical estimators' answers for one ball,
:mod:`eyeviz.model.predictions3d`; and responses: each lit facet shaded by its graded
response, :mod:`eyeviz.model.responses3d`); the planar-only layers (sectors, ambiguity, posterior,
trajectory, and any registered layer) and a ``[trajectory]`` table are refused in one line.

Measured eyes (docs/measured.md): ``[eyes] file = "..."`` (and ``units``) names an eye file,
resolved against the scene file's folder and written back relative to the folder a scene
is saved to (:mod:`eyeviz.model.scene_eyes`); such a scene is on the spherical side too
(balls in millimetres) and may show the ``cones`` layer (the selected ball's lit
acceptance cones), not ``predictions`` (:data:`LAYER_KINDS`).

This module imports the standard library and tomli_w only (no Qt, VTK or torch).

It is over 400 lines because every rule of the scene contract is checked in one place
(:class:`_Checker`, :func:`_scene_from_doc`, :func:`_line_of`) beside the writer that must
round-trip it (``loads(dumps(s)) == s``); split, the rules and the writer would drift apart.
"""

from __future__ import annotations

import copy
import math
import os
import re
import tomllib
import unicodedata
from dataclasses import dataclass, field
from pathlib import Path

import tomli_w

from eyeviz import EyevizError
from eyeviz.files import limits
from eyeviz.files.atomic import atomic_output
from eyeviz.model.layers import applies, layer, layer_names
from eyeviz.model.scene_eyes import SIDES, SPACE_SIDE, Eyes, eyes_doc, eyes_from_table
from eyeviz.model.steps import Step, check_steps, step_doc

__all__ = [
    "OKABE_ITO",
    "SPHERICAL_LAYERS",
    "TRAJECTORY_KINDS",
    "Eyes",
    "Feature",
    "Scene",
    "SceneError",
    "Trajectory",
    "View",
    "dumps",
    "load",
    "loads",
    "save",
]

TRAJECTORY_KINDS = ("horizontal", "circular", "vertical")
# Okabe & Ito (2008) colour-blind-safe palette, black left out (it is the eyes' ink).
OKABE_ITO = ("#D55E00", "#0072B2", "#009E73", "#E69F00", "#CC79A7", "#56B4E9", "#F0E442")
DEFAULT_LAYERS = ["eyes", "bfv", "features", "bitmaps", "readout"]
#: The layers a spherical scene may show (see the module docstring), in the order of the
#: 3D page's layer menu: the layers of the table (eyeviz.model.layers.LAYERS) that apply
#: to HEALPix or measured eyes (a test holds the two equal).
SPHERICAL_LAYERS = (
    "eyes", "features", "bfv", "bitmaps", "readout", "labels", "tangents", "plane", "predictions",
    "cones", "responses",
)  # fmt: skip
#: The estimators of a spherical scene's predictions layer when its file names none (the
#: planar scenes' default is compact; a spherical scene naming a planar one is refused by
#: eyeviz.model.predictions3d.check_estimators).
SPHERICAL_ESTIMATORS = SPACE_SIDE.estimators
#: Layers of spherical scenes only (their table entries apply to no planar eyes).
SPHERICAL_ONLY = tuple(n for n in SPHERICAL_LAYERS if not applies(n, "planar"))
#: The spherical side's layers that apply to some eye models only (the others: to both),
#: as their table entries state (``LayerSpec.kinds``): the estimators' answers to HEALPix
#: eyes (no estimator of measured eyes in the app yet), the lit acceptance cones to
#: measured eyes (a HEALPix facet has no lens).
LAYER_KINDS: dict[str, tuple[str, ...]] = {
    n: k
    for n in SPHERICAL_LAYERS
    if len(k := tuple(x for x in layer(n).kinds if SIDES[x].in_space)) == 1
}


def layer_applies(layer: str, kind: str) -> bool:
    """Whether a spherical-side ``layer`` applies to eyes of model ``kind`` (its table
    entry's ``kinds``)."""
    return applies(layer, kind)


_COLOR = re.compile(r"^#[0-9a-fA-F]{6}$")
#: Bounds of what a scene may ask the app to draw (see the module docstring).
MAX_SCENE_COORD = 1e12
MIN_VIEW_WIDTH = 1e-6
MAX_STRINGS = 100


def _short(v, n: int = 60) -> str:
    t = repr(v)
    return t if len(t) <= n else t[: n - 3] + "..."


def _bad_text(s: str) -> str | None:
    """Why ``s`` cannot be a name or title (None when it can)."""
    if len(s) > limits.MAX_NAME_CHARS:
        return f"longer than {limits.MAX_NAME_CHARS} characters ({len(s)})"
    for ch in s:
        if unicodedata.category(ch) in ("Cc", "Cs") or ch in "\u2028\u2029":
            return f"contains the control character {ch!r}"
    return None


class SceneError(EyevizError):
    """A scene file or value breaks a rule; the message names file, key and rule."""


@dataclass
class Feature:
    """A circular feature of radius g centred at (x, y) (Section 3, Prop. 2)."""

    name: str
    x: float
    y: float
    g: float
    color: str = "#d62728"
    z: float = 0.0  # a ball's height above the plane z = 0 (spherical scenes only)


@dataclass
class View:
    """The visible region: centre (x, y) and width in model units."""

    center: tuple[float, float] = (0.0, 2500.0)
    width: float = 8000.0


@dataclass
class Trajectory:
    """A Figure 14 trajectory at ``distance`` from the origin for a feature of radius g."""

    kind: str
    distance: float
    g: float


@dataclass
class Scene:
    eyes: Eyes = field(default_factory=Eyes)
    features: list[Feature] = field(default_factory=list)
    layers: list[str] = field(default_factory=lambda: list(DEFAULT_LAYERS))
    estimators: list[str] = field(default_factory=lambda: ["compact"])
    view: View = field(default_factory=View)
    title: str = ""
    trajectory: Trajectory | None = None
    steps: list[Step] = field(default_factory=list)  # a lecture's steps (eyeviz.model.steps)

    def copy(self) -> Scene:
        """A deep copy, field by field (issue 25: ``copy.deepcopy`` took ~139 ms at 10^4
        features, this ~4 ms; every undo step holds two). Nothing is shared with ``self``:
        the features, lists, view, trajectory and steps are new objects (their fields are
        immutable values: str, float, int, tuple)."""
        t = self.trajectory
        return Scene(
            self.eyes.copy(),
            [Feature(f.name, f.x, f.y, f.g, f.color, f.z) for f in self.features],
            list(self.layers),
            list(self.estimators),
            View(copy.copy(self.view.center), self.view.width),
            self.title,
            None if t is None else Trajectory(t.kind, t.distance, t.g),
            [copy.deepcopy(st) for st in self.steps],
        )

    def shows(self, layer: str) -> bool:
        return layer in self.layers

    @property
    def in_space(self) -> bool:
        """Whether the scene's features are balls in space (HEALPix or measured eyes: the
        3D page, figure3d), not discs in the plane (the side's :class:`Side`)."""
        return self.eyes.spec.in_space

    @property
    def kind(self) -> str:
        """``"planar"`` or ``"spherical"``: the side of the scene's eyes (HEALPix and
        measured eyes are both spherical: balls in space; ``eyes.kind`` names the model)."""
        return self.eyes.side


# --- validation ------------------------------------------------------------------------


class _Checker:
    """Checks one parsed TOML document; errors name source, key, line and rule."""

    def __init__(self, text: str, source: str):
        self.text = text
        self.source = source

    def fail(self, key: str, rule: str) -> SceneError:
        rule = " ".join(rule.split())
        line = _line_of(self.text, key)
        where = f"{self.source}:{line}" if line else self.source
        return SceneError(f"{where}: {key}: {rule}")

    def table(self, doc: dict, key: str, required: bool = False) -> dict:
        if key not in doc:
            if required:
                raise self.fail(key, "missing table")
            return {}
        val = doc[key]
        if not isinstance(val, dict):
            raise self.fail(key, "must be a table")
        return val

    def keys(self, tab: dict, prefix: str, allowed: tuple[str, ...]) -> None:
        for k in tab:
            if k not in allowed:
                raise self.fail(f"{prefix}{k}", f"unknown key (allowed: {', '.join(allowed)})")

    def number(self, tab: dict, key: str, prefix: str, default=None, rule: str = "") -> float:
        if key not in tab:
            if default is None:
                raise self.fail(f"{prefix}{key}", f"missing ({rule or 'a number'})")
            return default
        v = tab[key]
        if isinstance(v, bool) or not isinstance(v, int | float):
            raise self.fail(f"{prefix}{key}", f"must be a number, got {_short(v)}")
        if isinstance(v, int) and abs(v) > MAX_SCENE_COORD:
            raise self.fail(f"{prefix}{key}", f"must be within +-{MAX_SCENE_COORD:g}")
        if not math.isfinite(v):
            raise self.fail(f"{prefix}{key}", f"must be finite, got {v!r}")
        if abs(v) > MAX_SCENE_COORD:
            raise self.fail(f"{prefix}{key}", f"must be within +-{MAX_SCENE_COORD:g}, got {v!r}")
        return float(v)

    def string(self, tab: dict, key: str, prefix: str, default=None) -> str:
        if key not in tab:
            if default is None:
                raise self.fail(f"{prefix}{key}", "missing (a string)")
            return default
        v = tab[key]
        if not isinstance(v, str):
            raise self.fail(f"{prefix}{key}", f"must be a string, got {_short(v)}")
        why = _bad_text(v)
        if why:
            raise self.fail(f"{prefix}{key}", f"{_short(v)} {why}")
        return v

    def strings(self, tab: dict, key: str, prefix: str, default: list[str]) -> list[str]:
        if key not in tab:
            return list(default)
        v = tab[key]
        if not isinstance(v, list) or not all(isinstance(s, str) for s in v):
            raise self.fail(f"{prefix}{key}", f"must be a list of strings, got {_short(v)}")
        if len(v) > MAX_STRINGS:
            raise self.fail(f"{prefix}{key}", f"more than {MAX_STRINGS} entries")
        for s in v:
            why = _bad_text(s)
            if why:
                raise self.fail(f"{prefix}{key}", f"{_short(s)} {why}")
        return list(v)


def _line_of(text: str, key: str) -> int | None:
    """1-based line of ``key`` ("eyes.m", "features[2].g", "layers.show") in TOML text."""
    m = re.fullmatch(r"(\w+)(?:\[(\d+)\])?(?:\.(\w+))?", key)
    if not m:
        return None
    table, index, name = m.group(1), m.group(2), m.group(3)
    current, count = None, -1
    for no, raw in enumerate(text.splitlines(), 1):
        line = raw.strip()
        head = re.fullmatch(r"\[\[\s*(\w+)\s*\]\]|\[\s*(\w+)\s*\]", line.split("#")[0].strip())
        if head:
            current = head.group(1) or head.group(2)
            if head.group(1) == table:
                count += 1
            if name is None and current == table and (index is None or count == int(index)):
                return no
            continue
        key_here = re.match(r"(\w+)\s*=", line)
        if not key_here:
            continue
        if current is None and name is None and key_here.group(1) == table:
            return no
        if (
            current == table
            and name is not None
            and key_here.group(1) == name
            and (index is None or count == int(index))
        ):
            return no
    return None


# long: every table of a scene file read in order, each key checked at the boundary with its own
# one-line error
def _scene_from_doc(doc: dict, text: str, source: str, base: Path | None) -> Scene:
    c = _Checker(text, source)
    c.keys(
        doc,
        "",
        ("title", "eyes", "features", "layers", "predictions", "view", "trajectory", "steps"),
    )
    title = c.string(doc, "title", "", default="")

    eyes = eyes_from_table(c, c.table(doc, "eyes"), base)
    side = eyes.spec  # what the scene's side decides (eyeviz.model.scene_eyes.SIDES)
    raw_features = doc.get("features", [])
    if not isinstance(raw_features, list):
        raise c.fail("features", "must be an array of tables ([[features]])")
    if len(raw_features) > limits.MAX_FEATURES:
        raise c.fail("features", f"{len(raw_features)} features, more than {limits.MAX_FEATURES}")
    features, names = [], set()
    for i, ft in enumerate(raw_features):
        p = f"features[{i}]."
        if not isinstance(ft, dict):
            raise c.fail(f"features[{i}]", "must be a table")
        c.keys(ft, p, ("name", "x", "y", "z", "g", "color"))
        name = c.string(ft, "name", p, default=f"feature {i + 1}")
        if not name.strip():
            raise c.fail(f"{p}name", "must not be empty")
        if name in names:
            raise c.fail(f"{p}name", f"duplicate feature name {name!r}")
        names.add(name)
        x = c.number(ft, "x", p, rule="centre x in model units")
        y = c.number(ft, "y", p, rule="centre y in model units")
        z = c.number(ft, "z", p, default=0.0)
        if z != 0.0 and not side.in_space:
            raise c.fail(
                f"{p}z",
                f"feature {name!r} has z = {z!r}, but a planar scene's features lie on "
                "z = 0 (give [eyes] nside or file for eyes in space)",
            )
        g = c.number(ft, "g", p, rule="radius g > 0")
        if g <= 0:
            raise c.fail(f"{p}g", f"feature radius must be > 0, got {g!r}")
        color = c.string(ft, "color", p, default=OKABE_ITO[i % len(OKABE_ITO)])
        if not _COLOR.match(color):
            raise c.fail(f"{p}color", f"must be a colour '#rrggbb', got {color!r}")
        features.append(Feature(name, x, y, g, color, z + 0.0))  # -0.0 -> 0.0

    layers_t = c.table(doc, "layers")
    c.keys(layers_t, "layers.", ("show",))
    layers = c.strings(layers_t, "show", "layers.", DEFAULT_LAYERS)
    # the layer table (eyeviz.model.layers), registered layers too: a spherical scene
    # knows them all (and refuses the planar-only ones below, in one line saying so)
    known = layer_names() if side.in_space else layer_names("planar")
    for name in layers:
        if name not in known:
            raise c.fail("layers.show", f"unknown layer {name!r} (known: {', '.join(known)})")
    if len(set(layers)) != len(layers):
        raise c.fail("layers.show", "a layer is named twice")
    if side.in_space:
        for name in layers:
            if name not in SPHERICAL_LAYERS:
                raise c.fail(
                    "layers.show",
                    f"layer {name!r} is planar-only; a spherical scene shows "
                    f"{', '.join(SPHERICAL_LAYERS)}",
                )
            if not layer_applies(name, eyes.kind):
                raise c.fail(
                    "layers.show",
                    f"layer {name!r} applies to {' and '.join(LAYER_KINDS[name])} eyes, "
                    f"not to the scene's {eyes.kind} eyes",
                )

    pred_t = c.table(doc, "predictions")
    c.keys(pred_t, "predictions.", ("estimators",))
    default = list(side.estimators)
    estimators = c.strings(pred_t, "estimators", "predictions.", default)
    if not estimators and "predictions" in layers:
        raise c.fail("predictions.estimators", "needs at least one estimator name")

    view_t = c.table(doc, "view")
    c.keys(view_t, "view.", ("center", "width"))
    center = view_t.get("center", [0.0, 2500.0])
    if (
        not isinstance(center, list)
        or len(center) != 2
        or not all(isinstance(v, int | float) and not isinstance(v, bool) for v in center)
        or not all(abs(v) <= MAX_SCENE_COORD for v in center)
    ):
        raise c.fail(
            "view.center",
            f"must be [x, y] (two numbers within +-{MAX_SCENE_COORD:g}), got {_short(center)}",
        )
    width = c.number(view_t, "width", "view.", default=8000.0)
    if not width >= MIN_VIEW_WIDTH:
        raise c.fail("view.width", f"must be >= {MIN_VIEW_WIDTH:g}, got {width!r}")
    view = View((float(center[0]), float(center[1])), width)

    trajectory = None
    if "trajectory" in doc and not side.trajectory:
        raise c.fail("trajectory", "a spherical scene has no trajectory (Figure 14 is planar)")
    if "trajectory" in doc:
        tt = c.table(doc, "trajectory")
        c.keys(tt, "trajectory.", ("kind", "distance", "g"))
        kind = c.string(tt, "kind", "trajectory.")
        if kind not in TRAJECTORY_KINDS:
            kinds = ", ".join(TRAJECTORY_KINDS)
            raise c.fail("trajectory.kind", f"must be one of {kinds}, got {kind!r}")
        dist = c.number(tt, "distance", "trajectory.", rule="distance > 0")
        if dist <= 0:
            raise c.fail("trajectory.distance", f"must be > 0, got {dist!r}")
        tg = c.number(tt, "g", "trajectory.", rule="feature radius g > 0")
        if tg <= 0:
            raise c.fail("trajectory.g", f"must be > 0, got {tg!r}")
        trajectory = Trajectory(kind, dist, tg)

    steps = []
    if "steps" in doc:
        step_layers = (
            tuple(n for n in SPHERICAL_LAYERS if layer_applies(n, eyes.kind))
            if side.in_space
            else known
        )
        steps = check_steps(doc["steps"], c.fail, step_layers, sorted(names), _bad_text, side.name)
        if not estimators and any("predictions" in st.layers for st in steps):
            raise c.fail("predictions.estimators", "a step shows predictions: name an estimator")

    return Scene(eyes, features, layers, estimators, view, title, trajectory, steps)


# --- public I/O ------------------------------------------------------------------------


def loads(text: str, source: str = "<string>", base: str | os.PathLike | None = None) -> Scene:
    """Parse and validate a scene from TOML text; ``source`` names it in errors, ``base``
    is the folder a relative ``[eyes] file`` is resolved in (the working folder if None)."""
    if len(text) > limits.MAX_SCENE_BYTES:
        raise SceneError(f"{source}: more than {limits.MAX_SCENE_BYTES} characters")
    try:
        doc = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise SceneError(f"{source}: not valid TOML: {' '.join(str(exc).split())}") from None
    except RecursionError:
        raise SceneError(f"{source}: not valid TOML: nested too deeply") from None
    except (ValueError, OverflowError) as exc:  # e.g. an integer of 5000 digits
        raise SceneError(f"{source}: not valid TOML: {_short(str(exc), 120)}") from None
    try:
        return _scene_from_doc(doc, text, source, None if base is None else Path(base))
    except RecursionError:
        raise SceneError(f"{source}: nested too deeply") from None


def load(path) -> Scene:
    """Read a scene file (TOML, docs/contract.md): a regular file of at most MAX_SCENE_BYTES."""
    p = Path(path)
    if not p.exists():
        raise SceneError(f"{p}: no such scene file")
    try:
        data = limits.read_bounded(p, limits.MAX_SCENE_BYTES, "scene file")
    except EyevizError as exc:
        raise SceneError(str(exc)) from None
    except OSError as exc:
        raise SceneError(f"{p}: cannot read: {exc.strerror or exc}") from None
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError:
        raise SceneError(f"{p}: not a text (UTF-8) file") from None
    return loads(text, str(p), p.absolute().parent)


def _doc(scene: Scene, base: Path | None = None) -> dict:
    """The TOML document of ``scene`` as plain data, keys in the order written (an eye
    file's path relative to ``base``, the folder written to, when given)."""
    doc: dict = {}
    if scene.title:
        doc["title"] = scene.title
    e = scene.eyes
    doc["eyes"] = eyes_doc(e, base)
    if scene.features:
        doc["features"] = [
            {"name": f.name, "x": float(f.x), "y": float(f.y), "g": float(f.g), "color": f.color}
            if not e.spec.in_space  # a planar scene's file never gains a z key
            else {
                "name": f.name,
                "x": float(f.x),
                "y": float(f.y),
                "z": float(f.z),
                "g": float(f.g),
                "color": f.color,
            }
            for f in scene.features
        ]
    doc["layers"] = {"show": list(scene.layers)}
    doc["predictions"] = {"estimators": list(scene.estimators)}
    cx, cy = scene.view.center
    doc["view"] = {"center": [float(cx), float(cy)], "width": float(scene.view.width)}
    if scene.trajectory is not None:
        t = scene.trajectory
        doc["trajectory"] = {"kind": t.kind, "distance": float(t.distance), "g": float(t.g)}
    if scene.steps:
        doc["steps"] = [step_doc(st) for st in scene.steps]
    return doc


def _value(v) -> str:
    """One TOML value: scalars by tomli_w (its quoting and float repr), arrays on one line."""
    if isinstance(v, list):
        return "[" + ", ".join(_value(x) for x in v) + "]"
    if isinstance(v, dict):  # an inline table (a step's explicit camera)
        return "{ " + ", ".join(f"{k} = {_value(x)}" for k, x in v.items()) + " }"
    return tomli_w.dumps({"v": v})[4:].rstrip("\n")


def _table(name: str | None, tab: dict, aot: bool = False) -> list[str]:
    head = [] if name is None else [f"[[{name}]]" if aot else f"[{name}]"]
    return head + [f"{k} = {_value(v)}" for k, v in tab.items()] + [""]


def dumps(scene: Scene, base: str | os.PathLike | None = None) -> str:
    """TOML text of ``scene``; ``loads(dumps(s)) == s`` (with ``base``: an eye file's
    path relative to that folder, and ``loads(dumps(s, base), base=base) == s``). Values
    are formatted by tomli_w (strings escaped, floats as repr); the layout is one
    ``key = value`` per line, one ``[[features]]`` table per feature, as the shipped
    scenes are written."""
    doc = _doc(scene, None if base is None else Path(base))
    out: list[str] = []
    if "title" in doc:
        out += _table(None, {"title": doc["title"]})
    out += _table("eyes", doc["eyes"])
    for f in doc.get("features", []):
        out += _table("features", f, aot=True)
    for name in ("layers", "predictions", "view", "trajectory"):
        if name in doc:
            out += _table(name, doc[name])
    for st in doc.get("steps", []):
        out += _table("steps", st, aot=True)
    text = "\n".join(out)
    tomllib.loads(text)  # tomli_w's values, our layout: still TOML
    return text


def save(scene: Scene, path) -> None:
    """Write ``scene`` atomically (temp file in the same directory, then os.replace)."""
    p = Path(path)
    base = p.absolute().parent
    text = dumps(scene, base)
    loads(text, str(path), base)  # refuse to write a scene that would not load back
    with atomic_output(p) as tmp:
        tmp.write_text(text, encoding="utf-8")
