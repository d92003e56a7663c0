"""Qt side panels: bitmaps, readout, eye parameters, feature list, layer toggles.

Panels draw from the model's :class:`~eyeviz.model.state.SceneState` and send edits to the
:class:`~eyeviz.model.app_model.AppModel`; none keeps its own copy of the truth. One module
a panel (bitmaps, readout, eyes, features, layers); what they share is in common.py and the
estimator notes in notes.py. Every name is re-exported here, as when this was one module.
"""

from __future__ import annotations

from eyeviz.app.panels.bitmaps import INK, BitmapPanel
from eyeviz.app.panels.common import (
    ERROR_STYLE,
    _Unelide,
    set_message,
    unelide_tabs,
    user_message,
    wrap_label,
)
from eyeviz.app.panels.eyes import EYE_FIELDS, PENDING_STYLE, EyesPanel
from eyeviz.app.panels.features import FeaturePanel
from eyeviz.app.panels.layers import LayersPanel
from eyeviz.app.panels.notes import ANY_DESIGN, design_note, design_skips, range_note
from eyeviz.app.panels.readout import (
    BAD,
    GOOD,
    GREY,
    READOUT_MIN_WIDTH,
    ReadoutPanel,
    ValueText,
)

__all__ = [
    "ANY_DESIGN",
    "BAD",
    "BitmapPanel",
    "ERROR_STYLE",
    "EYE_FIELDS",
    "EyesPanel",
    "FeaturePanel",
    "GOOD",
    "GREY",
    "INK",
    "LayersPanel",
    "PENDING_STYLE",
    "READOUT_MIN_WIDTH",
    "ReadoutPanel",
    "ValueText",
    "_Unelide",
    "design_note",
    "design_skips",
    "range_note",
    "set_message",
    "unelide_tabs",
    "user_message",
    "wrap_label",
]
