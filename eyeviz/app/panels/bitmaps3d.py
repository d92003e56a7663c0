"""The eyes' facets beside the 3D view, for any eye model with facets on a sphere of
directions (docs/spherical.md, docs/measured.md, docs/facet_maps.md).

Each eye's facets on a Mollweide map seen from inside the eye (forward at the centre, the
eye's right on the right, as the 3D figure draws them:
:func:`eyeviz.render.mpl.facet_map.draw_eye_view`), lit facets in their features'
colours (a later feature wins), the equator drawn under them and labelled beside the map
(for HEALPix eyes that row of facets is the planar eye's bitmap, m = 4 nside). The facets'
outlines come from the eye model's provider (:func:`eyeviz.model.facet_patches.facet_patches`).
The selected ball's lit facets are outlined in ink: a thick stroke under the fills (only
the patch's border shows), and its facets a later ball colours outlined thinly over
them; it follows the selection (Tab in the 3D view). The wheel zooms both maps, a drag
pans them, a double click or "Whole map" goes back (:mod:`eyeviz.app.panels.map_zoom`).

Fast updates: what does not change with the balls (the unlit sphere: at most
:data:`~eyeviz.render.mpl.facet_map.MAX_ALL_FACETS` facets per eye every facet with its
outline, otherwise one solid ellipse; the graticule) is drawn once and kept as a pixel
background; a new state sets the lit facets' polygons in place and repaints them and the
outlines over that background (blitting). Above MAX_ALL_FACETS facets an eye they are
painted as pixels instead (:mod:`eyeviz.app.panels.lit_raster`). The maps are drawn
in the exact Mollweide projection (:func:`eyeviz.render.mpl.facet_map.mollweide`) on plain
axes, so the point under the mouse is inverted in closed form and handed to the provider
(:func:`~eyeviz.render.mpl.facet_map.facet_at`): hovering shows the facet's index, its
direction (azimuth from +x counter-clockwise seen from above, forward = 90 deg, and
elevation, docs/conventions.md) and its size (a HEALPix facet's solid angle 4 pi / npix, a
measured facet's acceptance angle).
"""

from __future__ import annotations

import math
import time

import numpy as np
from matplotlib.backends.backend_qt5agg import FigureCanvasQTAgg
from matplotlib.collections import PathCollection, PolyCollection
from matplotlib.colors import to_rgba_array
from matplotlib.figure import Figure
from matplotlib.patches import Polygon
from PyQt5 import QtCore, QtWidgets

from eyeviz.app.panels.common import LinesLabel, follows_text_scale, text_scale, wrap_label
from eyeviz.app.panels.lit_raster import LitRaster
from eyeviz.app.panels.map_geometry import (
    R2,
    Outlines,
    all_polys,
    by_ball,
    edge_colour,
    ellipse,
    fit_words,
    label_side,
    lit_owners,
    map_polys,
    place_side_words,
)
from eyeviz.app.panels.map_zoom import MapZoom
from eyeviz.model import responses3d as r3
from eyeviz.model.facet_patches import FacetPatches, facet_patches, patches_caption_forms
from eyeviz.model.scene import Scene
from eyeviz.model.state3d import SceneState3D
from eyeviz.render.mpl.facet_map import (
    MAX_ALL_FACETS,
    compound_path,
    facet_at,
    mollweide,
    view_lonlat,
)
from eyeviz.render.mpl.style import GREY, INK, UNLIT

__all__ = ["Bitmaps3DPanel", "lit_owners"]

EYES = ("A", "B")
STEP = 2  # outline points per facet edge
HALO_LW = 2.2  # the selected ball's outline (points; about half of it shows outside)
MAP_PT = 8.0  # the maps' words (left / forward / right, the equator) at text scale 1
MAP_TITLE_PT = 9.0  # each map's title at text scale 1
#: the maps' least height (px): normally, and at a text scale of LARGE_TEXT or more, where
#: the Balls table's rows below need the room (F11 + F5 + 175 % in 1280 x 720: its three
#: rows whole made the window 730 px tall)
MAP_MIN_PX = (260, 220)
LARGE_TEXT = 2.0


#: The whole map's limits without the equator's label (the Mollweide ellipse, 1 % margin)
HOME = (-2 * R2 * 1.01, 2 * R2 * 1.01, -R2 * 1.01, R2 * 1.01)


class Bitmaps3DPanel(QtWidgets.QWidget):
    """Eye A over eye B, each a Mollweide map of its facets; see the module docstring.

    ``set_state(state, scene, selected)`` takes a computed :class:`SceneState3D` and the
    selected ball (outlined; None: none); ``update_ms`` holds the time of the last update
    (the lit polygons set and repainted)."""

    def __init__(self, parent: QtWidgets.QWidget | None = None) -> None:
        super().__init__(parent)
        self.nside: int | None = None  # the spherical eyes' (None for other models)
        self.patches: dict[str, FacetPatches] = {}  # per eye: the facets' outline provider
        self.owners: dict[str, tuple[np.ndarray, np.ndarray]] = {}
        self.names: list[str] = []
        self.update_ms = 0.0
        self.hover_pix: tuple[str, int] | None = None
        self.values: dict[str, np.ndarray] = {}  # responses layer: per lit facet (owners')
        self.kind = ""  # the responses' kind
        self._unlit = to_rgba_array([UNLIT])[0]
        self._keys: dict[str, bytes] = {}
        self._bg = None
        self._lit: dict[str, tuple[PathCollection, ...]] = {}
        self.selected: int | None = None
        self._halo: dict[str, PathCollection] = {}  # the selected ball's outline per eye
        # per eye: the selected ball's facets a later ball colours, outlined over the fills
        self._covered: dict[str, PathCollection] = {}
        self._clips: dict[str, Polygon] = {}  # each map's outline (the halo's clip)
        self._halo_keys: dict[str, bytes | None] = {}
        # per eye: the lit facets and their outlines (base, across the edge, second copies)
        self._geom: dict[str, tuple[np.ndarray, ...]] = {}
        self._outlines: dict[str, Outlines] = {}
        # eyes of sub-pixel facets (above MAX_ALL_FACETS): lit facets painted as pixels
        self._raster: dict[str, LitRaster] = {}
        self._over: list = []  # animated artists drawn over the lit facets, in order
        self._under: list = []  # the equator: under the lit facets (never hiding a mark)
        self._home_lim = HOME  # the whole map's limits (a margin for the equator's label)
        self.zoom = MapZoom(lambda: self._home_lim, self._apply_limits)
        self._hover_coll: PolyCollection | None = None
        self._texts: list[tuple] = []  # the maps' words (matplotlib Text, size at scale 1)
        self.fig = Figure(figsize=(3.6, 4.2), facecolor="white")
        self.canvas = FigureCanvasQTAgg(self.fig)
        self.canvas.setSizePolicy(QtWidgets.QSizePolicy.Expanding, QtWidgets.QSizePolicy.Expanding)
        self.canvas.setMinimumSize(240, MAP_MIN_PX[0])
        self.axes = {
            "A": self.fig.add_axes((0.01, 0.535, 0.98, 0.40)),
            "B": self.fig.add_axes((0.01, 0.045, 0.98, 0.40)),
        }
        for eye, ax in self.axes.items():
            ax.set_gid(f"map{eye}")
        self.counts = LinesLabel(2)  # shorter forms, never taller at 175 %; gives way first
        self.hover = LinesLabel(2, wrap=True)  # kept free: the first hover moves nothing
        self.hover.setObjectName("hover3d")
        # over the canvas's top-right corner while zoomed: never moves the dock's layout
        self.whole = QtWidgets.QPushButton("Whole map", self.canvas)
        self.whole.setToolTip("Wheel: zoom the maps; drag: pan; double click: the whole map")
        self.whole.hide()
        self.whole.clicked.connect(self.zoom.reset)
        self.message = wrap_label(QtWidgets.QLabel("bitmaps layer hidden"))
        self.message.setAlignment(QtCore.Qt.AlignmentFlag.AlignCenter)
        lay = QtWidgets.QVBoxLayout(self)
        lay.setContentsMargins(2, 2, 2, 2)
        lay.addWidget(self.counts)
        lay.addWidget(self.canvas, 1)
        lay.addWidget(self.hover)
        lay.addWidget(self.message)
        self.canvas.hide()
        self.canvas.mpl_connect("draw_event", self._on_draw)
        self.canvas.mpl_connect("motion_notify_event", self._on_move)
        self.canvas.mpl_connect("figure_leave_event", self._on_leave)
        self.canvas.mpl_connect("scroll_event", self._on_scroll)
        self.canvas.mpl_connect("button_press_event", self._on_press)
        self.canvas.mpl_connect("button_release_event", lambda _e: self.zoom.release())
        self.canvas.mpl_connect("resize_event", self._place_axes)
        self._fit_text()

    def _place_axes(self, _event=None) -> None:
        """Each map below its title and above its words (left / forward / right) at their
        size now: larger text gives the maps less room, never overlapping words."""
        # the canvas widget's size now (the figure's own lags behind a resize)
        px_per_in = self.fig.dpi / max(self.canvas.devicePixelRatioF(), 1.0)
        h_in = self.canvas.height() / px_per_in
        if h_in <= 0:
            return
        s = text_scale()
        title = 1.2 * MAP_TITLE_PT * s / 72.0 / h_in  # figure fractions
        words = 1.2 * MAP_PT * s / 72.0 / h_in
        if title <= 0.065 and title + words <= 0.09:  # the words fit the margins
            self.axes["A"].set_position((0.01, 0.535, 0.98, 0.40))
            self.axes["B"].set_position((0.01, 0.045, 0.98, 0.40))
            self._fit_words(s, h_in)
            return
        # larger text: the maps as large as the words leave them
        room = max((1.0 - 2.0 * (title + words + 0.008)) / 2.0, 0.05)
        gap = max((1.0 - 2.0 * (room + title + words)) / 3.0, 0.0)  # above, between, below
        top_b = 1.0 - gap - title - room
        self.axes["A"].set_position((0.01, top_b, 0.98, room))
        self.axes["B"].set_position((0.01, top_b - words - gap - title - room, 0.98, room))
        self._fit_words(s, h_in)

    def _fit_words(self, s: float, h_in: float) -> None:
        """The words and titles that fit the maps' width now (see :meth:`_place_axes`), and
        the room beside the whole map that the equator's label takes (off the facets).
        Every word is measured as matplotlib draws it (its renderer at the text size now),
        not estimated from a character count: "left" / "right" go where they overlap
        nothing (:func:`side_words`)."""
        room = self.axes["A"].get_position().height
        px_per_in = self.fig.dpi / max(self.canvas.devicePixelRatioF(), 1.0)
        w_in = self.canvas.width() / px_per_in
        box_w, box_h = 0.98 * w_in, room * h_in
        rend = self.canvas.get_renderer()
        zoomed = self.zoom.zoomed  # the words name the whole map's places
        texts = [t for t, _pt in self._texts]
        label_in = fit_words(texts, rend, self.fig.dpi, 0.98 * w_in, box_h, zoomed)
        self._set_home(label_in, box_w, box_h)
        place_side_words(list(self.axes.values()), rend, self.fig.bbox, zoomed)

    def _set_home(self, label_in: float, box_w: float, box_h: float) -> None:
        """The whole map's limits with ``label_in`` inches beside it for the equator's
        label, on its side; the maps' limits follow unless zoomed."""
        x0, x1, y0, y1 = HOME
        if label_in > 0:
            # map units per inch: the map fills the box's height, or its width less the label
            per_in = max((y1 - y0) / box_h, (x1 - x0) / max(box_w - label_in, 1e-6))
            side = label_side(self.patches["A"]) if self.patches else -1
            m = (label_in + 0.04) * per_in
            x0, x1 = (x0 - m, x1) if side < 0 else (x0, x1 + m)
        self._home_lim = (x0, x1, y0, y1)
        self._apply_limits(redraw=False)

    def _apply_limits(self, redraw: bool = True) -> None:
        """Both maps at the zoom's window (MapZoom.changed); the whole map's words shown
        only on the whole map."""
        x0, x1, y0, y1 = self.zoom.current()
        for ax in self.axes.values():
            ax.set_xlim(x0, x1)
            ax.set_ylim(y0, y1)
        self.whole.adjustSize()
        self.whole.move(max(self.canvas.width() - self.whole.width() - 2, 0), 2)
        self.whole.setVisible(self.zoom.zoomed)
        if redraw:
            self._place_axes()
            self._bg = None
            self.canvas.draw_idle()

    def _on_scroll(self, event) -> None:
        if event.inaxes in self.axes.values() and event.xdata is not None:
            self.zoom.wheel(event.xdata, event.ydata, event.step)

    def _on_press(self, event) -> None:
        ax = event.inaxes
        if ax not in self.axes.values() or event.button != 1:
            return
        if event.dblclick:
            self.zoom.reset()
            return
        x0, x1, y0, y1 = self.zoom.current()
        self.zoom.press(event.x, event.y, (x1 - x0) / ax.bbox.width, (y1 - y0) / ax.bbox.height)

    def changeEvent(self, ev) -> None:  # noqa: N802 (Qt name)
        """Ctrl+= / Ctrl+- / F5 (the app font changed): the maps' words follow."""
        super().changeEvent(ev)
        if follows_text_scale(ev) and hasattr(self, "hover"):
            self._fit_text()

    def _fit_text(self) -> None:
        """The maps' words at the text scale (the hover line keeps its two lines free, so
        that the first hover does not push the panels below it down: issue 32)."""
        s = text_scale()
        self.canvas.setMinimumHeight(MAP_MIN_PX[1] if s >= LARGE_TEXT else MAP_MIN_PX[0])
        for t, pt in self._texts:
            t.set_fontsize(pt * s)
        self._place_axes()
        self._bg = None
        self.canvas.draw_idle()

    # --- state ---------------------------------------------------------------------------

    def set_state(self, state: SceneState3D, scene: Scene, selected: int | None = None) -> None:
        """Show the lit facets of ``state`` (computed from ``scene``) and outline ball
        ``selected``'s: the polygons of the eyes whose lit sets, colours or outline changed
        are set in place and repainted over the kept background; new eyes (another nside,
        another measured pair) redraw the whole figure."""
        t0 = time.perf_counter()
        if state.lit_a is None or state.lit_b is None or not scene.shows("bitmaps"):
            self.canvas.hide()
            self.counts.setText("")
            self.hover.setText("")
            self.message.setText(
                "bitmaps layer hidden" if not scene.shows("bitmaps") else "no lit sets"
            )
            self.message.show()
            self.owners, self._keys, self._halo_keys, self.values = {}, {}, {}, {}
            return
        self.message.hide()
        self.canvas.show()
        pair = state.pair
        patches = {e: facet_patches(pair, e, STEP) for e in EYES}
        if any(patches[e] is not self.patches.get(e) for e in EYES):
            self._build(patches, getattr(pair, "nside", None))
        self.names = [f.name for f in scene.features]
        colors = [f.color for f in scene.features]
        rgba = to_rgba_array(colors) if colors else np.zeros((0, 4))
        changed = False
        counts: list[str] = []
        n = len(scene.features)
        self.selected = selected if selected is not None and 0 <= selected < n else None
        vals = r3.lit_responses(state, self.selected) if scene.shows("responses") else None
        self.values, self.kind = {}, r3.LAYER_KIND.get(pair.kind, "")
        for eye, csr in zip(EYES, (state.lit_a, state.lit_b), strict=True):
            pix, owner = lit_owners(csr)
            self.owners[eye] = (pix, owner)
            ball, colours = owner, rgba
            if vals is not None:  # each facet its ball's colour at its response's shade
                self.values[eye] = r3.owner_values(csr, vals[eye])
                ball, colours = r3.shaded_owners(owner, self.values[eye], rgba, self._unlit)
            key = b"".join((pix.tobytes(), ball.tobytes(), colours.tobytes()))
            if eye in self._raster:
                changed |= self._set_raster(eye, csr, pix, ball, colours, key)
                counts.append(f"{eye} {pix.size:,}")
                continue
            if self._set_halo(eye, csr, pix, key):
                changed = True
            if self._keys.get(eye) == key:
                counts.append(f"{eye} {pix.size:,}")
                continue
            self._keys[eye] = key
            changed = True
            base, over, dup, cnt = self._geom[eye][1:]
            # facets inside the map's outline need no clipping (2 ms a frame at nside 180)
            inner, edge = self._lit[eye]
            paths, fc = by_ball(base[~over], ball[~over], colours, cnt[~over])
            inner.set_paths(paths)
            inner.set_facecolor(fc)
            paths, fc = by_ball(
                np.concatenate([base[over], dup[over]]),
                np.tile(ball[over], 2),
                colours,
                np.tile(cnt[over], 2),
            )
            edge.set_paths(paths)
            edge.set_facecolor(fc)
            counts.append(f"{eye} {pix.size:,}")
        sel = "" if self.selected is None else f"; {self.names[self.selected]!r} outlined"
        lit = "lit: " + ", ".join(counts)
        self.counts.set_lines(
            [patches_caption_forms(pair), (lit + sel, lit, lit.removeprefix("lit: "))]
        )
        if changed:
            self._repaint()
        self.update_ms = (time.perf_counter() - t0) * 1e3

    def _set_raster(self, eye: str, csr, pix, ball, rgba, key: bytes) -> bool:
        """Eye ``eye``'s lit facets and the selected ball's, painted as pixels
        (:class:`LitRaster`); True when they changed."""
        i = self.selected
        indptr, idx = csr
        mine = idx[indptr[i] : indptr[i + 1]] if i is not None else idx[:0]
        key = b"".join((key, b"" if i is None else np.int64(i).tobytes(), mine.tobytes()))
        if self._keys.get(eye) == key:
            return False
        self._keys[eye] = key
        self._raster[eye].set(pix, ball, rgba, mine)
        return True

    def _set_halo(self, eye: str, csr, pix: np.ndarray, key: bytes) -> bool:
        """Outline the selected ball's lit facets on eye ``eye`` (``pix`` all lit facets,
        ``key`` their drawing's key); True when the outline changed. Keeps the facets'
        outlines of ``pix`` in ``_geom`` (computed once per lit set)."""
        if self._keys.get(eye) != key or eye not in self._geom:
            self._geom[eye] = (pix, *self._outlines[eye].get(pix))
        i = self.selected
        indptr, idx = csr
        mine = idx[indptr[i] : indptr[i + 1]] if i is not None else idx[:0]
        hkey = None if i is None else b"".join((key, np.int64(i).tobytes(), mine.tobytes()))
        if self._halo_keys.get(eye, b"") == hkey:
            return False
        self._halo_keys[eye] = hkey
        lit, base, over, dup, cnt = self._geom[eye]
        k = np.searchsorted(lit, mine)
        across = over[k]
        verts = np.concatenate([base[k], dup[k[across]]])
        counts = np.concatenate([cnt[k], cnt[k[across]]])
        halo = self._halo[eye]
        halo.set_paths([compound_path(verts, counts)] if len(verts) else [])
        # where a later ball colours its facets the stroke under the fills is hidden: those
        # facets' outlines go over the fills (thin: the other ball's colour stays)
        hid = k[self.owners[eye][1][k] != i] if i is not None else k[:0]
        v2, c2 = (
            np.concatenate([base[hid], dup[hid[over[hid]]]]),
            np.concatenate([cnt[hid], cnt[hid[over[hid]]]]),
        )
        self._covered[eye].set_paths([compound_path(v2, c2)] if len(v2) else [])
        self._covered[eye].set_clip_path(self._clips[eye] if over[hid].any() else None)
        # clipped to the map only when the patch crosses its edge (a clip path costs a
        # mask of the whole map at every repaint)
        halo.set_clip_path(self._clips[eye] if across.any() else None)
        return True

    def outlined(self, eye: str) -> int:
        """How many facet outlines the selected ball's outline on eye ``eye`` holds (its
        lit facets, those across the map's edge twice; tests)."""
        if eye in self._raster:
            return int(self._raster[eye].sel.size)
        h = self._halo.get(eye)
        if h is None:
            return 0
        return sum(int(np.count_nonzero(np.asarray(p.codes) == p.MOVETO)) for p in h.get_paths())

    def lit_facets(self, eye: str) -> np.ndarray:
        """The facets drawn lit on eye ``eye``'s map (sorted RING indices)."""
        return self.owners[eye][0] if eye in self.owners else np.zeros(0, np.int64)

    # --- drawing -------------------------------------------------------------------------

    # long: both eyes' maps set up in drawing order (axes, outlines, labels, empty lit
    # collections): matplotlib calls, not logic
    def _build(self, patches: dict[str, FacetPatches], nside: int | None) -> None:
        """The static parts for the eyes' facets ``patches`` and empty lit collections."""
        self.nside = nside
        self.patches = patches
        self._outlines = {e: Outlines(p) for e, p in patches.items()}
        halo_px = round(HALO_LW / 2 * self.fig.dpi / 72)
        self._raster = {
            e: LitRaster(p, halo_px) for e, p in patches.items() if p.n > MAX_ALL_FACETS
        }
        self._keys = {}
        self._halo_keys = {}
        self._geom = {}
        self._over = []
        self._under = []
        self.zoom.limits = None  # new eyes: the whole map
        self._texts = []
        self._bg = None
        ell = ellipse()
        for eye, ax in self.axes.items():
            n_pix = patches[eye].n
            ax.clear()
            ax.set_axis_off()
            x0, x1, y0, y1 = self.zoom.current()
            ax.set_xlim(x0, x1)
            ax.set_ylim(y0, y1)
            ax.set_aspect("equal", adjustable="box", anchor="C")
            clip = Polygon(ell, closed=True, transform=ax.transData)
            if n_pix <= MAX_ALL_FACETS:  # every facet, outlined
                verts, _, cnt = all_polys(patches[eye])
                back = PolyCollection(
                    [v[:c] for v, c in zip(verts, cnt, strict=True)], facecolors=UNLIT,
                    edgecolors=edge_colour(n_pix), linewidths=0.3,
                )  # fmt: skip
            else:  # the unlit sphere as one solid ellipse
                back = PolyCollection([ell], facecolors=UNLIT, edgecolors="none")
            back.set_clip_path(clip)
            ax.add_collection(back, autolim=False)
            back.set_clip_box(ax.bbox)  # a zoomed map: within its axes too
            for deg in (-60, -30, 30, 60):  # a faint graticule: elevation seen from the eye
                x, y = mollweide(np.linspace(-math.pi, math.pi, 2), np.full(2, math.radians(deg)))
                ax.plot(x, y, color="#c8c8c8", lw=0.4)
            for deg in (-90, 90):
                lat = np.linspace(-math.pi / 2, math.pi / 2, 61)
                x, y = mollweide(np.full_like(lat, math.radians(deg)), lat)
                ax.plot(x, y, color="#c8c8c8", lw=0.4)
            ax.plot(ell[:, 0], ell[:, 1], color=GREY, lw=0.6)
            # left and right flush with the map's ends: apart from "forward" at any text size
            for tx, t, ha in ((-2 * R2, "left", "left"), (0.0, "forward", "center"),
                              (2 * R2, "right", "right")):  # fmt: skip
                word = ax.text(tx, -R2 * 1.01, t, color=GREY, ha=ha, va="top")
                self._texts.append((word, MAP_PT))
            # the lit facets: outlined when all facets are (as the unlit ones), plain above
            # (a stroke of every facet cost 7 ms a frame at nside 180); those across the
            # map's edge in a collection of their own, clipped to the outline
            edged = n_pix <= MAX_ALL_FACETS
            lit = tuple(
                PathCollection(
                    [],
                    edgecolors=edge_colour(n_pix),
                    linewidths=0.3 if edged else 0.0,
                    animated=True,
                )
                for _ in range(2)
            )
            lit[1].set_clip_path(clip)
            # the selected ball's outline: a thick stroke under the fills (only the border
            # of its patch shows), clipped to the map
            halo = PathCollection(
                [], facecolors="none", edgecolors=INK, linewidths=HALO_LW, animated=True
            )
            halo.set_gid(f"selected{eye}")
            covered = PathCollection(
                [], facecolors="none", edgecolors=INK, linewidths=1.0, animated=True
            )
            self._covered[eye] = covered
            self._clips[eye] = clip
            for c in (halo, *lit, covered):
                ax.add_collection(c, autolim=False)
                c.set_clip_box(ax.bbox)
            self._lit[eye] = lit
            self._halo[eye] = halo
            (eq,) = ax.plot([-2 * R2, 2 * R2], [0.0, 0.0], color=INK, lw=0.8, animated=True)
            side = label_side(patches[eye])
            # beside the map, off the facets (its room is kept in the limits: _fit_words)
            eq_word = ax.text(
                side * 2 * R2 * 1.02, 0.0,
                "equator:\nthe plane\nz = 0" if nside is None
                else f"equator:\nthe planar\neye, m = {4 * nside:,}",
                color=INK, ha="right" if side < 0 else "left", va="center", gid="equator",
            )  # fmt: skip
            title = ax.text(
                0.5, 1.0, f"eye {eye} ({'left' if eye == 'A' else 'right'}), seen from inside",
                transform=ax.transAxes, color=INK, ha="center", va="bottom", gid="maptitle",
            )  # fmt: skip
            self._texts += [(eq_word, MAP_PT), (title, MAP_TITLE_PT)]
            self._under.append(eq)
            self._over += [(ax, halo), (ax, lit[0]), (ax, lit[1]), (ax, covered)]
        self._hover_coll = PolyCollection(
            [], facecolors="none", edgecolors="#000000", linewidths=1.2, animated=True
        )
        self._hover_ax = None
        self._fit_text()

    def _draw_over(self) -> None:
        for line in self._under:
            self.fig.draw_artist(line)
        if self._raster:  # sub-pixel facets: straight into the canvas's pixels
            buf = np.asarray(self.canvas.buffer_rgba())
            ink = np.round(to_rgba_array([INK])[0] * 255).astype(np.uint8)
            for r in self._raster.values():
                r.paint(buf, ink)
        for _, artist in self._over:
            if isinstance(artist, PathCollection) and not artist.get_paths():
                continue  # nothing lit or selected on that map: not even a draw call
            self.fig.draw_artist(artist)
        if self.hover_pix is not None and self._hover_coll is not None:
            self.fig.draw_artist(self._hover_coll)

    def _on_draw(self, _event) -> None:
        """After a full draw: keep the background, then paint the animated parts."""
        self._bg = self.canvas.copy_from_bbox(self.fig.bbox)
        if self._raster:  # the figure's pixels may have moved (a resize)
            height = np.asarray(self.canvas.buffer_rgba()).shape[0]
            for eye, r in self._raster.items():
                r.layout(self.axes[eye], height)
        self._draw_over()

    def _repaint(self) -> None:
        """The lit facets, the equator and the hover outline over the kept background."""
        if self._bg is None or not self.canvas.isVisible():
            self.canvas.draw_idle()
            return
        self.canvas.restore_region(self._bg)
        self._draw_over()
        self.canvas.blit(self.fig.bbox)

    # --- hover ---------------------------------------------------------------------------

    def facet_at(self, eye: str, x: float, y: float) -> int:
        """The facet of eye ``eye`` drawn at (x, y) of its map (Mollweide plane), -1 off
        the map."""
        if eye not in self.patches:
            return -1
        return int(facet_at(self.patches[eye], x, y))

    def _on_move(self, event) -> None:
        if self.zoom.drag(event.x, event.y):
            return
        eye = next((e for e, ax in self.axes.items() if event.inaxes is ax), None)
        if eye is None or event.xdata is None or not self.patches:
            self._set_hover(None)
            return
        pix = self.facet_at(eye, event.xdata, event.ydata)
        self._set_hover((eye, pix) if pix >= 0 else None)

    def _on_leave(self, _event) -> None:
        self._set_hover(None)

    def _set_hover(self, hit: tuple[str, int] | None) -> None:
        if hit == self.hover_pix:
            return
        self.hover_pix = hit
        if hit is None or not self.patches:
            self.hover.setText("")
            self.canvas.setToolTip("")
            self._repaint()
            return
        eye, pix = hit
        patches = self.patches[eye]
        text = f"eye {eye}, " + patches.describe(pix)
        lit, ball = self.owners.get(eye, (np.zeros(0, np.int64), np.zeros(0, np.int64)))
        k = int(np.searchsorted(lit, pix))
        if k < lit.size and lit[k] == pix:
            text += f"; lit by {self.names[int(ball[k])]!r}"
            if eye in self.values:
                text += "; " + r3.response_text(float(self.values[eye][k]), self.kind)
        self.hover.setText(text)
        self.canvas.setToolTip(text)
        assert self._hover_coll is not None
        verts, _, cnt = map_polys(patches, np.array([pix]))
        self._hover_coll.set_verts([v[:c] for v, c in zip(verts, cnt, strict=True)])
        ax = self.axes[eye]
        if self._hover_coll.axes is not ax:
            if self._hover_coll.axes is not None:
                self._hover_coll.remove()
            ax.add_collection(self._hover_coll, autolim=False)
            self._hover_coll.set_clip_path(Polygon(ellipse(), closed=True, transform=ax.transData))
            self._hover_coll.set_clip_box(ax.bbox)
        self._repaint()

    def map_point(self, eye: str, pix: int) -> tuple[float, float]:
        """The Mollweide-plane point of facet ``pix``'s centre on eye ``eye``'s map."""
        c = self.patches[eye].centers(np.array([pix]))[0]
        mx, my = view_lonlat(math.atan2(c[1], c[0]), math.asin(max(-1.0, min(1.0, c[2]))))
        x, y = mollweide(mx, my)
        return float(x), float(y)
