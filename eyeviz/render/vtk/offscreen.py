"""An off-screen VTK render window for the 3D exports, in plain VTK (issue 32.14).

What :func:`eyeviz.render.vtk.scene3d.offscreen_view` needs of an off-screen
``pyvista.Plotter`` (a window of a given size, a main renderer lit by VTK's light kit, no
multisampling, the pixels back as an array) without importing ``pyvista.plotting``: that
package (and matplotlib.pyplot, which it imports) and the plotter's set-up took a quarter
of a second of every ``eyeviz snapshot`` of a spherical scene.
"""

from __future__ import annotations

import numpy as np
import vtkmodules.vtkRenderingFreeType  # noqa: F401  (text actors' fonts)
import vtkmodules.vtkRenderingOpenGL2  # noqa: F401  (the OpenGL window and renderers)
from vtkmodules.util.numpy_support import vtk_to_numpy
from vtkmodules.vtkRenderingCore import (
    vtkLightKit,
    vtkRenderer,
    vtkRenderWindow,
    vtkWindowToImageFilter,
)

__all__ = ["OffscreenWindow"]


class OffscreenWindow:
    """A ``width`` x ``height`` off-screen window with one renderer (``renderer``) lit as
    pyvista's ``lighting="light kit"`` lights it; :meth:`pixels` renders and reads it."""

    def __init__(self, width: int, height: int) -> None:
        self.ren_win = vtkRenderWindow()
        self.ren_win.SetOffScreenRendering(1)
        self.ren_win.SetMultiSamples(0)
        self.ren_win.SetAlphaBitPlanes(1)  # a transparent background reads back as alpha 0
        self.ren_win.SetSize(width, height)
        self.renderer = vtkRenderer()
        self.renderer.AutomaticLightCreationOff()
        vtkLightKit().AddLightsToRenderer(self.renderer)
        self.renderer.LightFollowCameraOn()
        self.ren_win.AddRenderer(self.renderer)

    def render(self) -> None:
        self.ren_win.Render()

    def pixels(self, transparent: bool) -> np.ndarray:
        """Render, then the window's pixels (height, width, 4 with ``transparent``, else
        3; uint8, the top row first)."""
        self.ren_win.Render()
        grab = vtkWindowToImageFilter()
        grab.SetInput(self.ren_win)
        grab.FixBoundaryOn()
        grab.ShouldRerenderOff()
        grab.ReadFrontBufferOff()
        if transparent:
            grab.SetInputBufferTypeToRGBA()
        else:
            grab.SetInputBufferTypeToRGB()
        grab.Update()
        img = grab.GetOutput()
        w, h, _ = img.GetDimensions()
        arr = vtk_to_numpy(img.GetPointData().GetScalars())
        return np.ascontiguousarray(arr.reshape(h, w, -1)[::-1])

    def close(self) -> None:
        self.ren_win.Finalize()
