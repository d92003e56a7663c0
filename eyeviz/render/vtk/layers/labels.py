"""``labels``: the eyes A, B and the origin O, each feature's name (at the Frame's
:class:`eyeviz.model.frame.LabelFrame` anchors) and the line "m, θ, ψ" of the BFV
(Eq. 15-16, from the Frame's ``bfv`` / ``pair``), in the inset or in the main view."""

from __future__ import annotations

import math

from vtkmodules.vtkRenderingCore import vtkBillboardTextActor3D, vtkTextActor

from eyeviz.model.frame import Frame
from eyeviz.render.vtk.primitives import Store, border_actor, screen_text, text3d
from eyeviz.render.vtk.style import BFV_LINE, INK, LABEL_ALL_MAX, Z_POINT, rgbf, style_text

__all__ = ["INSET_LINE_CHARS", "INSET_LINE_PX", "LabelsLayer", "bfv_line"]

INSET_LINE_PX = 14  # the inset's "m, θ, ψ" line
INSET_LINE_CHARS = 26  # characters of it that fit the smallest inset at INSET_LINE_PX
# a feature's name label's depth: over the centre dots, which are drawn as spheres whose
# fragments come up to their radius in world units (~60-80 at a 6,000-9,000 wide view)
# nearer the camera than Z_POINT, and so covered a label at Z_POINT (in a crowd of 10^4
# features, wholly); the camera is at z = 1,000 (eyeviz/app/canvas.py), clipped at 1
Z_NAME = 900.0


def bfv_line(frame: Frame) -> str:
    """'m = ...' and, with the bfv and labels layers, 'θ = ...°  ψ = ...°'."""
    text = f"m = {frame.pair.m}"
    if {"bfv", "labels"} <= frame.layers:
        deg = 180.0 / math.pi
        text += f"  θ = {frame.pair.theta * deg:.4g}°  ψ = {frame.pair.psi * deg:.4g}°"
    return text


class LabelsLayer:
    """Eye labels (inset, and main without the inset), feature names, the BFV line."""

    def __init__(self, main, inset):
        self.main, self.inset = main, inset
        self.eye_store = Store()
        self.feature_store = Store()
        self.inset_shown = True
        self.main_eye_labels_shown = False  # the eyes' A, O, B in the main view
        self.main_eye_labels: list[vtkBillboardTextActor3D] = []
        self.feature_labels: list[vtkBillboardTextActor3D] = []
        self.bfv_text = {
            "inset": screen_text(INSET_LINE_PX, BFV_LINE, (0.5, 0.03), center=True),
            "main": screen_text(20, BFV_LINE, (0.985, 0.02), right=True),
        }
        inset.AddViewProp(self.bfv_text["inset"])
        main.AddViewProp(self.bfv_text["main"])
        self.inset_label = vtkTextActor()
        style_text(self.inset_label.GetTextProperty(), 16, INK)
        self.inset_label.GetTextProperty().SetVerticalJustificationToTop()
        self.inset_label.GetPositionCoordinate().SetCoordinateSystemToNormalizedViewport()
        self.inset_label.SetPosition(0.03, 0.96)
        inset.AddViewProp(self.inset_label)
        self.inset_border = border_actor()
        inset.AddViewProp(self.inset_border)
        self._eyes_key: tuple | None = None
        self._feat_key: tuple | None = None

    def draw(self, frame: Frame, selected: int | None) -> None:
        """Eye labels and the BFV line when the eyes or the layers changed, feature labels
        when the features' names or colours did; then the labels' places. Runs whatever
        the layers (the BFV line "m = ..." is always shown; the names with ``labels``)."""
        layers = tuple(sorted(frame.layers))
        pair = frame.pair
        eyes_key = (pair.h, pair.l, pair.m, layers)
        feat_key = (tuple(frame.names), tuple(frame.colors), layers)
        if eyes_key != self._eyes_key:
            self.build_eyes(frame)
            self._eyes_key = eyes_key
        if feat_key != self._feat_key:
            self.build_features(frame)
            self._feat_key = feat_key
        self.update(frame, selected)

    def build_eyes(self, frame: Frame) -> None:
        """Eye and origin labels and the BFV line (the eyes or the layers changed)."""
        self.eye_store.clear()
        self.main_eye_labels = []
        for lab in frame.labels:
            if lab.kind != "eye":
                continue
            for ren in (self.inset, self.main):
                t = text3d(22, INK, center=True)
                t.SetInput(lab.text)
                t.SetPosition(lab.x, lab.y, Z_POINT)
                self.eye_store.add(ren, t)
                if ren is self.main:
                    t.SetVisibility(self.main_eye_labels_shown)
                    self.main_eye_labels.append(t)
        self.inset_label.SetInput("")
        text = bfv_line(frame)
        self.bfv_text["inset"].SetInput(text)
        # a long line (m = 100000) gets smaller text: it stays inside the inset
        size = INSET_LINE_PX * min(1.0, INSET_LINE_CHARS / max(len(text), 1))
        self.bfv_text["inset"].GetTextProperty().SetFontSize(max(9, int(size)))
        self.bfv_text["main"].SetInput(text if "θ" in text else "")
        self.place_bfv_text()

    def build_features(self, frame: Frame) -> None:
        """One name label per feature (the features' names or colours changed); beyond
        LABEL_ALL_MAX features only the selected one's is shown: ONE label, moved to it
        (issue 25: 10^4 hidden text actors cost seconds to build and walk)."""
        self.feature_store.clear()
        self.feature_labels = []
        if "features" not in frame.layers:
            return
        for lab in frame.labels:
            if lab.kind != "feature" or lab.feature is None:
                continue
            if self.feature_labels and frame.n > LABEL_ALL_MAX:
                break
            label = vtkBillboardTextActor3D()
            tp = label.GetTextProperty()
            style_text(tp, 22, rgbf(frame.colors[lab.feature]))
            tp.SetJustificationToLeft()
            tp.SetVerticalJustificationToBottom()
            self.feature_store.add(self.main, label)
            self.feature_labels.append(label)

    def update(self, frame: Frame, selected: int | None) -> None:
        """Feature names at the Frame's anchors (all for a few features, else the selected)."""
        few = frame.n <= LABEL_ALL_MAX
        feats = [lab for lab in frame.labels if lab.kind == "feature"]
        if not few:  # the one label: the selected feature's name, in its colour
            feats = [lab for lab in feats if lab.feature == selected][:1]
            for label in self.feature_labels[len(feats) :]:
                label.SetVisibility(False)
            if feats and self.feature_labels and selected is not None:
                tp = self.feature_labels[0].GetTextProperty()
                tp.SetColor(*rgbf(frame.colors[selected]))
        for label, lab in zip(self.feature_labels, feats, strict=False):
            shown = few or lab.feature == selected
            label.SetVisibility(shown)
            if shown:  # a hidden label is placed when it is shown
                label.SetInput(f" {lab.text}")  # no-op (no Modified) when unchanged
                label.SetPosition(lab.x, lab.y, Z_NAME)
        self.place_bfv_text()

    def set_inset_shown(self, shown: bool, main_eye_labels: bool | None = None) -> None:
        """The eye labels go to the inset when it is shown; the main view carries them
        where ``main_eye_labels`` (default: whenever the inset is hidden)."""
        self.inset_shown = bool(shown)
        self.main_eye_labels_shown = not shown if main_eye_labels is None else main_eye_labels
        for t in self.main_eye_labels:
            t.SetVisibility(self.main_eye_labels_shown)
        self.place_bfv_text()

    def place_bfv_text(self) -> None:
        has = bool(self.bfv_text["main"].GetInput())
        self.bfv_text["inset"].SetVisibility(has and self.inset_shown)
        main = has and not self.inset_shown
        # the main view's line steps aside for a feature's name (zoomed onto the eyes it
        # was drawn over one); the view's own theta and psi labels still say it
        self.bfv_text["main"].SetVisibility(main and self._footer_free())

    def _footer_free(self) -> bool:
        """Whether no shown feature name meets the main view's "m, θ, ψ" line (pixels)."""
        ren = self.main
        w, h = ren.GetSize()
        if w <= 0 or h <= 0:
            return True
        foot = self.bfv_text["main"]
        box = [0.0] * 4
        foot.GetBoundingBox(ren, box)  # about its anchor (right-justified)
        x, y = foot.GetPosition()
        fx1, fy0 = x * w, y * h
        fx0, fy1 = fx1 - (box[1] - box[0]), fy0 + (box[3] - box[2])
        for label in self.feature_labels:
            if not label.GetVisibility():
                continue
            ren.SetWorldPoint(*label.GetPosition(), 1.0)
            ren.WorldToDisplay()
            lx, ly, _ = ren.GetDisplayPoint()
            size = label.GetTextProperty().GetFontSize()
            lw = 0.65 * size * len(label.GetInput() or "")  # left-justified, bottom anchor
            if lx < fx1 and lx + lw > fx0 and ly < fy1 and ly + 1.3 * size > fy0:
                return False
        return True
