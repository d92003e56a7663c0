"""Scene -> a matplotlib figure for papers: true vectors, drawn from one Frame.

:func:`figure` builds the scene's :class:`eyeviz.model.frame.Frame` (every derived
quantity: tangents, sectors, the BFV wedge, runs, readout, predictions, ambiguity,
trajectory) and hands it to the matplotlib painter of each layer shown, in the layer
table's order (:mod:`eyeviz.model.layers`; the painters are in
:mod:`eyeviz.render.mpl.layers`); no geometry and no prediction is computed here. SVG and
PDF hold one path per ommatidium (Figure 2), feature disc and the BFV wedge (Definition
2), with text kept as text (never below 6 pt). The layout (:mod:`eyeviz.render.mpl.layout`)
follows the width: a journal column (3.5 in), a double column (7.2 in) or any width
between 3 and 10 in.

Why this is not one module with the spherical figure (:mod:`eyeviz.render.mpl.figure3d`,
:mod:`eyeviz.render.mpl.perspective3d`; issue 37 asked for twins that do the same job to
be merged): the mathematics of the two pictures differs. The planar scene lies in the
plane it is drawn in: a feature is a disc, an ommatidium a triangle, the BFV a wedge, all
drawn in model coordinates with an affine data-to-axes map, so the painters of the layer
table draw straight from the Frame and matplotlib's own axes clip and scale. The spherical
scene is a 3D one seen through a camera: every polygon (facets of a HEALPix or measured
eye, balls, cones, the field's boundary) is put through VTK's perspective projection,
back faces culled, sorted far to near (painter's algorithm) and shaded, and the eyes'
facets are also drawn on Mollweide maps. What both need of a figure, the house style,
fonts and the font floor, widths in inches, is shared (:mod:`eyeviz.render.mpl.style`).

matplotlib is imported when this module is; callers that must stay light import it late.
"""

from __future__ import annotations

import math

from matplotlib.figure import Figure

from eyeviz import EyevizError
from eyeviz.model.frame import build_frame, state_for
from eyeviz.model.layers import ordered, resolve
from eyeviz.model.predictor import Predictor
from eyeviz.model.scene import Scene
from eyeviz.model.state import SceneState
from eyeviz.render.mpl.bounded import bound_figure
from eyeviz.render.mpl.canvas import draw_notes, make_canvas
from eyeviz.render.mpl.layout import ASPECT_RANGE, default_aspect, layout, more_text
from eyeviz.render.mpl.style import (
    BASE_DPI,
    MAX_WIDTH,
    MIN_WIDTH,
    RC,
    VECTOR_DPI,
    WIDTH_IN,
    WIDTHS,
    check_min_font,
    raise_fonts,
)
from eyeviz.render.mpl.style import min_font as font_floor

__all__ = [
    "BASE_DPI",
    "MAX_FEATURES",
    "MAX_COORD",
    "VECTOR_DPI",
    "RC",
    "figure",
    "refuse_unloadable",
    "resolve_width",
]

MAX_FEATURES = 10_000  # a snapshot with more features is refused (drawing would take minutes)
MAX_COORD = 1e15  # |x|, |y|, g and the view beyond this cannot be drawn by Agg
#: The view's width relative to its centre's distance from the origin, at least (about
#: 4,500 float64 steps across the view); far below it float64 cannot even tell the view's
#: edges from its centre (1e12 +- 5e-7 == 1e12).
MIN_VIEW_REL = 1e-12


def resolve_width(width) -> float:
    """'single' (3.5 in), 'double' (7.2 in) or a number of inches in [3, 10]."""
    if isinstance(width, str):
        key = width.strip().lower()
        if key in WIDTHS:
            return WIDTHS[key]
        try:
            width = float(key)
        except ValueError:
            raise EyevizError(
                f"width must be 'single', 'double' or inches, got {width!r}"
            ) from None
    try:
        w = float(width)
    except (TypeError, ValueError):
        raise EyevizError(f"width must be 'single', 'double' or inches, got {width!r}") from None
    if not (math.isfinite(w) and MIN_WIDTH <= w <= MAX_WIDTH):
        raise EyevizError(
            f"width must be between {MIN_WIDTH:g} and {MAX_WIDTH:g} inches, got {width!r}"
        )
    return w


def check_drawable(scene: Scene) -> None:
    """EyevizError (one line) for a scene no figure can show: too many features,
    coordinates beyond :data:`MAX_COORD`, or a view narrower than :data:`MIN_VIEW_REL`
    times its centre's distance from the origin."""
    n = len(scene.features)
    if n > MAX_FEATURES:
        raise EyevizError(f"a figure shows at most {MAX_FEATURES} features; this scene has {n}")
    cx, cy = scene.view.center
    vals = {"view centre x": cx, "view centre y": cy, "view width": scene.view.width}
    for k, v in vals.items():
        if not (math.isfinite(v) and abs(v) <= MAX_COORD):
            raise EyevizError(f"{k} = {v:g} cannot be drawn (|value| must be <= {MAX_COORD:g})")
    least = MIN_VIEW_REL * max(abs(cx), abs(cy))
    if scene.view.width < least:
        raise EyevizError(
            f"view width = {scene.view.width:g} cannot be drawn at centre ({cx:g}, {cy:g}): "
            f"below float64 resolution there (need width >= {MIN_VIEW_REL:g} * |centre| = "
            f"{least:g})"
        )
    for f in scene.features:
        for k, v in (("x", f.x), ("y", f.y), ("g", f.g)):
            if not (math.isfinite(v) and abs(v) <= MAX_COORD):
                name = f.name if len(f.name) <= 40 else f.name[:39] + "\u2026"
                raise EyevizError(
                    f"feature {name!r}: {k} = {v:g} cannot be drawn "
                    f"(|{k}| must be <= {MAX_COORD:g})"
                )


def refuse_unloadable(scene: Scene, predictor: Predictor, predictions: dict | None) -> None:
    """EyevizError (one line) when the scene shows predictions and one of its estimators
    cannot be loaded at all, for the CLI and the app's export alike (that message never
    goes into a figure; an estimator that cannot answer for these eyes is drawn as its
    reason). ``predictions`` given: their "unavailable" answers are refused."""
    if not scene.shows("predictions") or not scene.features:
        return
    if predictions is None:
        for name in scene.estimators:
            est = predictor.estimator(name)
            if isinstance(est, str):
                _refuse(name, est)
        return
    for name, res in predictions.items():
        if isinstance(res, str) and res.startswith("unavailable"):
            _refuse(name, res)


def _refuse(name: str, reason: str) -> None:
    reason = reason.removeprefix("unavailable: ")
    raise EyevizError(f"predictions layer: cannot load estimator {name!r}: {reason}")


def resolve_aspect(aspect: float | None, width: float = WIDTH_IN) -> float:
    """The main view's height / width: ``None`` is the default for a ``width``-inch figure
    (0.86 for a single column, 0.5 for a double one: :func:`layout.default_aspect`); a
    number must lie in [0.3, 1.6] (refused, not clamped: the figure would not show what
    was asked)."""
    if aspect is None:
        return default_aspect(width)
    lo, hi = ASPECT_RANGE
    try:
        a = float(aspect)
    except (TypeError, ValueError):
        a = math.nan
    if not lo <= a <= hi:
        raise EyevizError(
            f"aspect (view height / width) must be in [{lo:g}, {hi:g}], got {aspect!r}"
        )
    return a


# long: a figure's layout, part after part in drawing order: matplotlib calls, not logic
def figure(
    scene: Scene,
    state: SceneState | None = None,
    *,
    dpi: float = BASE_DPI,
    merge: bool | None = None,
    predictions: dict | None = None,
    width: float | str = WIDTH_IN,
    title: bool = True,
    table: bool = True,
    bitmaps: bool = True,
    predictor=None,
    aspect: float | None = None,
    min_font: float | None = None,
) -> Figure:
    """The scene as a matplotlib Figure (no pyplot, no GUI), ``width`` inches wide
    ('single' = 3.5, 'double' = 7.2, or a number in [3, 10]).

    ``aspect`` (height / width of the main view, in [0.3, 1.6]; default 0.86 for a single
    column, 0.5 for a double one, interpolated between) frames the
    figure as a window of that shape shows the scene's view: the app's File > Export
    passes its view's, so the figure shows what the window shows.

    ``dpi`` is the resolution the figure will be rendered at (decides, with ``merge=None``,
    whether ommatidium triangles are below a pixel and merged into runs; pass
    :data:`VECTOR_DPI` for SVG/PDF). ``predictions`` maps estimator name -> (r_hat,
    phi_hat) arrays per feature; when None and the scene shows predictions, the scene's
    estimators are loaded (``predictor``, or a new :class:`Predictor`). An estimator that
    cannot load is refused (EyevizError). ``title``, ``table`` and ``bitmaps`` (False)
    drop the title, the readout table and the bitmap strips. ``min_font`` (points, in
    [6, 12]) raises every smaller text to it; rows, lanes and margins grow to match.
    """
    import matplotlib

    w = resolve_width(width)
    aspect = resolve_aspect(aspect, w)
    floor = 0.0 if min_font is None else check_min_font(min_font)
    check_drawable(scene)
    drop = set()
    if not table:
        drop.add("readout")
    if not bitmaps:
        drop.add("bitmaps")
    if drop:
        scene = scene.copy()
        scene.layers = [k for k in scene.layers if k not in drop]
    state = state_for(scene, state)
    lay_names = set(scene.layers)
    predictor = Predictor() if predictor is None else predictor
    refuse_unloadable(scene, predictor, predictions)
    n_est = len(scene.estimators)
    cx, cy = scene.view.center
    with matplotlib.rc_context(RC), font_floor(floor):
        lay0 = layout(
            w,
            layers=lay_names,
            title=title and bool(scene.title),
            n_features=len(scene.features),
            n_estimators=n_est,
            intervals=_intervals(state),
            m=state.pair.m,
            ylim=(cy - scene.view.width * aspect / 2, cy + scene.view.width * aspect / 2),
            xlim=(cx - scene.view.width / 2, cx + scene.view.width / 2),
            aspect=aspect,
            min_font=floor,
        )
        vw = scene.view.width
        vh = vw * lay0.main.h / lay0.main.w
        rect = (cx - vw / 2, cx + vw / 2, cy - vh / 2, cy + vh / 2)
        fr = build_frame(scene, state, predictor, rect=rect, predictions=predictions)
        cv = make_canvas(scene, fr, lay0, dpi, merge, title)
        for spec in ordered("mpl", lay_names):  # the layer table, in its matplotlib order
            resolve(spec.mpl)(cv)
        if fr.regions_left_out and {"ambiguity", "posterior"} & lay_names:
            what = " or ".join(k for k in ("ambiguity", "posterior") if k in lay_names)
            cv.notes.append(more_text(fr.regions_left_out, f"more without {what}"))
        draw_notes(cv)  # what the caps left out, counted
        raise_fonts(cv.fig, floor)
        bound_figure(cv.fig)  # nothing Agg/FreeType cannot raster in bounded time
        cv.fig._eyeviz_rc = dict(RC)  # savefig must run under the same rc (fonttype)
        cv.fig._eyeviz_merged = cv.merged
        cv.fig._eyeviz_frame = fr
    return cv.fig


def _intervals(state: SceneState):
    if state.LA is None:
        return None
    return (state.LA, state.RA), (state.LB, state.RB)
