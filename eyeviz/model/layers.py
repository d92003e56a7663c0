"""The layer table: one entry per layer, read by the scene file, the state, the Frame and
both renderers (docs/architecture.md, "The layer table"; napari's layer-to-visual map).

A :class:`LayerSpec` says everything about one layer: its name and one-line help, what it
needs from the state (:data:`NEEDS`: the lit intervals, the per-ommatidium owners, the
per-feature readout), the function that builds its part of the
:class:`eyeviz.model.frame.Frame`, its matplotlib painter, its VTK painter, and its draw
order in each renderer. ``build_frame``, ``compute_state``, the vector figure and the VTK
view iterate :data:`LAYERS`; the scene file accepts exactly its names. A new layer is one
module (a frame builder and its painters) and one :func:`register_layer` call.

Builders and painters are named by ``"module:attribute"`` strings resolved on first use
(:func:`resolve`), so this module imports nothing of eyeviz: the model never imports a
renderer, and a matplotlib-only export never imports VTK. A callable is accepted too (a
layer defined in a test or a notebook).

Hooks (each optional):

- ``frame(frame, inputs) -> None`` fills the layer's part of the Frame from
  :class:`eyeviz.model.frame.FrameInputs` (a layer of its own puts it in
  ``frame.parts[name]``); run only when the scene shows the layer.
- ``mpl(canvas) -> None`` paints the part on a :class:`eyeviz.render.mpl.canvas.Canvas`.
- ``vtk``: a class made once per view as ``cls(main_renderer, inset_renderer)`` (it adds
  its actors; the inset may be None in an overlay view made without one) whose
  ``draw(frame, selected)`` is called for every Frame the view draws: it draws the part,
  or hides its actors when ``frame.layers`` does not show the layer.
  ``vtk_stage`` says which Frame it gets in the app: ``"scene"`` (built from the state at
  each update) or ``"overlay"`` (the parts the app model caches: predictions, the
  selected feature's ambiguity region, the trajectory path).
- ``vtk3d``: the app's 3D view's painter (:class:`eyeviz.render.vtk.painter3d.Painter3D`),
  a class made once per 3D view as ``cls(scene_renderer, eyes_renderer)`` whose
  ``update(scene, state, selected, surface)`` draws the layer from a spherical-side state
  or hides its actors; ``vtk3d_order`` its place among them. A painter may draw a few
  layers that share its actors (the field's painter draws ``bfv`` and ``plane``); those
  layers name no painter of their own.

Every layer states the eye models it applies to (``kinds``, among :data:`MODEL_KINDS`:
the planar eyes, the HEALPix eyes and measured eyes, ``Eyes.kind``): a scene of another
model refuses it in one line, and the app's layer menus list it only for those models
(:func:`layer_names`, :func:`applies`). A registered layer applies to the planar eyes
unless it says otherwise.

>>> from eyeviz.model.layers import layer, layer_names
>>> layer("tangents").needs
frozenset({'readout'})
>>> "bfv" in layer_names()
True
"""

from __future__ import annotations

import importlib
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from typing import Any

__all__ = [
    "LAYERS",
    "MODEL_KINDS",
    "NEEDS",
    "applies",
    "LayerSpec",
    "Ref",
    "layer",
    "layer_names",
    "needs_of",
    "ordered",
    "register_layer",
    "resolve",
    "unregister_layer",
]

#: What a layer can need from the state (:func:`eyeviz.model.state.compute_state`).
NEEDS = ("intervals", "owners", "readout")
#: How the app's VTK view feeds a painter (see the module docstring).
VTK_STAGES = ("scene", "overlay")
#: The eye models a layer can apply to (``eyeviz.model.scene_eyes.Eyes.kind``).
MODEL_KINDS = ("planar", "spherical", "measured")
_EVERY = MODEL_KINDS
_SPACE = ("spherical", "measured")

Ref = str | Callable[..., Any]  # "package.module:attribute", or the object itself


@dataclass(frozen=True)
class LayerSpec:
    """One layer: what it needs, how its Frame part is built and how it is painted."""

    name: str
    help: str
    needs: frozenset[str] = field(default_factory=frozenset)
    frame: Ref | None = None
    mpl: Ref | None = None
    vtk: Ref | None = None
    mpl_order: float = 0.0
    vtk_order: float = 0.0
    vtk_stage: str = "scene"
    kinds: tuple[str, ...] = ("planar",)
    vtk3d: Ref | None = None
    vtk3d_order: float = 0.0

    def __post_init__(self) -> None:
        if not isinstance(self.name, str) or not self.name.isidentifier():
            raise ValueError(f"name must be an identifier, got {self.name!r}")
        if not isinstance(self.help, str) or not self.help.strip() or "\n" in self.help:
            raise ValueError(f"help must be one non-empty line, got {self.help!r}")
        needs = frozenset(self.needs)
        bad = sorted(needs - set(NEEDS))
        if bad:
            raise ValueError(f"needs must be among {', '.join(NEEDS)}, got {', '.join(bad)}")
        object.__setattr__(self, "needs", needs)
        if self.vtk_stage not in VTK_STAGES:
            raise ValueError(f"vtk_stage must be 'scene' or 'overlay', got {self.vtk_stage!r}")
        kinds = tuple(self.kinds)
        if not kinds or any(k not in MODEL_KINDS for k in kinds):
            raise ValueError(f"kinds must be among {', '.join(MODEL_KINDS)}, got {kinds!r}")
        object.__setattr__(self, "kinds", kinds)


_F, _M, _V = "eyeviz.model.frame:", "eyeviz.render.mpl.layers.", "eyeviz.render.vtk.layers."
_V3 = "eyeviz.render.vtk."

#: The table, in the order the scene file and the app's Layers panel list the layers.
#: ``bitmaps`` and ``readout`` have no VTK painter: the app draws them in Qt panels (the
#: 3D page too). The spherical side's vector figure (eyeviz.render.mpl.figure3d) and its
#: close-up panels are not hooks of this table yet: they draw from the state by layer name.
LAYERS: list[LayerSpec] = [
    LayerSpec(
        "eyes",
        "the two eyes' ommatidia, lit in the colour of the feature they see (Figure 2)",
        needs=frozenset({"intervals", "owners"}),
        frame=_F + "build_eyes",
        mpl=_M + "eyes:paint",
        vtk=_V + "eyes:EyesLayer",
        mpl_order=30,
        vtk_order=10,
        kinds=_EVERY,
        vtk3d=_V3 + "eyes3d:EyesPainter",
        vtk3d_order=20,
    ),
    LayerSpec(
        "bfv",
        "the binocular field of view: the wedge both eyes see (Definition 2)",
        frame=_F + "build_bfv",
        mpl=_M + "bfv:paint",
        vtk=_V + "bfv:BFVLayer",
        mpl_order=10,
        vtk_order=5,
        kinds=_EVERY,
        vtk3d=_V3 + "field3d:FieldPainter",
        vtk3d_order=10,
    ),
    LayerSpec(
        "features",
        "the circular features (discs), grey outside the estimators' domain",
        needs=frozenset({"readout"}),
        mpl=_M + "features:paint",
        vtk=_V + "features:FeaturesLayer",
        mpl_order=70,
        vtk_order=20,
        kinds=_EVERY,
        vtk3d=_V3 + "balls3d:BallsPainter",
        vtk3d_order=30,
    ),
    LayerSpec(
        "bitmaps",
        "each eye's bitmap as a strip of lit ommatidia",
        needs=frozenset({"intervals"}),
        frame=_F + "build_eyes",
        mpl=_M + "bitmaps:paint",
        mpl_order=110,
        kinds=_EVERY,
    ),
    LayerSpec(
        "readout",
        "the table of each feature's r, phi, lit intervals and predictions",
        needs=frozenset({"intervals", "readout"}),
        mpl=_M + "table:paint",
        mpl_order=120,
        kinds=_EVERY,
    ),
    LayerSpec(
        "tangents",
        "the tangents from each eye centre to a feature's disc (Prop. 2, Figure 3b)",
        needs=frozenset({"readout"}),
        frame=_F + "build_tangents",
        mpl=_M + "tangents:paint",
        vtk=_V + "tangents:TangentsLayer",
        mpl_order=40,
        vtk_order=40,
        kinds=_EVERY,
    ),
    LayerSpec(
        "sectors",
        "the ommatidium sectors a feature's lit interval spans (Eq. 8, 11)",
        needs=frozenset({"intervals", "readout"}),
        frame=_F + "build_sectors",
        mpl=_M + "sectors:paint",
        vtk=_V + "sectors:SectorsLayer",
        mpl_order=20,
        vtk_order=45,
    ),
    LayerSpec(
        "labels",
        "the names of the eyes, the origin and the features",
        needs=frozenset({"intervals", "readout"}),
        frame=_F + "build_labels",
        mpl=_M + "features:labels",
        vtk=_V + "labels:LabelsLayer",
        mpl_order=100,
        vtk_order=30,
        kinds=_EVERY,
    ),
    LayerSpec(
        "predictions",
        "each estimator's answer as a ghost disc joined to the true centre",
        needs=frozenset({"intervals", "readout"}),
        frame=_F + "build_predictions",
        mpl=_M + "predictions:paint",
        vtk=_V + "predictions:PredictionsLayer",
        mpl_order=80,
        vtk_order=80,
        vtk_stage="overlay",
        kinds=("planar", "spherical"),
    ),
    LayerSpec(
        "ambiguity",
        "the region of centres that light the same ommatidia as a feature",
        needs=frozenset({"intervals", "readout"}),
        frame=_F + "build_ambiguity",
        mpl=_M + "ambiguity:paint",
        vtk=_V + "ambiguity:AmbiguityLayer",
        mpl_order=50,
        vtk_order=60,
        vtk_stage="overlay",
    ),
    LayerSpec(
        "posterior",
        "the limit estimator's posterior over a feature's centre, shaded",
        needs=frozenset({"intervals"}),
        frame=_F + "build_posterior",
        mpl=_M + "posterior:paint",
        vtk=_V + "posterior:PosteriorLayer",
        mpl_order=90,
        vtk_order=90,
    ),
    LayerSpec(
        "trajectory",
        "a feature's path and the estimators' accuracy along it (Figure 14)",
        frame=_F + "build_trajectory",
        mpl=_M + "trajectory:paint",
        vtk=_V + "trajectory:TrajectoryLayer",
        mpl_order=60,
        vtk_order=70,
        vtk_stage="overlay",
    ),
    LayerSpec(
        "plane",
        "the plane z = 0 with a grid, and each eye's equator",
        kinds=_SPACE,  # drawn by the field's painter (bfv) and the eyes' (their equators)
    ),
    LayerSpec(
        "cones",
        "the selected ball's lit facets' acceptance cones",
        kinds=("measured",),  # a HEALPix facet has no lens
        vtk3d=_V3 + "cones3d:ConesPainter",
        vtk3d_order=40,
    ),
    LayerSpec(
        "responses",
        "the lit facets shaded by their graded response",
        kinds=_SPACE,  # drawn by the eyes' painter and the 3D bitmaps panel
    ),
]

_RESOLVED: dict[str, Any] = {}
_CACHE: dict[tuple, Any] = {}  # ordered() and needs_of() answers; cleared when LAYERS changes


def layer_names(kind: str | None = None) -> tuple[str, ...]:
    """The names of every layer, in table order; with ``kind``, of the layers that apply
    to that eye model (:data:`MODEL_KINDS`)."""
    return tuple(s.name for s in LAYERS if kind is None or kind in s.kinds)


def applies(name: str, kind: str) -> bool:
    """Whether layer ``name`` applies to eyes of model ``kind`` (False for an unknown
    name)."""
    return any(s.name == name and kind in s.kinds for s in LAYERS)


def layer(name: str) -> LayerSpec:
    """The entry of layer ``name``; KeyError (one line) for an unknown name."""
    for s in LAYERS:
        if s.name == name:
            return s
    raise KeyError(f"unknown layer {name!r} (known: {', '.join(layer_names())})")


def register_layer(spec: LayerSpec) -> LayerSpec:
    """Add ``spec`` to the table (after the others); ValueError if the name is taken.

    Scene files accept the name at once; the app's views and Layers panel made before the
    call do not show the layer (they read the table when they are made)."""
    if not isinstance(spec, LayerSpec):
        raise TypeError(f"spec must be a LayerSpec, got {type(spec).__name__}")
    if spec.name in layer_names():
        raise ValueError(f"a layer named {spec.name!r} is already registered")
    LAYERS.append(spec)
    _CACHE.clear()
    return spec


def unregister_layer(name: str) -> None:
    """Remove layer ``name`` from the table (a test's layer, say)."""
    LAYERS.remove(layer(name))
    _CACHE.clear()


def ordered(hook: str, shown: Iterable[str] | None = None) -> list[LayerSpec]:
    """The entries with a ``hook`` ("frame", "mpl", "vtk" or "vtk3d"), in that renderer's
    draw order (``mpl_order`` / ``vtk_order`` / ``vtk3d_order``, then table order); only
    the names in ``shown`` if given."""
    keep = None if shown is None else frozenset(shown)
    ck = ("ordered", hook, keep)
    if ck not in _CACHE:  # a drag frame asks again with the same layers
        specs = [s for s in LAYERS if getattr(s, hook) is not None]
        if keep is not None:
            specs = [s for s in specs if s.name in keep]
        key = {"mpl": "mpl_order", "vtk": "vtk_order", "vtk3d": "vtk3d_order"}.get(hook)
        _CACHE[ck] = specs if key is None else sorted(specs, key=lambda s: getattr(s, key))
    return list(_CACHE[ck])


def needs_of(shown: Iterable[str]) -> frozenset[str]:
    """What the layers ``shown`` need from the state (unknown names need nothing)."""
    names = frozenset(shown)
    ck = ("needs", names)
    if ck not in _CACHE:
        out: frozenset[str] = frozenset()
        for s in LAYERS:
            if s.name in names:
                out |= s.needs
        _CACHE[ck] = out
    return _CACHE[ck]


def resolve(ref: Ref | None) -> Any:
    """The object a ``"module:attribute"`` string names (imported on first use), or ``ref``
    itself when it is already an object; ValueError for a missing hook (None)."""
    if ref is None:
        raise ValueError("this layer has no such hook (None); iterate ordered(hook)")
    if not isinstance(ref, str):
        return ref
    if ref not in _RESOLVED:
        mod, sep, attr = ref.partition(":")
        if not sep or not mod or not attr:
            raise ValueError(f"a layer hook must read 'package.module:attribute', got {ref!r}")
        _RESOLVED[ref] = getattr(importlib.import_module(mod), attr)
    return _RESOLVED[ref]
