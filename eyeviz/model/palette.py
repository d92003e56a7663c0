"""Colours fixed by name: the features' Okabe-Ito palette and one colour per estimator.

An estimator keeps its colour whatever its position in a scene's list (compact is the
same in every scene, app, export and report), and no estimator colour is close to a
feature colour (Paul Tol's dark qualitative colours against Okabe & Ito 2008). A name
not listed gets a fixed colour from its CRC-32 (the same in every run), never a
feature's.
"""

from __future__ import annotations

import zlib

from eyeviz.model.scene import OKABE_ITO

__all__ = ["ESTIMATOR_COLORS", "FEATURE_COLORS", "estimator_color", "estimator_colors"]

FEATURE_COLORS: tuple[str, ...] = tuple(OKABE_ITO)
ESTIMATOR_COLORS: dict[str, str] = {
    "analytic": "#882255",  # wine
    "compact": "#332288",  # indigo
    "bayes": "#117733",  # dark green
    "paper": "#999933",  # olive
    "limit": "#6B3E00",  # dark brown
}
_EXTRA = ("#5A5A5A", "#1D4E5F", "#7A4F8C", "#3B5B12")


def estimator_color(name: str) -> str:
    """The colour of estimator ``name`` (fixed by name, never a feature colour)."""
    if name in ESTIMATOR_COLORS:
        return ESTIMATOR_COLORS[name]
    return _EXTRA[zlib.crc32(name.encode()) % len(_EXTRA)]


def estimator_colors(names) -> dict[str, str]:
    """name -> colour for several estimators (each by its name, not its position)."""
    return {n: estimator_color(n) for n in names}
