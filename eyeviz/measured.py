"""Measured compound eyes (docs/measured.md): stable public path ``eyeviz.measured``.

>>> from eyeviz.measured import load_eyes, shipped_eye
>>> pair = load_eyes(shipped_eye("AM_60185-real.eye"))
>>> pair.facet_counts
(3187, 3187)
"""

from __future__ import annotations

from eyeviz.core.measured import MeasuredEye, MeasuredEyePair
from eyeviz.core.measured_from import as_measured
from eyeviz.files.eye_io import EyeSizeWarning, load_eyes, save_eyes, shipped_eye

__all__ = [
    "EyeSizeWarning",
    "MeasuredEye",
    "MeasuredEyePair",
    "as_measured",
    "load_eyes",
    "save_eyes",
    "shipped_eye",
]
