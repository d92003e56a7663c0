"""What File > Export writes of the 3D view (:class:`eyeviz.app.view3d.Scene3DHost`): the
vector figure, run on a worker thread, or the PNG (VTK off-screen), run on the GUI thread.
The window's one ``export_to`` (:class:`eyeviz.app.window.MainWindow`) runs it, as it
runs the planar page's figure."""

from __future__ import annotations

import os
from collections.abc import Callable
from pathlib import Path
from typing import Any

__all__ = ["export_work3d"]


def export_work3d(
    host: Any,  # the 3D page (eyeviz.app.view3d.Scene3DHost: no import cycle)
    path: str | os.PathLike,
    scale: float = 1.0,
    transparent: bool = False,
    *,
    width: float | str = "single",
    title: bool = True,
    table: bool = True,
    bitmaps: bool = True,
) -> tuple[Callable[[], Any], bool]:
    """(work, on the GUI thread) of File > Export of a spherical scene: the figure (the 3D
    view through the view's camera, framed as on screen: its height / width, within
    [0.3, 1.6]; the maps; the readout). SVG/PDF the vector figure
    (:func:`eyeviz.render.mpl.figure3d.export3d`) on a worker thread; PNG the same figure
    with the view rendered off-screen by VTK (:func:`eyeviz.render.vtk.png3d.export_png3d`),
    on the GUI thread (VTK's OpenGL context is per thread)."""
    from eyeviz.render.mpl.figure3d import export3d
    from eyeviz.render.mpl.vector import resolve_width

    assert host.model is not None and host.view is not None
    scene = host.model.scene.copy()
    cam = host.camera()
    fmt = Path(path).suffix.lower()
    vw, vh = max(host.view.width(), 1), max(host.view.height(), 1)
    aspect = min(max(vh / vw, 0.3), 1.6)  # the view's height / width, as on screen
    opts = dict(
        width=resolve_width(width), title=title, table=table, bitmaps=bitmaps,
        aspect=aspect, camera=cam,
    )  # fmt: skip
    # the predictions layer: the selected ball's, as shown (computed by the export,
    # the limit included, while the view still waits for the limit)
    ball = host.model.selected if host.model.selected is not None else 0
    preds = host.preds
    if preds is not None and any(a in ("computing…", "after the drag")
                                 for a in preds.answers.values()):  # fmt: skip
        preds = None
    if fmt == ".png":
        from eyeviz.render.vtk.png3d import export_png3d

        def work():
            return export_png3d(
                scene, path, scale, transparent, ball=ball, predictions=preds, **opts
            )

    else:

        def work():
            return export3d(scene, path, scale, transparent, predictions=preds, ball=ball, **opts)

    return work, fmt == ".png"
