"""The canvas event bridge: Qt events on the view -> model gestures; model cameras -> VTK.

Only translation lives here: pixels are measured from the widgets and handed to
:mod:`eyeviz.model.interactions` (press, wheel, pan, fit) and :mod:`eyeviz.model.camera`
(pixel <-> model); no scene edit or camera maths is done in Qt code.
"""

from __future__ import annotations

import math
from collections.abc import Generator
from typing import TYPE_CHECKING

import numpy as np
from PyQt5 import QtCore, QtWidgets

from eyeviz.model import camera, interactions
from eyeviz.model.app_model import DOT_PX, MouseEvent, hit_test
from eyeviz.model.camera import Viewport
from eyeviz.model.scene import View
from eyeviz.render.vtk.actors import inset_viewport

if TYPE_CHECKING:
    from vtkmodules.vtkRenderingCore import vtkRenderer, vtkTextActor

    from eyeviz.app.view import _Frames
    from eyeviz.model.app_model import AppModel
    from eyeviz.render.vtk.actors import SceneActors

    _MainWindow = QtWidgets.QMainWindow
else:
    _MainWindow = object  # MainWindow brings QMainWindow

__all__ = ["CanvasMixin"]

CAMERA_DISTANCE = 1000.0
INSET_HIDE_EYE_PX = 40.0  # eyes at least this wide on screen: no magnified inset
RESIZE_MODIFIERS = (
    QtCore.Qt.KeyboardModifier.ShiftModifier | QtCore.Qt.KeyboardModifier.ControlModifier
)
TITLE_MARGIN_PX = 10.0  # the title's distance from the view's top-left corner
LABEL_CHAR_PX = 14.0  # a character of a feature's label (22 px bold DejaVu Sans)
TITLE_BAND_PX = 48.0  # the band a fit keeps free for the title (24 px text + margins)
TANGENT_NOTE_PX = 34.0  # the tangents' note (20 px text) and a margin under it


class CanvasMixin(_MainWindow):
    """Mixed into MainWindow: needs ``plotter``, ``model``, ``main_ren``, ``inset_ren``,
    ``actors``, ``title_actor``, ``cursor_label``, ``inset_shown``, ``render`` and
    ``toggle_play``."""

    # MainWindow's (set in its __init__)
    model: AppModel
    plotter: _Frames
    main_ren: vtkRenderer
    inset_ren: vtkRenderer
    actors: SceneActors
    title_actor: vtkTextActor
    cursor_label: QtWidgets.QLabel
    inset_shown: bool
    context_menu: QtWidgets.QMenu  # the last one shown (tests)

    if TYPE_CHECKING:  # for mypy only: at run time MainWindow's and SideDocksMixin's

        def render(self) -> None: ...  # type: ignore[override]  # MainWindow's, not QWidget's

        def toggle_play(self) -> None: ...

    _drag: Generator[None, MouseEvent, None] | None = None
    _drag_which = "main"
    _fitted_view: View | None = None  # the main view as the last fit left it

    # --- pixels <-> model ------------------------------------------------------------
    def viewport(self, which: str) -> Viewport:
        """A renderer's rectangle in widget pixels (y down)."""
        w, h = max(self.plotter.width(), 1), max(self.plotter.height(), 1)
        if which == "main":
            return Viewport(0.0, 0.0, float(w), float(h))
        x0, y0, x1, y1 = inset_viewport(w, h)
        return Viewport(x0 * w, (1.0 - y1) * h, (x1 - x0) * w, (y1 - y0) * h)

    def _viewport_px(self, which: str) -> tuple[float, float, float, float]:
        vp = self.viewport(which)
        return vp.left, vp.top, vp.width, vp.height

    def _view(self, which: str) -> View:
        return interactions.view_of(self.model, which)

    @property
    def inset_view(self) -> View:
        return self.model.inset_view

    @property
    def inset_auto(self) -> bool:
        return self.model.inset_auto

    def units_per_px(self, which: str = "main") -> float:
        return camera.units_per_px(self._view(which), self.viewport(which))

    def which_at(self, px: float, py: float) -> str:
        return "inset" if self.inset_shown and self.viewport("inset").contains(px, py) else "main"

    def to_model(self, px: float, py: float, which: str | None = None) -> tuple[str, float, float]:
        """Widget pixel -> (which renderer, x, y) in model units."""
        which = which or self.which_at(px, py)
        x, y = camera.to_model(self._view(which), self.viewport(which), px, py)
        return which, x, y

    def to_pixel(self, x: float, y: float, which: str = "main") -> tuple[float, float]:
        return camera.to_pixel(self._view(which), self.viewport(which), x, y)

    # --- model cameras -> VTK -----------------------------------------------------------
    def apply_cameras(self) -> None:
        w, h = max(self.plotter.width(), 1), max(self.plotter.height(), 1)
        self.inset_ren.SetViewport(*inset_viewport(w, h))
        # the title's top-left corner a fixed number of pixels from the view's corner
        self.title_actor.SetPosition(TITLE_MARGIN_PX / w, 1.0 - TITLE_MARGIN_PX / h)
        self._update_inset_visibility()
        for which, ren in (("main", self.main_ren), ("inset", self.inset_ren)):
            vp = self.viewport(which)
            v = self._view(which)
            cam = ren.GetActiveCamera()
            cam.ParallelProjectionOn()
            cx, cy = v.center
            cam.SetFocalPoint(cx, cy, 0.0)
            cam.SetPosition(cx, cy, CAMERA_DISTANCE)
            cam.SetViewUp(0.0, 1.0, 0.0)
            cam.SetParallelScale(v.width * vp.height / vp.width / 2.0)
            cam.SetClippingRange(1.0, 2.0 * CAMERA_DISTANCE)
        e = self.model.scene.eyes
        self.actors.set_zoom(
            1.0 / self.units_per_px("main"), 1.0 / self.units_per_px("inset"), e.l, e.m
        )

    def _inset_wanted(self) -> bool:
        """The inset magnifies the eyes; where they are already large on screen (or the
        scene has no eyes) it would only duplicate the main view."""
        e = self.model.scene.eyes
        eye_px = 2.0 * e.l / self.units_per_px("main")
        return self.model.scene.shows("eyes") and eye_px < INSET_HIDE_EYE_PX

    def _feature_under_inset(self, only: int | None = None) -> bool:
        """A feature's disc (or its centre dot) drawn where the inset sits (``only``: that
        feature's)."""
        sc = self.model.scene
        if not sc.features or not sc.shows("features"):
            return False
        st = self.model.state
        x, y, g = st.x, st.y, st.g
        if only is not None:
            x, y, g = x[only : only + 1], y[only : only + 1], g[only : only + 1]
        rect = self.viewport("inset")
        return camera.discs_meet(sc.view, self.viewport("main"), x, y, g, rect, DOT_PX)

    def _update_inset_visibility(self, moved: int | None = None) -> None:
        """Show the inset where it is wanted and hides no feature: a feature dragged or
        fitted under it hides the inset instead (it comes back once the corner is free).
        ``moved``: only that feature changed, so a shown inset asks only about it."""
        only = moved if moved is not None and self.inset_shown else None
        if only is not None and only >= len(self.model.scene.features):
            only = None
        wanted = self._inset_wanted()
        want = wanted and not self._feature_under_inset(only)
        # the main view names the eyes only where they are large on screen: a tiny pair
        # whose inset stepped aside for a feature would carry A, O, B on top of each other
        labels = not wanted
        if (
            want != self.inset_shown
            or self.inset_ren.GetDraw() != want
            or labels != self.actors.labels.main_eye_labels_shown
        ):
            self.inset_shown = want
            self.inset_ren.SetDraw(want)
            self.actors.set_inset_shown(want, main_eye_labels=labels)

    def title_band_px(self) -> float:
        """Pixels at the top of the view taken by the scene's title (none without one) and
        the tangents' note under it, at the window's text scale (eyeviz.app.presenting)."""
        presenter = getattr(self, "presenter", None)
        s = presenter.effective_scale if presenter is not None else 1.0
        sc = self.model.scene
        band = TITLE_BAND_PX * s if sc.title.strip() else 0.0
        if sc.shows("tangents") and self.model.selected is not None:
            # the note's top at a tenth of the view's height (render.vtk.layers.tangents)
            band = max(band, 0.1 * self.plotter.height() + TANGENT_NOTE_PX * s)
        return band

    def label_band_px(self) -> float:
        """About the widest feature label in pixels (22 px bold text, see SceneActors)."""
        sc = self.model.scene
        if not (sc.shows("labels") and sc.shows("features")) or not sc.features:
            return 0.0
        presenter = getattr(self, "presenter", None)
        s = presenter.effective_scale if presenter is not None else 1.0  # Ctrl+= grows them
        return LABEL_CHAR_PX * s * (1 + max(len(f.name) for f in sc.features))

    def fit_view(self) -> None:
        """F: every feature and the eyes in view, none under the inset or the title. The
        view then follows the window's size until the user zooms or pans it."""
        avoid = self.viewport("inset") if self._inset_wanted() else None
        top, right = self.title_band_px(), self.label_band_px()
        path = self._path_box()
        interactions.fit_view(self.model, self.viewport("main"), avoid, top, right, path)
        # fitting may make the eyes large (no inset wanted): then fit the whole view
        if avoid is not None and not self._inset_wanted():
            interactions.fit_view(self.model, self.viewport("main"), None, top, right, path)
        self._update_inset_visibility()
        self._fitted_view = self.model.scene.view

    def _path_box(self) -> tuple[float, float, float, float] | None:
        """What F frames besides the eyes and the features: the shown trajectory's path,
        the estimators' ghost discs and the sector rays (issue 24: none under the title)."""
        xs: list[float] = []
        ys: list[float] = []
        panel = getattr(self, "trajectory_panel", None)
        p = panel.path if panel is not None else None
        if p is not None and self.model.scene.shows("trajectory") and p.n > 0:
            xs += [float(p.x.min()) - p.g, float(p.x.max()) + p.g]
            ys += [float(p.y.min()) - p.g, float(p.y.max()) + p.g]
        g = np.array([f.g for f in self.model.scene.features], dtype=float)
        for res in self.model.predictions.values():
            if isinstance(res, str):
                continue
            r, phi = np.asarray(res[0], float), np.asarray(res[1], float)
            ok = np.isfinite(r) & np.isfinite(phi)
            if r.shape != g.shape or not ok.any():
                continue
            x, y, gg = r[ok] * np.cos(phi[ok]), r[ok] * np.sin(phi[ok]), g[ok]
            xs += [float((x - gg).min()), float((x + gg).max())]
            ys += [float((y - gg).min()), float((y + gg).max())]
        # the selected feature's sector rays (they reach past the disc: none under the title
        # or its tangents' note)
        sectors = self.actors.painters.get("sectors")
        if self.model.scene.shows("sectors") and getattr(sectors, "shown", False):
            pts = np.asarray(sectors.mesh.points)[:, :2]  # type: ignore[union-attr]
            xs += [float(pts[:, 0].min()), float(pts[:, 0].max())]
            ys += [float(pts[:, 1].min()), float(pts[:, 1].max())]
        if not xs:
            return None
        return min(xs), max(xs), min(ys), max(ys)

    def fit_inset(self) -> None:
        interactions.fit_inset(self.model, self.viewport("inset"))

    def _resized(self) -> None:
        if self.inset_auto:
            self.fit_inset()
        if self._fitted_view is not None and self.model.scene.view == self._fitted_view:
            self.fit_view()  # fitted and not zoomed or panned since: stay fitted
        elif not self.inset_auto:
            self.apply_cameras()
            self.render()

    # --- events ---------------------------------------------------------------------
    def _status(self, which: str, x: float, y: float) -> None:
        r = math.hypot(x, y)
        phi = math.degrees(math.atan2(y, x)) % 360.0
        self.cursor_label.setText(f"x {x:,.1f}   y {y:,.1f}     r {r:,.1f}   φ {phi:.2f}°")

    def eventFilter(self, obj, ev) -> bool:  # noqa: N802 (Qt name)
        if obj is not self.plotter:
            return False
        t = ev.type()
        E = QtCore.QEvent.Type
        if t == E.MouseButtonPress:
            self.plotter.setFocus(QtCore.Qt.FocusReason.MouseFocusReason)
            self._press(ev)
            return True
        if t == E.MouseMove:
            which, x, y = self.to_model(ev.x(), ev.y(), self._drag_which if self._drag else None)
            self._status(which, x, y)
            if self._drag is not None:
                self._send(MouseEvent("move", x, y, ev.x(), ev.y()))
            return True
        if t == E.MouseButtonRelease:
            if self._drag is not None:
                _, x, y = self.to_model(ev.x(), ev.y(), self._drag_which)
                self._send(MouseEvent("release", x, y, ev.x(), ev.y()))
                self._drag = None
            return True
        if t == E.Wheel:
            self._wheel(ev)
            return True
        if t == E.ContextMenu:
            self._context_menu(ev.pos(), ev.globalPos())
            return True
        if t == E.KeyPress and ev.key() == QtCore.Qt.Key.Key_Space and not ev.isAutoRepeat():
            self.toggle_play()  # Space plays only while the view has the focus
            return True
        if t in (E.MouseButtonDblClick, E.KeyPress, E.KeyRelease):
            return True
        if t == E.Resize:
            QtCore.QTimer.singleShot(0, self._resized)
        return False

    def _press(self, ev) -> None:
        which, x, y = self.to_model(ev.x(), ev.y())
        me = MouseEvent("press", x, y, ev.x(), ev.y())
        if self._drag is not None:  # a press while another button drags: end that drag
            self._send(MouseEvent("release", x, y, ev.x(), ev.y()))
        button = {
            QtCore.Qt.MouseButton.LeftButton: "left",
            QtCore.Qt.MouseButton.MiddleButton: "middle",
        }.get(ev.button(), "other")
        main_vp = self.viewport("main") if which == "inset" else None
        self._drag = interactions.press(
            self.model, me, which, self.viewport(which), button, main_vp
        )
        self._drag_which = which

    def _send(self, me: MouseEvent) -> None:
        assert self._drag is not None  # called only while a drag runs
        try:
            self._drag.send(me)
        except StopIteration:
            self._drag = None

    def _wheel(self, ev) -> None:
        d = ev.angleDelta()
        steps = (d.y() or d.x()) / 120.0  # Shift+wheel may arrive as a horizontal wheel
        px, py = ev.pos().x(), ev.pos().y()
        which = self.which_at(px, py)
        resize = bool(ev.modifiers() & RESIZE_MODIFIERS)
        interactions.wheel(self.model, which, self.viewport(which), px, py, steps, resize)

    def _context_menu(self, pos: QtCore.QPoint, global_pos: QtCore.QPoint) -> QtWidgets.QMenu:
        which, x, y = self.to_model(pos.x(), pos.y())
        sc = self.model.scene
        i, _ = hit_test(sc, self.model.selected, x, y, self.units_per_px(which))
        menu = QtWidgets.QMenu(self)
        menu.addAction(f"Add feature at ({x:,.0f}, {y:,.0f})", lambda: self.model.add_feature(x, y))
        if i is not None:
            name = sc.features[i].name
            menu.addAction(f"Duplicate {name}", lambda: self.model.duplicate_feature(i))
            menu.addAction(f"Delete {name}", lambda: self.model.delete_feature(i))
        menu.popup(global_pos)
        self.context_menu = menu
        return menu
