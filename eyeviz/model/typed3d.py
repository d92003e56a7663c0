"""A ball's coordinate typed into the 3D readout (issue 32.6), as the planar feature table.

A ball is typed either in Cartesian coordinates (x, y, z, g) or as the readout shows it:
r (distance from the origin, midway between the eye centres), azimuth (degrees from +x
counter-clockwise seen from above; forward = 90) and elevation (degrees above the plane
z = 0), :mod:`eyeviz.model.state3d`'s definitions (docs/conventions.md). Changing one of
r, azimuth, elevation keeps the other two. Bad text is refused in one line (ValueError),
naming the coordinate.
"""

from __future__ import annotations

import math

from eyeviz.model.edits import feature_value
from eyeviz.model.scene import Feature

__all__ = ["KEYS", "typed_ball"]

#: the coordinates that can be typed, and what each is called in a message
KEYS = {
    "x": "x",
    "y": "y",
    "z": "z",
    "g": "g",
    "r": "r",
    "az": "azimuth",
    "el": "elevation",
}


def _number(key: str, text: str) -> float:
    try:
        v = float(str(text).strip().replace(",", ""))
    except ValueError:
        raise ValueError(f"{KEYS[key]} must be a number, got {str(text)[:40]!r}") from None
    if not math.isfinite(v):
        raise ValueError(f"{KEYS[key]} must be finite, got {str(text)[:40]!r}")
    return v


def typed_ball(f: Feature, key: str, text: str) -> tuple[float, float, float, float]:
    """Ball ``f``'s (x, y, z, g) with coordinate ``key`` (one of :data:`KEYS`) set to
    the number ``text``; ValueError (one line) for a bad key, text or value (g and r must
    be > 0, elevation within [-90, 90])."""
    if key not in KEYS:
        raise ValueError(f"cannot type {key!r}: one of {', '.join(KEYS)}")
    v = _number(key, text)
    x, y, z, g = f.x, f.y, f.z, f.g
    if key in ("x", "y", "z", "g"):
        out = {"x": x, "y": y, "z": z, "g": g}
        out[key] = feature_value(key, v, "ball radius")
        return out["x"], out["y"], out["z"], out["g"]
    horiz = math.hypot(x, y)
    r = math.hypot(horiz, z)
    az = math.atan2(y, x)
    el = math.atan2(z, horiz)
    if key == "r":
        if v <= 0:
            raise ValueError(f"r must be > 0, got {v:g}")
        r = v
    elif key == "az":
        az = math.radians(v)
    else:
        if not -90.0 <= v <= 90.0:
            raise ValueError(f"elevation must be within [-90, 90] degrees, got {v:g}")
        el = math.radians(v)
    if r == 0.0:
        raise ValueError(f"{KEYS[key]} has no meaning for a ball at the origin: type x, y, z")
    c = r * math.cos(el)
    return c * math.cos(az), c * math.sin(az), r * math.sin(el), g
