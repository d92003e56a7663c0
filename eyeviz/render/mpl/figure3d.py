"""A spherical scene (issue 22, docs/spherical.md) as a matplotlib figure: headless, no VTK.

:func:`figure3d` draws, from one :class:`eyeviz.model.state3d.SceneState3D`:

- the 3D view through a camera (:class:`eyeviz.model.camera3d.Camera3D`; default the
  ``default`` preset framing the balls; the app's File > Export passes its view's), drawn
  from the model by :mod:`eyeviz.render.mpl.perspective3d` as the VTK view draws it: the
  eyes close up on the left, the scene on the right; the eyes' facets (layer "eyes"), the
  balls ("features"), the tangent cones ("tangents"), the plane z = 0 ("plane") and the
  boundary of the 3D binocular field ("bfv") as polygons projected as VTK projects them,
  back faces of the eyes and balls culled, painted far to near (painter's algorithm);
- each eye's facets on a Mollweide map seen from inside the eye (layer "bitmaps"; forward
  at the centre, the eye's right on the right, the equator drawn: that row is the planar
  bitmap), lit facets in the features' colours. Above
  :data:`eyeviz.render.mpl.healpix_map.MAX_ALL_FACETS` facets per eye (nside > 32) only the
  lit facets are drawn as polygons, over a solid background of the unlit sphere (nside 180
  is 388,800 facets per eye: far too heavy for SVG or PDF); the 3D view then draws the
  unlit sphere at nside 16 and the lit facets at the scene's nside over it;
- a readout table (layer "readout"): per ball r, azimuth and elevation (degrees; azimuth
  from +x counter-clockwise seen from above, forward = 90), g, in the 3D BFV, visible
  per eye (Definition 1), overlaps per eye and facets lit per eye.

SVG and PDF are true vectors (one path per drawn facet, text as text, nothing rasterised).
It stays apart from the planar figure (:mod:`eyeviz.render.mpl.vector`) because the
mathematics differs: a perspective projection of spheres, cones and facets with culling and
depth order here, a planar drawing in model coordinates there (that module's docstring).
matplotlib is imported when this module is; callers that must stay light import it late.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from eyeviz import EyevizError
from eyeviz.core.geometry3d import EyePair3D
from eyeviz.core.validation import check_choice
from eyeviz.files.atomic import atomic_output
from eyeviz.model import shapes3d
from eyeviz.model.camera3d import PRESETS, Camera3D, view_side
from eyeviz.model.facet_patches import facet_patches
from eyeviz.model.predictions3d import (
    Predictions3D,
    Predictor3D,
    estimator_color3d,
    prediction_rows,
    scene_predictions3d,
)
from eyeviz.model.scene import Scene
from eyeviz.model.state3d import SceneState3D, compute_state3d
from eyeviz.render.mpl.facet_map import MapAxes, draw_eye_view, view_lonlat
from eyeviz.render.mpl.inset3d import draw_ball_inset
from eyeviz.render.mpl.perspective3d import (
    VIEW_LAYERS,
    draw_panel,
    framed_camera,
    split_viewports,
)
from eyeviz.render.mpl.style import (
    BASE_DPI,
    FONT,
    GREY,
    INK,
    RC,
    SMALL,
    VECTOR_DPI,
    check_min_font,
    pt,
    raise_fonts,
    short,
)
from eyeviz.render.mpl.style import min_font as font_floor

__all__ = [
    "MAX_BALLS",
    "ViewImage",
    "check_drawable3d",
    "export3d",
    "figure3d",
    "readout_rows",
]

#: ``view_image(camera, width_px, height_px)`` -> the 3D view's picture, rows x columns x
#: 3 or 4 (uint8 or floats in [0, 1]): the VTK render the PNG shows (:func:`figure3d`).
ViewImage = Callable[[Camera3D, int, int], np.ndarray]

#: A 3D figure shows at most this many balls (the table holds a row per ball).
MAX_BALLS = 40
#: |x|, |y|, |z| and g a 3D figure can draw (as the planar figure's MAX_COORD).
MAX_COORD3D = 1e15
ROW_IN = 0.14  # a table row, inches


def check_drawable3d(scene: Scene) -> None:
    """EyevizError (one line) for a spherical scene the figure cannot show."""
    n = len(scene.features)
    if n > MAX_BALLS:
        raise EyevizError(f"a 3D figure shows at most {MAX_BALLS} balls; this scene has {n}")
    for f in scene.features:
        for k, v in (("x", f.x), ("y", f.y), ("z", f.z), ("g", f.g)):
            if not (math.isfinite(v) and abs(v) <= MAX_COORD3D):
                raise EyevizError(
                    f"feature {short(f.name)!r}: {k} = {v:g} cannot be drawn "
                    f"(|{k}| must be <= {MAX_COORD3D:g})"
                )


# --- the 3D view -------------------------------------------------------------------------


def _draw_view(
    fig: Figure,
    box: tuple[float, float, float, float],
    st: SceneState3D,
    scene: Scene,
    cam: Camera3D,
    image: np.ndarray | None = None,
    predictions: Predictions3D | None = None,
) -> None:
    """The 3D view in ``box`` (figure fractions) as the VTK view lays it out: the eyes
    close up on the left, the scene through ``cam`` on the right (polygons, or ``image``:
    the VTK render of the same view, :func:`eyeviz.render.mpl.perspective3d.draw_panel`)."""
    eyes_ax, scene_ax = draw_panel(fig, box, st, scene, cam, image=image, predictions=predictions)
    if predictions is not None and scene.shows("predictions"):  # the ghosts told apart
        draw_ball_inset(scene_ax, st, scene, predictions, cam)
    scene_ax.text(
        0.02, 0.98, _view_caption(cam), transform=scene_ax.transAxes, fontsize=SMALL,
        color=GREY, ha="left", va="top",
    )  # fmt: skip
    pair = st.pair
    if isinstance(pair, EyePair3D):
        caption = f"eyes close up, nside {pair.nside}\n{pair.npix:,} facets each"
    else:
        caption = "eyes close up\n{:,} + {:,} facets".format(*pair.facet_counts)
    eyes_ax.text(
        0.03, 0.98, caption,
        transform=eyes_ax.transAxes, fontsize=SMALL, color=GREY, ha="left", va="top",
    )  # fmt: skip


def _view_caption(cam: Camera3D) -> str:
    """Where the camera looks from, in words (the model's axes): the first line of the
    app's :func:`eyeviz.model.camera3d.view_side`, the one place that words it."""
    return view_side(cam).split("\n")[0]


# --- the readout ---------------------------------------------------------------------


def _yes(v) -> str:
    return "yes" if bool(v) else "no"


def _pair(a, b) -> str:
    return ("A" if a else "") + ("B" if b else "") or "no"


def _dist(r: float) -> str:
    """A distance: whole units from 100 on (the HEALPix scenes'), else three significant
    digits (a bee's balls are a few millimetres away); from 10^5 on in one-digit exponent
    form, so the table's narrow column holds it."""
    if r >= 1e5:
        return f"{r:.0e}"
    return f"{r:.0f}" if r >= 100 else f"{r:.3g}"


def readout_rows(st: SceneState3D, scene: Scene) -> list[tuple[str, ...]]:
    """The table's rows (strings), one per ball: name, r, azimuth and elevation (degrees),
    g, in the BFV, visible per eye, overlaps per eye, facets lit per eye."""
    rows: list[tuple[str, ...]] = []
    for i, f in enumerate(scene.features):
        rows.append(
            (
                short(f.name, 14),
                _dist(float(st.r[i])),
                f"{math.degrees(st.azimuth[i]):.1f}",
                f"{math.degrees(st.elevation[i]):.1f}",
                f"{f.g:g}" if f.g < 1e5 else f"{f.g:.0e}",
                _yes(st.in_bfv[i]) if st.in_bfv is not None else "",
                _pair(st.vis_a[i], st.vis_b[i])
                if st.vis_a is not None and st.vis_b is not None
                else "",
                _pair(st.overlap_a[i], st.overlap_b[i])
                if st.overlap_a is not None and st.overlap_b is not None
                else "",
                f"{st.facets_a[i]}/{st.facets_b[i]}"
                if st.facets_a is not None and st.facets_b is not None
                else "",
            )
        )
    return rows


#: the readout table's headers, and the short ones a narrow figure uses (the app's)
HEADS = ("ball", "r", "az\u00b0", "el\u00b0", "g", "BFV", "visible", "overlap", "facets A/B")
SHORT_HEADS = ("ball", "r", "az\u00b0", "el\u00b0", "g", "BFV", "vis", "ovl", "lit A/B")
_MARK = 0.12  # inches: the colour swatch before a name


def _columns(ax, rows: list[tuple[str, ...]], heads: tuple[str, ...]) -> list[float] | None:
    """Column left edges (axes fractions) from the texts' widths at the drawn size
    (estimated from their lengths, as the 3D names), or None when they do not fit."""
    size = pt(SMALL)
    pos = ax.get_position()
    avail = pos.width * ax.figure.get_figwidth()
    gap = 0.45 * size / 72.0
    widths = [
        max(len(t) for t in [h] + [r[j] for r in rows]) * 0.6 * size / 72.0
        for j, h in enumerate(heads)
    ]
    widths[0] += _MARK
    need = sum(widths) + gap * (len(widths) - 1)
    if need > avail:
        return None
    spare = (avail - need) / (len(widths) - 1)  # spread between the columns
    edges, x = [], 0.0
    for w in widths:
        edges.append(x / avail)
        x += w + gap + spare
    return edges


def _draw_table(ax, st: SceneState3D, scene: Scene) -> None:
    ax.set_axis_off()
    ax.set_xlim(0, 1)
    n = len(scene.features)
    ax.set_ylim(-(n + 0.5), 1.0)
    rows = readout_rows(st, scene)
    heads = HEADS
    edges = _columns(ax, rows, HEADS)
    if edges is None:  # narrow, or text raised by --min-font: the app's short headers
        heads = SHORT_HEADS
        edges = _columns(ax, rows, SHORT_HEADS) or [
            0.0, 0.2, 0.28, 0.37, 0.46, 0.53, 0.63, 0.74, 0.86,
        ]  # fmt: skip
    mark = _MARK / (ax.get_position().width * ax.figure.get_figwidth())
    for x, t in zip(edges, heads, strict=True):
        ax.text(x, 0.0, t, fontsize=SMALL, color=GREY, ha="left", va="center")
    ax.plot([0, 1], [-0.5, -0.5], color=GREY, lw=0.4)
    for i, row in enumerate(rows):
        y = -(i + 1)
        ax.plot([0.008], [y], marker="s", ms=3.5, mew=0, color=scene.features[i].color)
        for j, (x, t) in enumerate(zip(edges, row, strict=True)):
            ax.text(x + (mark if j == 0 else 0.0), y, t, fontsize=SMALL, color=INK, va="center",
                    parse_math=False)  # fmt: skip


def _draw_predictions_table(ax, preds: Predictions3D, scene: Scene) -> None:
    """The predictions layer's rows (:func:`prediction_rows`, as the app's readout)."""
    ax.set_axis_off()
    ax.set_xlim(0, 1)
    rows = prediction_rows(preds)
    ax.set_ylim(-(len(rows) + 0.5), 1.0)
    name = short(scene.features[preds.ball].name, 20) if preds.ball < len(scene.features) else ""
    edges = [0.0, 0.2, 0.3, 0.4, 0.52, 0.63, 0.73, 0.84]
    heads = ("estimator", "r", "\u0394r %", "az\u00b0", "\u0394az\u00b0", "el\u00b0",
             "\u0394el\u00b0", f"({name})")  # fmt: skip
    for x, t in zip(edges, heads, strict=True):
        ax.text(x, 0.0, t, fontsize=SMALL, color=GREY, ha="left", va="center", parse_math=False)
    ax.plot([0, 1], [-0.5, -0.5], color=GREY, lw=0.4)
    for i, row in enumerate(rows):
        y = -(i + 1)
        ax.plot([0.008], [y], marker="s", ms=3.5, mew=0, color=estimator_color3d(row[0]))
        for j, (x, t) in enumerate(zip(edges, row, strict=True)):
            ax.text(x + (0.02 if j == 0 else 0.0), y, short(t, 40), fontsize=SMALL, color=INK,
                    va="center", parse_math=False)  # fmt: skip


# --- the figure --------------------------------------------------------------------------


# long: a figure's layout, panel after panel in drawing order: matplotlib calls, not logic
def figure3d(
    scene: Scene,
    state: SceneState3D | None = None,
    *,
    width: float = 3.5,
    title: bool = True,
    table: bool = True,
    bitmaps: bool = True,
    aspect: float | None = None,
    camera: Camera3D | None = None,
    view: str = "default",
    dpi: float | None = None,
    view_image: ViewImage | None = None,
    predictions: Predictions3D | None = None,
    ball: int = 0,
    min_font: float | None = None,
) -> Figure:
    """The spherical scene as a Figure ``width`` inches wide (see the module docstring).
    ``title``, ``table`` and ``bitmaps`` (False) leave those parts out; ``aspect`` is the
    3D view's height / width (default 0.6; 0.38 from 6 inches wide, where the two maps
    stand side by side); ``camera`` is the view's (default: the preset ``view``, one of
    :data:`eyeviz.model.camera3d.PRESETS`, framing the eyes and the balls).

    ``dpi`` (the PNG's pixels per inch) makes the figure a whole number of pixels wide
    and high and puts the 3D view's box on whole pixels; ``view_image`` (needs ``dpi``)
    is called as ``view_image(camera, width_px, height_px)`` for the view's picture at
    that box's pixel size (the VTK off-screen render,
    :func:`eyeviz.render.vtk.png3d.view_rgba`), shown pixel for pixel in place of the
    polygons; the maps, the readout and the text are drawn as for the vector figure.

    With the predictions layer the view draws the estimators' ghosts and the limit's
    cloud for ball ``ball`` (the app passes its selection) and the readout their rows:
    ``predictions`` (:func:`eyeviz.model.predictions3d.scene_predictions3d`), computed
    here (the limit included) when None.

    ``min_font`` (points, ``snapshot --min-font``, as the planar figure's): no text
    smaller; the title, the maps' captions and the table rows grow to match."""
    floor = 0.0 if min_font is None else check_min_font(min_font)
    with font_floor(floor):
        fig = _figure3d(scene, state, width, title, table, bitmaps, aspect, camera, view, dpi,
                        view_image, predictions, ball)  # fmt: skip
    raise_fonts(fig, floor)
    return fig


# long: the figure's layout in one place (view, maps, table, close-up inset, legend), each
# part placed relative to the ones before it; split, the parts would pass the layout around
def _figure3d(scene, state, width, title, table, bitmaps, aspect, camera, view, dpi,
              view_image, predictions, ball) -> Figure:  # fmt: skip
    """:func:`figure3d` at the font floor set (:func:`eyeviz.render.mpl.style.pt`)."""
    import matplotlib

    if view_image is not None and dpi is None:
        raise EyevizError("figure3d: view_image needs the PNG's dpi")

    if not scene.in_space:
        raise EyevizError("figure3d draws a spherical scene ([eyes] nside)")
    check_drawable3d(scene)
    st = compute_state3d(scene) if state is None else state
    shapes3d.check_drawn_facets(st)  # before anything is drawn (issue 35)
    shown = set(scene.layers)
    preds = predictions
    if "predictions" in shown and preds is None and scene.features:
        preds = scene_predictions3d(scene, st, min(max(ball, 0), st.n - 1), Predictor3D())
    if "predictions" not in shown:
        preds = None
    persp = bool(shown & set(VIEW_LAYERS))
    maps = bitmaps and "bitmaps" in shown and st.lit_a is not None
    tab = table and "readout" in shown and bool(scene.features)
    side = width >= 6.0  # the two maps side by side
    if aspect is None:
        aspect = 0.38 if side else 0.6
    m = 0.08  # margin, inches
    map_w = (width - 3 * m) / 2 if side else width - 2 * m
    grow = pt(SMALL) / SMALL  # text raised by --min-font: its lines grow as much
    map_h = map_w / 2 + 0.3 * grow  # Mollweide is 2:1, a caption above and directions below
    parts: list[tuple[str, float]] = []
    if title and scene.title:
        parts.append(("title", 0.26 * grow))
    if persp:
        parts.append(("persp", (width - 2 * m) * aspect))
    if maps:
        parts += [("maps", map_h)] if side else [("mapA", map_h), ("mapB", map_h)]
    if tab:
        parts.append(("table", grow * ROW_IN * (len(scene.features) + 1.3)))
    if table and preds is not None and preds.answers:
        parts.append(("preds", grow * ROW_IN * (len(preds.answers) + 1.3)))
    if not parts:
        parts.append(("empty", 0.3))
    height = sum(h for _, h in parts) + 2 * m
    if dpi is not None:  # whole pixels (the rounding goes to the right and bottom margins)
        width, height = round(width * dpi) / dpi, round(height * dpi) / dpi
    with matplotlib.rc_context(RC):
        fig = Figure(figsize=(width, height))
        top = height - m

        def rect(x0: float, w: float, h: float, down: float = 0.0):
            """(left, bottom, width, height) in figure fractions of a box ``w`` x ``h``
            inches at ``x0``, ``down`` inches below the current top."""
            return (x0 / width, (top - down - h) / height, w / width, h / height)

        for name, h in parts:
            if name == "title":
                fig.text(
                    0.5, (top - h / 2) / height, short(scene.title, 90), ha="center",
                    va="center", fontsize=FONT + 1, color=INK, gid="title", parse_math=False,
                )  # fmt: skip
            elif name == "persp":
                box = rect(m, width - 2 * m, h)
                image = None
                if dpi is not None:
                    box, (w_px, h_px) = _on_pixels(box, width * dpi, height * dpi)
                cam = camera
                if cam is None:  # the preset, moved back until the names are clear
                    w_in, h_in = box[2] * width, box[3] * height
                    _, (sx0, _, sx1, _) = split_viewports(w_in, h_in)
                    cam = framed_camera(
                        st, scene, view, (sx1 - sx0) * w_in * 72.0, h_in * 72.0,
                        predictions=preds,
                    )  # fmt: skip
                if view_image is not None:
                    image = view_image(cam, w_px, h_px)
                    if image.shape[:2] != (h_px, w_px):
                        raise EyevizError(
                            f"figure3d: view_image gave {image.shape[1]} x {image.shape[0]} "
                            f"px for a {w_px} x {h_px} px view"
                        )
                _draw_view(fig, box, st, scene, cam, image, preds)
            elif name in ("maps", "mapA", "mapB"):
                eyes = "AB" if name == "maps" else name[-1]
                for k, eye in enumerate(eyes):
                    x0 = m + k * (map_w + m)
                    ax = fig.add_axes(rect(x0, map_w, map_w / 2, 0.18 * grow), axes_class=MapAxes)
                    ax.set_gid(f"map{eye}")
                    _draw_map(ax, st, scene, eye)
            elif name == "table":
                ax = fig.add_axes(rect(m, width - 2 * m, h))
                ax.set_gid("readout")
                _draw_table(ax, st, scene)
            elif name == "preds" and preds is not None:
                ax = fig.add_axes(rect(m, width - 2 * m, h))
                ax.set_gid("predictions")
                _draw_predictions_table(ax, preds, scene)
            elif name == "empty":
                fig.text(0.5, 0.5, "(no layer to draw)", ha="center", fontsize=FONT, color=GREY)
            top -= h
        fig._eyeviz_rc = dict(RC)  # type: ignore[attr-defined]
    return fig


def _on_pixels(
    box: tuple[float, float, float, float], fig_w: float, fig_h: float
) -> tuple[tuple[float, float, float, float], tuple[int, int]]:
    """``box`` (figure fractions) moved to whole pixels of a ``fig_w`` x ``fig_h`` pixel
    figure, and its (width, height) in pixels."""
    x0, y0 = round(box[0] * fig_w), round(box[1] * fig_h)
    x1, y1 = round((box[0] + box[2]) * fig_w), round((box[1] + box[3]) * fig_h)
    return (x0 / fig_w, y0 / fig_h, (x1 - x0) / fig_w, (y1 - y0) / fig_h), (x1 - x0, y1 - y0)


def _draw_map(ax, st: SceneState3D, scene: Scene, eye: str) -> None:
    """Eye ``eye``'s facets on ``ax`` (the outlines its model gives:
    :func:`eyeviz.model.facet_patches.facet_patches`), lit ones in their balls' colours."""
    pair = st.pair
    patches = facet_patches(pair, eye)
    lits = [st.lit(i, eye) for i in range(st.n)]
    draw_eye_view(ax, patches, lits, [f.color for f in scene.features])
    count = np.unique(np.concatenate(lits)).size if lits else 0
    side = "left" if eye == "A" else "right"
    nside = f", nside {pair.nside}" if isinstance(pair, EyePair3D) else ""
    ax.set_title(
        f"eye {eye} ({side}){nside}: {count:,} of {patches.n:,} facets lit",
        fontsize=SMALL, color=INK, pad=3,
    )  # fmt: skip
    for deg in (-60, -30, 30, 60):  # a faint graticule: elevation seen from the eye
        la = math.radians(deg)
        ax.plot([-math.pi, math.pi], [la, la], color="#cccccc", lw=0.3)
    mer = np.linspace(-math.pi / 2, math.pi / 2, 61)
    for deg in (-90, 90):
        ax.plot(np.full_like(mer, math.radians(deg)), mer, color="#cccccc", lw=0.3)
    for x, t in ((0.25, "left"), (0.5, "forward"), (0.75, "right")):
        ax.text(x, -0.01, t, transform=ax.transAxes, fontsize=SMALL, color=GREY, ha="center",
                va="top")  # fmt: skip
    if "labels" in scene.layers:
        cx, cy, cz = pair.centers[0 if eye == "A" else 1]
        for f in scene.features:
            lon = math.atan2(f.y - cy, f.x - cx)
            lat = math.atan2(f.z - cz, math.hypot(f.x - cx, f.y - cy))
            mx, my = view_lonlat(lon, lat)
            # a label on the side away from the map's centre (balls ahead of the eyes
            # crowd there), and inwards near the map's edge
            west = float(mx) > 1.5 or -1.5 <= float(mx) <= 0.0
            ax.annotate(
                short(f.name, 16), (float(mx), float(my)), xytext=(-4 if west else 4, 3),
                textcoords="offset points", fontsize=SMALL, color=INK,
                ha="right" if west else "left", parse_math=False,
            )  # fmt: skip


# --- export ------------------------------------------------------------------------------


def export3d(
    scene: Scene,
    path,
    scale: float = 1.0,
    transparent: bool = False,
    *,
    width: float = 3.5,
    title: bool = True,
    table: bool = True,
    bitmaps: bool = True,
    aspect: float | None = None,
    camera: Camera3D | None = None,
    view: str = "default",
    view_image: ViewImage | None = None,
    predictions: Predictions3D | None = None,
    ball: int = 0,
    min_font: float | None = None,
) -> Path:
    """Write the spherical scene's figure (:func:`figure3d`, through ``camera`` or the
    preset ``view``) to
    ``path`` (.png, .svg or .pdf) atomically, as :func:`eyeviz.render.mpl.export.export`
    writes a planar one. A PNG is ``width`` inches at 300 dpi times ``scale``, on whole
    pixels; ``view_image`` (PNG only, see :func:`figure3d`) gives its 3D view's picture
    (:func:`eyeviz.render.vtk.png3d.export_png3d` passes the VTK render); ``min_font``:
    no text smaller, in points (:func:`figure3d`)."""
    import matplotlib

    from eyeviz.render.mpl.export import MAX_PNG_PX, _check_scale, _metadata, format_of

    fmt = format_of(path)
    scale = _check_scale(scale)
    check_choice("view", view, PRESETS)
    if fmt == "png" and width * BASE_DPI * scale > MAX_PNG_PX:
        raise EyevizError(
            f"scale {scale:g} at width {width:g} in makes a PNG "
            f"{width * BASE_DPI * scale:,.0f} px wide; at most {MAX_PNG_PX} px: "
            f"scale <= {MAX_PNG_PX / (width * BASE_DPI):.3g} at this width"
        )
    target = Path(path)
    parent = target.parent if str(target.parent) else Path(".")
    if not parent.is_dir():
        raise EyevizError(f"{target}: directory {parent} does not exist")
    dpi = BASE_DPI * scale if fmt == "png" else VECTOR_DPI
    fig = figure3d(
        scene, width=width, title=title, table=table, bitmaps=bitmaps, aspect=aspect,
        camera=camera, view=view, dpi=dpi if fmt == "png" else None,
        view_image=view_image if fmt == "png" else None, predictions=predictions, ball=ball,
        min_font=min_font,
    )  # fmt: skip
    with atomic_output(target) as tmp, matplotlib.rc_context(RC):
        fig.savefig(
            tmp,
            format=fmt,
            dpi=dpi if fmt == "png" else 72,
            transparent=transparent,
            metadata=_metadata(fmt, scene),
        )
    return target
