"""Step-by-step construction of a scene for a lecture: ``[[steps]]`` in the scene file.

Each step names the layers and the features shown at that point of the lecture, and a
caption said or shown with it (docs/contract.md). Walking the steps (PageDown / PageUp
in the app) shows the scene as each step says; the scene itself is never changed, so
the full scene is what is saved::

    [[steps]]
    caption = "Two eyes of m ommatidia each (Figure 2)"
    layers = ["eyes", "labels"]
    features = []          # no feature yet (omitted: every feature)

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

__all__ = ["MAX_STEPS", "STEP_KEYS", "Step", "apply_step", "check_steps", "step_doc"]

MAX_STEPS = 100
STEP_KEYS = ("caption", "layers", "features")


@dataclass
class Step:
    """One step: the layers shown, the features shown (None: all of them), a caption."""

    caption: str
    layers: list[str] = field(default_factory=list)
    features: list[str] | None = None


def check_steps(
    raw: Any,
    fail: Callable[[str, str], Exception],
    known_layers: Sequence[str],
    feature_names: Sequence[str],
    bad_text: Callable[[str], str | None],
) -> list[Step]:
    """The steps of a parsed ``[[steps]]`` array; ``fail(key, rule)`` makes the one-line
    error (naming the file, line and key, e.g. ``steps[2].layers``) that is raised."""
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
        steps.append(Step(cap, layers, feats))
    return steps


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
