"""A backdrop: opaque props drawn before a renderer's own and kept while they are unchanged.

Issue 25: at 10^4 features, filling the merged discs (~16 M fragments in software GL) was
nearly the whole of a drag frame, though a drag moves only the selected feature and never
the camera. A :class:`Backdrop` holds such props (the features layer gives it its merged
discs, :mod:`eyeviz.render.vtk.layers.features`) in a renderer of its own that follows the
main renderer's camera, viewport and background. Before the main renderer draws (its
``StartEvent``), the backdrop either

- draws its props into the window's render framebuffer and copies the colour AND depth
  buffers into a framebuffer object of its own (a *capture*: the props, the camera, the
  background or the window's size changed since the last one), or
- copies the kept colour and depth back (a *hit*: one framebuffer blit, ~1-2 ms for a
  1280 x 800 window in llvmpipe, instead of the props' whole fill).

The main renderer keeps the buffers (``PreserveColorBuffer``, ``PreserveDepthBuffer``)
and draws its own props over them with the depth test: what is drawn over or under a
backdrop disc is resolved per pixel as if the disc were the main renderer's, so a hit's
pixels equal those of drawing everything in one renderer (tests/app/test_backdrop.py and
tests/render/test_backdrop_unit.py compare them). This holds for opaque props, which is
all a backdrop may hold, and a main renderer without passes of its own (a backdrop hands
its props to one with order-independent translucency or depth peeling instead; the app's
is plain, eyeviz.app.view.fast_renderer). The one difference is a tie, a main-renderer
prop at exactly a backdrop prop's depth, which the main renderer's prop now wins (it is
drawn later). A window without a render framebuffer, or with multisampling, leaves the
backdrop drawing its props at every frame: the same pixels, no saving.
"""

from __future__ import annotations

from vtkmodules.vtkCommonCore import VTK_UNSIGNED_CHAR, vtkCommand
from vtkmodules.vtkRenderingCore import vtkProp, vtkRenderer
from vtkmodules.vtkRenderingOpenGL2 import vtkOpenGLFramebufferObject

__all__ = ["Backdrop"]

_GL_READ_FRAMEBUFFER = 0x8CA8
_GL_DRAW_FRAMEBUFFER = 0x8CA9
_GL_COLOR_AND_DEPTH = 0x4000 | 0x0100  # GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT
_GL_NEAREST = 0x2600
_GL_SCISSOR_TEST = 0x0C11


class Backdrop:
    """Opaque props drawn under ``main``'s own, kept between frames (see the module).

    It has ``AddActor`` and ``RemoveActor`` as a renderer has, so a layer's
    :class:`eyeviz.render.vtk.primitives.Store` can hold props in it. ``captures`` and
    ``hits`` count the frames of each kind (read by tests and the bench)."""

    def __init__(self, main: vtkRenderer):
        self.main = main
        self.ren = vtkRenderer()  # in the window, never drawn by it: only by this class
        self.ren.SetUseOIT(False)
        self.ren.SetUseDepthPeeling(False)
        self.ren.InteractiveOff()
        self.props: list[vtkProp] = []
        self.passed: list[vtkProp] = []  # props handed to a main renderer with passes
        self.keep = True  # False: draw the props every frame, keep nothing (tests compare)
        self.captures = 0
        self.hits = 0
        self._observer: int | None = None
        self._attach_later: int | None = None  # the window's EndEvent observer, if any
        self._fbo: vtkOpenGLFramebufferObject | None = None
        self._fbo_size: tuple[int, int] = (0, 0)
        self._key: tuple | None = None  # what the kept buffers show
        self._preserve = (main.GetPreserveColorBuffer(), main.GetPreserveDepthBuffer())

    # --- a renderer's interface for a Store ----------------------------------------------
    def AddActor(self, prop: vtkProp) -> None:  # noqa: N802 (vtkRenderer's name)
        m = self.main
        if m.GetUseOIT() or m.GetUseDepthPeeling() or m.GetPass() is not None:
            # a main renderer with passes of its own does not draw over kept buffers: the
            # prop is simply its (the app's is plain: eyeviz.app.view.fast_renderer)
            m.AddActor(prop)
            self.passed.append(prop)
            return
        self.ren.AddActor(prop)
        self.props.append(prop)
        self._key = None
        if self._observer is None:
            self._preserve = (
                self.main.GetPreserveColorBuffer(),
                self.main.GetPreserveDepthBuffer(),
            )
            self.main.PreserveColorBufferOn()
            self.main.PreserveDepthBufferOn()
            self._observer = self.main.AddObserver(vtkCommand.StartEvent, self._before_main)
        self._attach(self.main.GetRenderWindow())

    def _attach(self, rw) -> None:
        """Put the renderer in the window, which then holds it (and lets go of it when it
        goes: a renderer keeps a plain pointer to its window) but never draws it."""
        if rw is not None and self.ren.GetRenderWindow() is not rw:
            self.ren.SetDraw(False)
            rw.AddRenderer(self.ren)

    def _attach_now(self, rw, _event=None) -> None:
        if self._attach_later is not None:
            rw.RemoveObserver(self._attach_later)
            self._attach_later = None
        if self.props:
            self._attach(rw)

    def RemoveActor(self, prop: vtkProp) -> None:  # noqa: N802 (vtkRenderer's name)
        if any(p is prop for p in self.passed):
            self.main.RemoveActor(prop)
            self.passed = [p for p in self.passed if p is not prop]
            return
        self.ren.RemoveActor(prop)
        self.props = [p for p in self.props if p is not prop]
        self._key = None
        if not self.props and self._observer is not None:
            self.main.RemoveObserver(self._observer)
            self._observer = None
            rw = self.ren.GetRenderWindow()
            if rw is not None:
                rw.RemoveRenderer(self.ren)
            self.main.SetPreserveColorBuffer(self._preserve[0])
            self.main.SetPreserveDepthBuffer(self._preserve[1])

    @property
    def active(self) -> bool:
        """Props are held: they are drawn before the main renderer's at every frame."""
        return self._observer is not None

    def invalidate(self) -> None:
        """Capture again at the next frame."""
        self._key = None

    # --- the frame -------------------------------------------------------------------------
    def _signature(self, rw) -> tuple:
        """Everything the kept buffers depend on: the window's and framebuffer's size, the
        main renderer's viewport, background and camera, and each prop's modification
        times (the prop and its property, its mapper, the mapper's input data)."""
        cam = self.main.GetActiveCamera()
        key: list = [
            tuple(rw.GetSize()),
            tuple(rw.GetTileViewport()),
            tuple(rw.GetTileScale()),
            tuple(self.main.GetViewport()),
            tuple(self.main.GetBackground()),
            tuple(self.main.GetBackground2()),
            self.main.GetGradientBackground(),
            self.main.GetBackgroundAlpha(),
            cam.GetAddressAsString("vtkObject"),  # the camera itself (wrappers come and go)
            cam.GetParallelProjection(),
            cam.GetParallelScale(),
            cam.GetViewAngle(),
            tuple(cam.GetPosition()),
            tuple(cam.GetFocalPoint()),
            tuple(cam.GetViewUp()),
            tuple(cam.GetClippingRange()),
            cam.GetMTime(),
        ]
        for p in self.props:
            mapper = p.GetMapper() if hasattr(p, "GetMapper") else None
            data = mapper.GetInputDataObject(0, 0) if mapper is not None else None
            key.append(
                (
                    id(p),
                    p.GetMTime(),
                    mapper.GetMTime() if mapper is not None else 0,
                    data.GetMTime() if data is not None else 0,
                )
            )
        return tuple(key)

    def _draw_props(self, rw) -> None:
        """Clear the main viewport to the main background and draw the props into it."""
        ren, main = self.ren, self.main
        # not in the window yet (its main renderer had none when the props came): the
        # window is mid-render and its renderer list must not change now, so for this
        # frame only
        borrowed = ren.GetRenderWindow() is not rw
        if borrowed:
            ren.SetRenderWindow(rw)
            if self._attach_later is None:  # once this render is over
                self._attach_later = rw.AddObserver(vtkCommand.EndEvent, self._attach_now)
        # a copy of the main camera, not the camera itself: vtkWindowToImageFilter (every
        # screenshot) gives each renderer a camera of its own for its render and Delete()s
        # whatever camera each has afterwards, so a renderer that took the main renderer's
        # camera then freed it twice (a segmentation fault from 150 features on)
        ren.GetActiveCamera().DeepCopy(main.GetActiveCamera())
        ren.SetViewport(*main.GetViewport())
        ren.SetBackground(*main.GetBackground())
        ren.SetBackground2(*main.GetBackground2())
        ren.SetGradientBackground(main.GetGradientBackground())
        ren.SetBackgroundAlpha(main.GetBackgroundAlpha())
        ren.SetDraw(True)
        try:
            ren.Render()
        finally:
            ren.SetDraw(False)  # the window's own pass, after the main renderer, skips it
            if borrowed:
                ren.SetRenderWindow(None)  # type: ignore[arg-type]  # (VTK accepts nullptr)

    def _framebuffer(self, rw, size: tuple[int, int]) -> vtkOpenGLFramebufferObject | None:
        """The backdrop's own framebuffer, with the render framebuffer's size and formats."""
        if self._fbo is not None and self._fbo_size == size:
            return self._fbo
        if self._fbo is not None:
            self._fbo.ReleaseGraphicsResources(rw)
        fbo = vtkOpenGLFramebufferObject()
        fbo.SetContext(rw)
        depth = rw.GetRenderBufferTargetDepthSize()
        st = rw.GetState()
        st.PushFramebufferBindings()  # making it binds it: the main renderer's must stay
        try:
            made = fbo.PopulateFramebuffer(
                size[0], size[1], True, 1, VTK_UNSIGNED_CHAR, True, depth, 0, False
            )
        finally:
            st.PopFramebufferBindings()
        if not made:
            self._fbo = None
            self._fbo_size = (0, 0)
            return None
        self._fbo, self._fbo_size = fbo, size
        return fbo

    @staticmethod
    def _blit(rw, src: vtkOpenGLFramebufferObject, dst: vtkOpenGLFramebufferObject, size) -> None:
        """Colour and depth of ``src`` -> ``dst`` (whole framebuffers, no scissor)."""
        st = rw.GetState()
        scissor = st.GetEnumState(_GL_SCISSOR_TEST)
        st.PushFramebufferBindings()
        src.Bind(_GL_READ_FRAMEBUFFER)
        src.ActivateReadBuffer(0)
        dst.Bind(_GL_DRAW_FRAMEBUFFER)
        dst.ActivateDrawBuffer(0)
        st.vtkglDisable(_GL_SCISSOR_TEST)
        w, h = size
        st.vtkglBlitFramebuffer(0, 0, w, h, 0, 0, w, h, _GL_COLOR_AND_DEPTH, _GL_NEAREST)
        st.PopFramebufferBindings()
        if scissor:
            st.vtkglEnable(_GL_SCISSOR_TEST)

    def _before_main(self, _obj=None, _event=None) -> None:
        """The main renderer's StartEvent: a hit, or the props drawn (and kept)."""
        rw = self.main.GetRenderWindow()
        if rw is None:
            return
        rfb = rw.GetRenderFramebuffer() if hasattr(rw, "GetRenderFramebuffer") else None
        if not self.keep or rfb is None or rw.GetMultiSamples():  # draw them, keep nothing
            self._draw_props(rw)
            self._key = None
            return
        wh = [0, 0]
        rfb.GetLastSize(wh)
        size = (int(wh[0]), int(wh[1]))
        key = (*self._signature(rw), size)
        if key == self._key and self._fbo is not None:
            self._blit(rw, self._fbo, rfb, size)
            self.hits += 1
            return
        self._draw_props(rw)
        self._key = None
        fbo = self._framebuffer(rw, size) if min(size) > 0 else None
        if fbo is None:
            return
        self._blit(rw, rfb, fbo, size)
        self._key = key
        self.captures += 1
