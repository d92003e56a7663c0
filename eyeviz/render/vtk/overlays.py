"""The "overlay"-stage layers of the layer table in the app's main view (prediction
ghosts, the ambiguity region, the trajectory path, and any such layer registered).

:class:`OverlayActors` builds one :class:`eyeviz.model.frame.Frame` of these layers from
what the app model already holds (predictions, the selected feature's ambiguity region,
the trajectory path) and hands it to each layer's VTK painter
(:mod:`eyeviz.render.vtk.layers`), which draws only the Frame. Nothing is drawn for a
layer the scene does not show.
"""

from __future__ import annotations

import dataclasses
from typing import cast

import numpy as np
from vtkmodules.vtkRenderingCore import vtkRenderer

from eyeviz.model.frame import Frame, TrajectoryPath, build_frame
from eyeviz.model.layers import ordered
from eyeviz.model.scene import Scene
from eyeviz.model.state import SceneState
from eyeviz.render.vtk.layers import Painter, painters
from eyeviz.render.vtk.layers.ambiguity import AmbiguityLayer
from eyeviz.render.vtk.layers.predictions import GHOST_N, PredictionsLayer
from eyeviz.render.vtk.layers.trajectory import TrajectoryLayer
from eyeviz.render.vtk.style import Z_AMBIGUITY

__all__ = ["OverlayActors", "Z_AMBIGUITY", "GHOST_N", "overlay_frame"]


def _overlay_layers() -> set[str]:
    return {s.name for s in ordered("vtk") if s.vtk_stage == "overlay"}


def overlay_frame(
    scene: Scene,
    state: SceneState,
    selected: int | None,
    predictions: dict,
    ambiguity: dict | None,
    path: TrajectoryPath | None,
) -> Frame:
    """The Frame of the overlay layers, with the app model's cached parts taken as given."""
    overlay = _overlay_layers()
    light = dataclasses.replace(
        scene, layers=[n for n in scene.layers if n in overlay], trajectory=None
    )
    return build_frame(
        light,
        state,
        rect=(0.0, 1.0, 0.0, 1.0),  # no wedge here: the rect only bounds computed regions
        predictions=predictions,
        ambiguity={} if selected is None else {selected: ambiguity},
        trajectory=path,
    )


class OverlayActors:
    """Prediction ghosts (rings at (r_hat, phi_hat) joined to the truth), the selected
    feature's ambiguity polygon and the trajectory path, in the main renderer."""

    def __init__(self, main: vtkRenderer, inset: vtkRenderer | None = None):
        self.main = main
        self.painters: dict[str, Painter] = painters("overlay", main, inset)
        self._names = set(self.painters)
        self.frame: Frame | None = None  # the Frame drawn last
        self._inputs: tuple | None = None  # what update() built it from
        self._hidden = False  # every painter drew a Frame without layers since

    def update(
        self,
        scene: Scene,
        state: SceneState,
        selected: int | None,
        predictions: dict,
        ambiguity: dict | None,
        path: TrajectoryPath | None,
        skip=frozenset(),
    ) -> Frame | None:
        """Build the overlay Frame and draw it; returns the Frame (None, and everything
        hidden, when the scene shows none of these layers: a drag builds nothing then)."""
        if not self._names & set(scene.layers):
            # none of these layers: each painter hides, drawing a Frame without layers
            # (once: a drag then builds nothing here)
            if not self._hidden:
                none = build_frame(dataclasses.replace(scene, layers=[], trajectory=None), state)
                for p in self.painters.values():
                    p.draw(none, selected)
                self._hidden = True
            self._inputs = None
            return None
        self._hidden = False
        # the same inputs (a refresh that changed nothing here: a selection, a panel, the
        # second call of a refresh): the Frame drawn last is still what is shown
        inputs = (state, predictions, ambiguity, path)
        plain = (
            selected,
            tuple(scene.layers),
            tuple(scene.estimators),
            tuple(f.color for f in scene.features),
            frozenset(skip),
        )
        last = self._inputs
        if (
            last is not None
            and self.frame is not None
            and all(a is b for a, b in zip(inputs, last[0], strict=True))
            and plain == last[1]
        ):
            return self.frame
        frame = overlay_frame(scene, state, selected, predictions, ambiguity, path)
        self._draw(frame, selected, skip)
        self._inputs = (inputs, plain)
        return frame

    def draw(self, frame: Frame, selected: int | None, skip=frozenset()) -> None:
        """Draw ``frame`` (estimators in ``skip``, made for other eyes, draw no ring)."""
        self._inputs = None  # a Frame from elsewhere: the next update draws its own
        self._draw(frame, selected, skip)

    def _draw(self, frame: Frame, selected: int | None, skip) -> None:
        self.frame = frame
        self._hidden = False
        self.predictions.skip = frozenset(skip)
        for p in self.painters.values():
            p.draw(frame, selected)

    @property
    def predictions(self) -> PredictionsLayer:
        return cast(PredictionsLayer, self.painters["predictions"])

    @property
    def ambiguity(self) -> AmbiguityLayer:
        return cast(AmbiguityLayer, self.painters["ambiguity"])

    @property
    def trajectory(self) -> TrajectoryLayer:
        return cast(TrajectoryLayer, self.painters["trajectory"])

    # --- what the tests and the window read -------------------------------------------
    @property
    def ghosts(self) -> dict[str, np.ndarray]:
        return self.predictions.ghosts

    @property
    def ghost_actor(self):
        return self.predictions.ghost_actor

    @property
    def ghost_points(self):
        return self.predictions.ghost_points

    @property
    def amb_fill(self):
        return self.ambiguity.amb_fill

    @property
    def amb_polygon(self) -> np.ndarray | None:
        return self.ambiguity.polygon
