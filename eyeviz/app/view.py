"""The VTK view widget: a native X window that VTK renders into directly.

Two implementations behind one switch (``BACKEND``, or ``$EYEVIZ_VIEW`` = ``pyvistaqt`` |
``vtk``), both a native-window ``QWidget`` drawing one VTK render per frame:

- ``pyvistaqt`` (the default, as the design names it): pyvistaqt's ``QtInteractor``
  pinned at 0.12.0, the last release whose ``QtInteractor`` is a native-window
  ``QWidget``; 0.13 made it a ``QOpenGLWidget``, whose ``paintGL`` renders again after every
  explicit render and whose frame Qt composites over the whole top-level window (1.3-3x the
  latency on software OpenGL). It is built with ``multi_samples=0, auto_update=False,
  lighting="none"``, OIT and depth peeling off, and frames go through ``plotter.render()``;
- ``vtk``: VTK's own ``QVTKRenderWindowInteractor``.

``scripts/bench_app.py`` measures both in the same run, in the order a, b, b, a (the
first window of a run measured up to ~10 % slower). Over five such runs on a quiet
2-core machine (issue 12) pyvistaqt's drag p50 was 0.98-1.11x of the native widget's at
m = 720 (mean 1.05x) and 0.95-1.12x at m = 36,000 (mean 1.03x): equal within the run-to-run
noise, so the design's choice is the default; ``EYEVIZ_VIEW=vtk`` selects VTK's own
widget.

The window never lets VTK's interactor styles see a mouse event (the main window filters
them), so this widget only renders.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from typing import TYPE_CHECKING

import vtkmodules.vtkRenderingFreeType  # noqa: F401  (text actors)
import vtkmodules.vtkRenderingOpenGL2  # noqa: F401  (the OpenGL render window)
from vtkmodules.qt.QVTKRenderWindowInteractor import QVTKRenderWindowInteractor
from vtkmodules.vtkRenderingCore import vtkRenderer, vtkRenderWindow

if TYPE_CHECKING:
    from PyQt5.QtWidgets import QWidget as _QWidget
else:
    _QWidget = object  # the views' Qt base comes from VTK's or pyvistaqt's class

__all__ = ["BACKEND", "BACKENDS", "NativeView", "VtkView", "fast_renderer", "make_view"]

BACKENDS = ("pyvistaqt", "vtk")
BACKEND = os.environ.get("EYEVIZ_VIEW", "pyvistaqt")


def fast_renderer(background: tuple[float, float, float] = (1.0, 1.0, 1.0)) -> vtkRenderer:
    """A renderer without order-independent translucency (VTK 9's default).

    OIT renders every frame with translucent props (all text actors are) through extra
    full-screen floating-point passes: ~9 ms of a ~17 ms frame in llvmpipe. Plain alpha
    blending is exact here: the 2D top view has no overlapping translucent surfaces.
    """
    ren = vtkRenderer()
    _plain(ren)
    ren.SetBackground(*background)
    return ren


def _plain(ren: vtkRenderer) -> None:
    ren.SetUseOIT(False)
    ren.SetUseDepthPeeling(False)


class _Frames(_QWidget):
    """What the window needs of a view: ``draw``, ``frames``, ``before_render``."""

    backend: str
    ren_win: vtkRenderWindow
    renderer: vtkRenderer
    closed = False
    frames = 0  # renders completed: the bench's "frame that reflects the event"
    before_render: Callable[[], None] | None = None  # run before each render (pending updates)
    grabbing = False  # the window is being grabbed: its picture of this view is not used

    def _init_frames(self) -> None:
        self.frames = 0
        self.before_render = None
        self.closed = False
        self.ren_win.SetMultiSamples(0)
        self.ren_win.SetLineSmoothing(False)
        self.ren_win.SetPointSmoothing(False)
        self.ren_win.SetPolygonSmoothing(False)

    def set_background(self, color: tuple[float, float, float]) -> None:
        self.renderer.SetBackground(*color)

    def _render_now(self) -> None:
        self.ren_win.Render()

    def draw(self) -> None:
        """Apply pending updates, then render synchronously (never after close)."""
        if self.closed:
            return
        if self.before_render is not None:
            self.before_render()
        self._render_now()
        self.frames += 1

    def paintEvent(self, ev) -> None:  # noqa: N802 (Qt name)
        if self.isVisible() and not self.grabbing:
            self.draw()


class NativeView(_Frames, QVTKRenderWindowInteractor):
    """VTK's ``QWidget`` with a native window VTK renders into (no multisampling)."""

    backend = "vtk"

    def __init__(self, parent: _QWidget | None = None) -> None:
        QVTKRenderWindowInteractor.__init__(self, parent)
        self.ren_win = self.GetRenderWindow()
        self._init_frames()
        self.renderer = fast_renderer()
        self.ren_win.AddRenderer(self.renderer)
        self._Iren.SetInteractorStyle(None)

    def close(self) -> bool:
        if not self.closed:
            self.closed = True
            self.Finalize()
        return super().close()


def _pyvistaqt_view(parent: _QWidget | None = None) -> _Frames:
    """pyvistaqt 0.12.0's ``QtInteractor`` set up for one render per frame."""
    from pyvistaqt import QtInteractor

    # pyvista types ren_win as Optional and renderer as a property (this class sets and
    # reads both as _Frames declares them); QWidget.update and BasePlotter.update clash in
    # QtInteractor itself
    class PyvistaView(_Frames, QtInteractor):  # type: ignore[misc]
        backend = "pyvistaqt"

        def __init__(self, parent: _QWidget | None = None) -> None:
            QtInteractor.__init__(self, parent, multi_samples=0, auto_update=False, lighting="none")
            self._init_frames()
            for ren in self.renderers:
                _plain(ren)
                ren.SetBackground(1.0, 1.0, 1.0)
            self.iren.interactor.SetInteractorStyle(None)

        # pyvista's is a functools.wraps object no def can match
        def set_background(self, color, *args, **kwargs) -> None:  # type: ignore[override]
            """The main renderer only (pyvista's would paint the inset too)."""
            import pyvista as pv

            self.renderer.SetBackground(*pv.Color(color).float_rgb)

        def _render_now(self) -> None:
            self.render()  # pyvista's path: BasePlotter.render -> one ren_win.Render()

        # QWidget.close's bool (pyvistaqt's returns None)
        def close(self) -> bool:  # type: ignore[override]
            if not self.closed:
                self.closed = True
                QtInteractor.close(self)
            return True

    return PyvistaView(parent)


def make_view(parent: _QWidget | None = None, backend: str | None = None) -> _Frames:
    """The view widget of ``backend`` (default: :data:`BACKEND`)."""
    backend = backend or BACKEND
    if backend == "pyvistaqt":
        return _pyvistaqt_view(parent)
    if backend != "vtk":
        from eyeviz import EyevizError

        raise EyevizError(f"EYEVIZ_VIEW must be one of {', '.join(BACKENDS)}, got {backend!r}")
    return NativeView(parent)


def VtkView(parent: _QWidget | None = None) -> _Frames:  # noqa: N802 (the window's call site)
    """The view of the configured backend (see :func:`make_view`)."""
    return make_view(parent)
