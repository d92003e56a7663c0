"""The check of a value typed or dragged into a feature (planar disc or 3D ball).

One rule for both app models (:mod:`eyeviz.model.app_model`, :mod:`eyeviz.model.app_model3d`):
a coordinate or radius is a float, refused (never clamped) when not finite, and the radius
g when <= 0 (docs/architecture.md, Validation: one line naming the parameter).
"""

from __future__ import annotations

import math

__all__ = ["feature_value"]


def feature_value(key: str, value: object, radius: str = "feature radius") -> float:
    """``value`` as a float for the feature's ``key`` (x, y, z or g), or a ``ValueError``
    naming it: ``"x must be finite, got inf"``, ``"g (<radius>) must be > 0, got 0.0"``;
    ``radius`` says what g is in the message (a feature's or a ball's radius)."""
    v = float(value)  # type: ignore[arg-type]
    if not math.isfinite(v):
        raise ValueError(f"{key} must be finite, got {v!r}")
    if key == "g" and v <= 0:
        raise ValueError(f"g ({radius}) must be > 0, got {v!r}")
    return v
