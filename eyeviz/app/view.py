"""The VTK view widget: a native X window that VTK renders into directly.

Why not pyvistaqt's ``QtInteractor`` (a ``QOpenGLWidget``): on this machine's software
OpenGL (llvmpipe under Xvfb) its frame costs two VTK renders (``paintGL`` always renders
again after an explicit ``Render()``) plus a GL composition of the whole top-level window
by Qt (~17 ms at 1280x800). A native child window costs one render and one buffer swap
of the view only. Measured with ``scripts/bench_app.py``; see the README.

The window never lets VTK's interactor styles see a mouse event (the main window filters
them), so this widget only renders.
"""

from __future__ import annotations

import vtkmodules.vtkRenderingFreeType  # noqa: F401  (text actors)
import vtkmodules.vtkRenderingOpenGL2  # noqa: F401  (the OpenGL render window)
from vtkmodules.qt.QVTKRenderWindowInteractor import QVTKRenderWindowInteractor
from vtkmodules.vtkRenderingCore import vtkRenderer

__all__ = ["VtkView", "fast_renderer"]


def fast_renderer(background=(1.0, 1.0, 1.0)) -> vtkRenderer:
    """A renderer without order-independent translucency (VTK 9's default).

    OIT renders every frame with translucent props (all text actors are) through extra
    full-screen floating-point passes: ~9 ms of a ~17 ms frame in llvmpipe. Plain alpha
    blending is exact here: the 2D top view has no overlapping translucent surfaces.
    """
    ren = vtkRenderer()
    ren.SetUseOIT(False)
    ren.SetUseDepthPeeling(False)
    ren.SetBackground(*background)
    return ren


class VtkView(QVTKRenderWindowInteractor):
    """A ``QWidget`` with a native window VTK renders into (no multisampling)."""

    def __init__(self, parent=None):
        super().__init__(parent)
        self.ren_win = self.GetRenderWindow()
        self.ren_win.SetMultiSamples(0)
        self.ren_win.SetLineSmoothing(False)
        self.ren_win.SetPointSmoothing(False)
        self.ren_win.SetPolygonSmoothing(False)
        self.renderer = fast_renderer()
        self.ren_win.AddRenderer(self.renderer)
        self._Iren.SetInteractorStyle(None)
        self.frames = 0  # renders completed: the bench's "frame that reflects the event"
        self.before_render = None  # callable run before each render (pending updates)
        self.closed = False

    def set_background(self, color) -> None:
        self.renderer.SetBackground(*color)

    def draw(self) -> None:
        """Apply pending updates, then render synchronously (never after close)."""
        if self.closed:
            return
        if self.before_render is not None:
            self.before_render()
        self.ren_win.Render()
        self.frames += 1

    def paintEvent(self, ev) -> None:  # noqa: N802 (Qt name)
        if self.isVisible():
            self.draw()

    def close(self) -> bool:
        if not self.closed:
            self.closed = True
            self.Finalize()
        return super().close()
