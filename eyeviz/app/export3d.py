"""File > Export of the 3D view (:class:`eyeviz.app.view3d.Scene3DHost`): the vector
figure on a worker thread, the PNG (VTK off-screen) on the GUI thread."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

__all__ = ["export_view3d"]


def export_view3d(
    host: Any,  # the 3D page (eyeviz.app.view3d.Scene3DHost: no import cycle)
    path: str | os.PathLike,
    scale: float = 1.0,
    transparent: bool = False,
    wait: bool = True,
    *,
    width: float | str = "single",
    title: bool = True,
    table: bool = True,
    bitmaps: bool = True,
):
    """File > Export of a spherical scene: the figure (the 3D view through the view's
    camera, framed as on screen: its height / width, within [0.3, 1.6]; the maps; the
    readout). SVG/PDF the vector figure (:func:`eyeviz.render.mpl.figure3d.export3d`)
    on a worker thread; PNG the same figure with the view rendered off-screen by VTK
    (:func:`eyeviz.render.vtk.png3d.export_png3d`), on this thread."""
    from eyeviz import EyevizError
    from eyeviz.app.panels import user_message
    from eyeviz.render.mpl.figure3d import export3d
    from eyeviz.render.mpl.vector import resolve_width

    assert host.model is not None and host.view is not None
    scene = host.model.scene.copy()
    cam = host.camera()
    win = host.win
    fmt = Path(path).suffix.lower()
    result: list = []
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

    def done(out) -> None:
        result.append(Path(out))
        win.statusBar().showMessage(f"exported {out}", 8000)

    def failed(exc) -> None:
        if isinstance(exc, (EyevizError, OSError, ValueError)):
            win.show_error("Cannot export", user_message(str(exc), 300))
        else:
            win.show_error("Cannot export", f"unexpected error: {user_message(str(exc))}")

    if fmt == ".png":  # VTK renders on this thread (its OpenGL context is per thread)
        try:
            done(work())
        except Exception as exc:  # noqa: BLE001 (shown in a dialog, as the job's)
            failed(exc)
        return result[0] if result else None
    job = win.jobs.start(work, f"exporting {Path(path).name}…", done, failed)
    if not wait:
        return job
    win.jobs.wait()
    return result[0] if result else None
