"""Add a layer to eyeviz: a frame builder, two painters and one entry of the layer table.

Run it: ``python examples/add_a_layer.py [-o OUT.svg]``. It registers ``distance``: a ring
through each feature's centre about the origin O, labelled with its distance r, drawn by the
exported figure (matplotlib) and by the app's view (VTK). The frame builder computes the
part once from the scene's state; the painters only draw it (docs/architecture.md, "The
layer table"). A scene shows the layer by naming it in ``[layers] show``; a scene that does
not name it builds nothing for it. The VTK part is drawn here on an off-screen plotter,
exactly as the app's view would draw it.
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

import numpy as np

from eyeviz.model.frame import build_frame
from eyeviz.model.layers import LayerSpec, register_layer, unregister_layer
from eyeviz.model.scene import Scene, loads

COLOR = "#7f3fbf"


def distance_part(frame, inputs) -> None:
    """The layer's part of the Frame: each feature's distance r from O (Eq. 22's r)."""
    st = inputs.state
    frame.parts["distance"] = np.hypot(st.x, st.y)


def paint_mpl(canvas) -> None:
    """Dashed arcs of radius r about O in the front half-plane, labelled with r."""
    t = np.linspace(0.0, np.pi, 400)
    for r in canvas.frame.parts["distance"]:
        canvas.ax.plot(r * np.cos(t), r * np.sin(t), "--", color=COLOR, lw=0.6, gid="distance")
        a = np.radians(165.0)  # on the left, clear of the BFV's angle labels
        canvas.ax.annotate(
            f"r = {r:.0f}", (r * np.cos(a), r * np.sin(a)), color=COLOR, fontsize=6, ha="right"
        )


class DistanceVtk:
    """The same arcs in the app's view: one polyline, updated in place."""

    def __init__(self, main, inset) -> None:
        import pyvista as pv

        from eyeviz.render.vtk.primitives import actor

        self.mesh = pv.PolyData()
        self.actor = actor(self.mesh, (0.5, 0.25, 0.75))
        main.AddActor(self.actor)

    def draw(self, frame, selected) -> None:
        radii = frame.parts.get("distance")
        shown = "distance" in frame.layers and radii is not None and len(radii) > 0
        self.actor.SetVisibility(shown)
        if shown:
            t = np.linspace(0.0, np.pi, 200)
            arcs = [np.column_stack([r * np.cos(t), r * np.sin(t), 0 * t]) for r in radii]
            k = t.size
            self.mesh.points = np.concatenate(arcs)
            self.mesh.lines = np.concatenate(
                [np.r_[k, np.arange(i * k, (i + 1) * k)] for i in range(len(arcs))]
            )


SPEC = LayerSpec(
    "distance",
    "a ring about O through each feature, labelled with its distance r",
    needs=frozenset({"readout"}),
    frame=distance_part,
    mpl=paint_mpl,
    vtk=DistanceVtk,
    mpl_order=15,
    vtk_order=15,
)

SCENE = """
[eyes]
h = 40.0
l = 20.0
m = 720
[[features]]
name = "near"
x = -400.0
y = 1500.0
g = 60.0
[[features]]
name = "far"
x = 700.0
y = 3200.0
g = 120.0
[layers]
show = ["eyes", "bfv", "features", "distance"]
[view]
center = [0.0, 2000.0]
width = 9000.0
"""


def main() -> None:
    from eyeviz.render.mpl.export import export
    from eyeviz.render.mpl.vector import figure

    register_layer(SPEC)
    try:
        scene = loads(SCENE)  # the scene file accepts the new name once it is registered
        frame = build_frame(scene)
        print("distance part:", np.round(frame.parts["distance"], 1))
        fig = figure(scene)
        arcs = [ln for ax in fig.axes for ln in ax.get_lines() if ln.get_gid() == "distance"]
        assert len(arcs) == 2, "the figure draws one arc per feature"
        out = Path(sys.argv[sys.argv.index("-o") + 1]) if "-o" in sys.argv else None
        out = export(scene, out or Path(tempfile.mkdtemp()) / "distance.svg")
        print(f"figure with the new layer: {out} ({out.stat().st_size} bytes)")
        plain = Scene(scene.eyes, scene.features, ["eyes", "features"])
        assert "distance" not in build_frame(plain).parts, "nothing built when not shown"
        draw_offscreen(scene)
    finally:
        unregister_layer("distance")


def draw_offscreen(scene: Scene) -> None:
    """The VTK painter on an off-screen plotter, as the app's view calls it."""
    import pyvista as pv

    from eyeviz.model.state import compute_state
    from eyeviz.render.vtk.actors import SceneActors

    pl = pv.Plotter(off_screen=True, window_size=(300, 200))
    try:
        inset = pv.Renderer(pl)
        pl.ren_win.AddRenderer(inset)
        actors = SceneActors(pl.renderer, inset)
        actors.update(scene, compute_state(scene), 0)
        painter = actors.layer("distance")
        assert painter.actor.GetVisibility() and painter.mesh.n_points == 400
        print(f"VTK view: {painter.mesh.n_points} points in the distance layer's polyline")
    finally:
        pl.close()


if __name__ == "__main__":
    main()
