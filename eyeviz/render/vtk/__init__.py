"""VTK painters: the app's actors, updated in place from the scene model.

With no display (no $DISPLAY, no $WAYLAND_DISPLAY) off-screen renders (``eyeviz snapshot``
of a spherical scene) use VTK's EGL window directly: VTK's default X window would first
print "bad X server connection" and then fall back to EGL, with the same pixels.
"""

import os

if not os.environ.get("DISPLAY") and not os.environ.get("WAYLAND_DISPLAY"):
    os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")
