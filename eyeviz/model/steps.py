"""Step-by-step construction of a scene for a lecture: ``[[steps]]`` in the scene file.

Each step names the layers and the features shown at that point of the lecture, and a
caption said or shown with it (docs/contract.md). Walking the steps (PageDown / PageUp
in the app) shows the scene as each step says; the scene itself is never changed, so
the full scene is what is saved::

    [[steps]]
    caption = "Two eyes of m ommatidia each (Figure 2)"
    layers = ["eyes", "labels"]
    features = []          # no feature yet (omitted: every feature)
    camera = "top"         # optional: how the view frames this step (below)
    panels = ["readout"]   # optional: the side panels the step needs (kept in F5)

A step frames what it shows: without ``camera`` the view is fitted to the eyes and the
step's features (planar: the Fit view of the app; spherical: the default 3/4 preset
framing the step's balls). ``camera`` names a spherical preset (``"default"``,
``"front"``, ``"top"``, ``"side"``, ``"eye_a"``, ``"eye_b"``; ``"fit"`` in both models),
or gives an explicit view: planar ``{center = [x, y], width = w}``, spherical
``{position = [..], focal_point = [..], view_up = [..], view_angle = 30}`` (VTK's
camera, eyeviz.model.camera3d.Camera3D). ``panels`` names the side panels the caption
talks about (:data:`PANELS`); presentation mode (F5), which hides the side panels, keeps
these.

Pure functions on the scene's dataclasses; no Qt.
"""

from __future__ import annotations

import copy
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any, Protocol, TypeVar


class _Staged(Protocol):  # eyeviz.model.scene.Scene (not imported: it imports this module)
    layers: list[str]
    features: list[Any]


S = TypeVar("S", bound=_Staged)

__all__ = [
    "MAX_STEPS",
    "PANELS",
    "STEP_KEYS",
    "Step",
    "apply_step",
    "check_camera",
    "check_steps",
    "step_doc",
]

MAX_STEPS = 100
STEP_KEYS = ("caption", "layers", "features", "camera", "panels")
#: The side panels a step may name, by the scene's side (the app maps them to its docks).
PANELS: dict[str, tuple[str, ...]] = {
    "planar": ("readout", "features", "eyes", "layers", "estimators", "trajectory", "design"),
    "spherical": ("maps", "readout", "estimators"),
}
#: The camera names a step may give, by side (``fit``: the view fitted to the step).
CAMERA_NAMES: dict[str, tuple[str, ...]] = {
    "planar": ("fit",),
    "spherical": ("fit", "default", "front", "top", "side", "eye_a", "eye_b"),
}
_CAMERA_TABLE: dict[str, dict[str, int]] = {  # key -> number of values (0: one number)
    "planar": {"center": 2, "width": 0},
    "spherical": {"position": 3, "focal_point": 3, "view_up": 3, "view_angle": 0},
}
_MAX_COORD = 1e9  # an explicit camera's coordinates are bounded (untrusted files)


@dataclass
class Step:
    """One step: the layers shown, the features shown (None: all of them), a caption."""

    caption: str
    layers: list[str] = field(default_factory=list)
    features: list[str] | None = None
    camera: str | dict[str, Any] | None = None  # None: fitted to what the step shows
    panels: list[str] | None = None  # the side panels kept in presentation mode


def check_steps(
    raw: Any,
    fail: Callable[[str, str], Exception],
    known_layers: Sequence[str],
    feature_names: Sequence[str],
    bad_text: Callable[[str], str | None],
    side: str = "planar",
) -> list[Step]:
    """The steps of a parsed ``[[steps]]`` array of a scene of ``side`` (planar or
    spherical); ``fail(key, rule)`` makes the one-line error (naming the file, line and
    key, e.g. ``steps[2].layers``) that is raised."""
    if not isinstance(raw, list):
        raise fail("steps", "must be an array of tables ([[steps]])")
    if len(raw) > MAX_STEPS:
        raise fail("steps", f"{len(raw)} steps, more than {MAX_STEPS}")
    steps = []
    for i, st in enumerate(raw):
        p = f"steps[{i}]"
        if not isinstance(st, dict):
            raise fail(p, "must be a table")
        for k in st:
            if k not in STEP_KEYS:
                raise fail(f"{p}.{k}", f"unknown key (allowed: {', '.join(STEP_KEYS)})")
        cap = st.get("caption", "")
        if not isinstance(cap, str):
            raise fail(f"{p}.caption", f"must be a string, got {type(cap).__name__}")
        why = bad_text(cap)  # too long, or a control character (a line break too)
        if why:
            raise fail(f"{p}.caption", f"{cap[:40]!r} {why}")
        layers = _names(st, "layers", p, fail)
        for name in layers:
            if name not in known_layers:
                raise fail(
                    f"{p}.layers", f"unknown layer {name!r} (known: {', '.join(known_layers)})"
                )
        feats = _names(st, "features", p, fail) if "features" in st else None
        for name in feats or []:
            if name not in feature_names:
                known = ", ".join(repr(n) for n in feature_names) or "none"
                raise fail(f"{p}.features", f"no feature named {name!r} (features: {known})")
        camera = check_camera(st["camera"], f"{p}.camera", fail, side) if "camera" in st else None
        panels = _names(st, "panels", p, fail) if "panels" in st else None
        for name in panels or []:
            if name not in PANELS[side]:
                known = ", ".join(PANELS[side])
                raise fail(f"{p}.panels", f"unknown panel {name!r} (a {side} scene's: {known})")
        steps.append(Step(cap, layers, feats, camera, panels))
    return steps


def check_camera(
    raw: Any, key: str, fail: Callable[[str, str], Exception], side: str
) -> str | dict[str, Any]:
    """A step's ``camera``: a name of :data:`CAMERA_NAMES` or an explicit view table."""
    if isinstance(raw, str):
        if raw not in CAMERA_NAMES[side]:
            raise fail(key, f"unknown camera {raw!r} (known: {', '.join(CAMERA_NAMES[side])})")
        return raw
    if not isinstance(raw, dict):
        raise fail(key, f"must be a name or a table, got {type(raw).__name__}")
    spec = _CAMERA_TABLE[side]
    out: dict[str, Any] = {}
    for k, v in raw.items():
        if k not in spec:
            raise fail(f"{key}.{k}", f"unknown key (allowed: {', '.join(spec)})")
        vals = v if spec[k] else [v]
        if (
            not isinstance(vals, list)
            or len(vals) != max(spec[k], 1)
            or not all(isinstance(x, int | float) and not isinstance(x, bool) for x in vals)
            or not all(abs(float(x)) <= _MAX_COORD for x in vals)  # NaN fails too
        ):
            n = f"{spec[k]} numbers" if spec[k] else "a number"
            raise fail(f"{key}.{k}", f"must be {n} of magnitude <= {_MAX_COORD:g}")
        out[k] = [float(x) for x in vals] if spec[k] else float(v)
    need = [k for k in spec if k not in ("view_angle",) and k not in out]
    if need:
        raise fail(key, f"missing {', '.join(need)}")
    if "width" in out and out["width"] <= 0:
        raise fail(f"{key}.width", f"must be > 0, got {out['width']!r}")
    if "view_angle" in out and not 1.0 <= out["view_angle"] <= 170.0:
        raise fail(f"{key}.view_angle", f"must be in [1, 170] degrees, got {out['view_angle']!r}")
    if "focal_point" in spec and out["position"] == out["focal_point"]:  # a camera in space
        raise fail(key, "position must differ from focal_point")
    return out


def _names(st: dict, key: str, p: str, fail: Callable[[str, str], Exception]) -> list[str]:
    v = st.get(key, [])
    if not isinstance(v, list) or not all(isinstance(s, str) for s in v):
        raise fail(f"{p}.{key}", "must be a list of strings")
    if len(set(v)) != len(v):
        raise fail(f"{p}.{key}", "a name is given twice")
    return list(v)


def step_doc(step: Step) -> dict:
    """The TOML table of ``step`` (the inverse of :func:`check_steps` for one step)."""
    doc: dict = {"caption": step.caption, "layers": list(step.layers)}
    if step.features is not None:
        doc["features"] = list(step.features)
    if step.camera is not None:
        doc["camera"] = step.camera if isinstance(step.camera, str) else dict(step.camera)
    if step.panels is not None:
        doc["panels"] = list(step.panels)
    return doc


def apply_step(scene: S, step: Step) -> S:
    """The scene as ``step`` shows it: the step's layers and only its features (the
    view, the eyes and the estimators are the scene's)."""
    out = copy.deepcopy(scene)
    out.layers = list(step.layers)
    if step.features is not None:
        keep = set(step.features)
        out.features = [f for f in out.features if f.name in keep]
    return out
