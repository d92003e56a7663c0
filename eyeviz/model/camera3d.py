"""The 3D view's camera as plain maths: presets and VTK's perspective projection (no VTK).

A :class:`Camera3D` holds what a VTK camera is made of (position, focal point, view-up,
vertical view angle in degrees). :func:`project` maps model points to normalised device
coordinates exactly as VTK's perspective camera does (window centre at the origin, no
shear, the vertical view angle), so a vector figure drawn from the model through the
same camera lines up with the PNG that VTK renders (``tests/model/test_camera3d.py``
checks a point against a real off-screen render). Coordinates are the model's
(``docs/spherical.md``): x right, y forward, z up; eye A at (-h, 0, 0), eye B at (h, 0, 0).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from eyeviz import EyevizError
from eyeviz.core.validation import check_choice, check_real

__all__ = [
    "PRESETS",
    "Camera3D",
    "basis",
    "eyes_camera",
    "preset",
    "project",
    "to_pixels",
    "dolly",
    "view_side",
]

Vec3 = tuple[float, float, float]

# Preset name -> (unit direction from the focal point to the camera, view-up).
_FRONT = ((0.0, 1.0, 0.0), (0.0, 0.0, 1.0))
_DIRS: dict[str, tuple[Vec3, Vec3]] = {
    "default": ((0.55, 0.70, 0.45), (0.0, 0.0, 1.0)),
    "front": _FRONT,
    "top": ((0.0, 0.0, 1.0), (0.0, 1.0, 0.0)),
    "side": ((1.0, 0.0, 0.0), (0.0, 0.0, 1.0)),
    "eye_a": _FRONT,
    "eye_b": _FRONT,
}
PRESETS: tuple[str, ...] = tuple(_DIRS)


@dataclass(frozen=True)
class Camera3D:
    """A perspective camera as VTK defines it (``vtkCamera``).

    ``view_angle`` is VTK's: the full vertical angle of the view, in degrees.
    """

    position: Vec3
    focal_point: Vec3
    view_up: Vec3
    view_angle: float = 30.0  # degrees, vertical, as VTK


def _unit(v) -> np.ndarray:
    a = np.asarray(v, dtype=float)
    n = float(np.linalg.norm(a))
    return a / n


def _look(
    focal: np.ndarray, direction: np.ndarray | Vec3, up: Vec3, dist: float, angle: float
) -> Camera3D:
    pos = focal + _unit(direction) * dist
    return Camera3D(
        tuple(float(c) for c in pos),  # type: ignore[arg-type]
        tuple(float(c) for c in focal),  # type: ignore[arg-type]
        tuple(float(c) for c in _unit(up)),  # type: ignore[arg-type]
        float(angle),
    )


def preset(
    name: str,
    h: float,
    l: float,
    extent: float,
    aspect: float = 1.0,
    *,
    centre: Vec3 | None = None,
    radius: float | None = None,
) -> Camera3D:
    """A named view of a scene with eyes ``h``, ``l`` whose features reach ``extent``.

    ``extent`` is the size of the region to show ahead of the eyes: the whole-scene
    presets frame a ball of radius ``0.6 extent`` (at least ``h + l``) about
    (0, extent / 2, 0). Names:

    - ``"default"``: a 3/4 view from front-right and above;
    - ``"front"``: from ahead of the eyes (+y) looking back at them, z up (eye A on the
      right, as one looks at a face);
    - ``"top"``: from above, x right and y up (the planar model's view);
    - ``"side"``: from +x, y (forward) to the right, z up;
    - ``"eye_a"``, ``"eye_b"``: along the eye's forward axis (the line through its
      centre parallel to y), looking back at that eye from ahead.

    ``aspect`` (the viewport's width / height) narrows the fit for a tall viewport;
    ``centre`` and ``radius`` (a ball the scene lies in) replace the ball ``extent`` gives.
    """
    name = check_choice("view", name, PRESETS)
    h = check_real("h", h, gt=0.0)
    l = check_real("l", l, gt=0.0)
    extent = check_real("extent", extent, gt=0.0)
    aspect = check_real("aspect", aspect, gt=0.0)
    direction, up = _DIRS[name]
    if radius is None:
        radius = max(0.6 * extent, h + l)
    radius = check_real("radius", radius, gt=0.0)
    half = math.radians(30.0) / 2.0
    half = min(half, math.atan(math.tan(half) * aspect))
    dist = radius / math.sin(half)
    if name in ("eye_a", "eye_b"):
        focal = np.array([-h if name == "eye_a" else h, 0.0, 0.0])
        dist += extent / 2.0
    else:
        focal = np.array([0.0, extent / 2.0, 0.0] if centre is None else centre, dtype=float)
    return _look(focal, direction, up, dist, 30.0)


def eyes_camera(cam: Camera3D, h: float, l: float, aspect: float = 1.0) -> Camera3D:
    """The close-up of the eyes seen from ``cam``'s direction (the 3D view's inset).

    The eyes are small beside the features they look at (l = 20 against r = 1000 in the
    paper), so the view shows them again at a scale where the facets are seen: same
    direction and view-up as ``cam``, framing both eyes, or one eye when ``cam`` looks at
    that eye's centre (the ``eye_a`` / ``eye_b`` presets), in a viewport ``aspect``
    (width / height) wide.
    """
    pos = np.asarray(cam.position, dtype=float)
    foc = np.asarray(cam.focal_point, dtype=float)
    direction = pos - foc
    if not np.any(direction):
        raise EyevizError("camera position must differ from its focal point")
    fx = float(foc[0])
    on_eye = abs(abs(fx) - h) <= 1e-9 * max(h, 1.0) and abs(foc[1]) <= 1e-9 and abs(foc[2]) <= 1e-9
    if on_eye:
        focal = np.array([fx, 0.0, 0.0])
        radius = 1.25 * l
    else:
        focal = np.zeros(3)
        radius = 1.1 * (h + l)
    half = math.radians(cam.view_angle) / 2.0
    half = min(half, math.atan(math.tan(half) * check_real("aspect", aspect, gt=0.0)))
    dist = radius / math.sin(half)
    return _look(focal, direction, cam.view_up, dist, cam.view_angle)


def basis(cam: Camera3D) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The camera's orthonormal (right, up, backward) axes, as VTK's view transform.

    VTK (``vtkPerspectiveTransform::SetupCamera``) orthogonalises view-up against the
    direction of projection; ``backward`` points from the focal point to the camera.
    """
    pos = np.asarray(cam.position, dtype=float)
    foc = np.asarray(cam.focal_point, dtype=float)
    back = pos - foc
    nb = float(np.linalg.norm(back))
    if nb == 0.0:
        raise EyevizError("camera position must differ from its focal point")
    back = back / nb
    right = np.cross(np.asarray(cam.view_up, dtype=float), back)
    nr = float(np.linalg.norm(right))
    if nr == 0.0:
        raise EyevizError("camera view_up must not be parallel to the direction of view")
    right = right / nr
    up = np.cross(back, right)
    return right, up, back


def project(cam: Camera3D, points, aspect: float) -> tuple[np.ndarray, np.ndarray]:
    """Model points (..., 3) -> (normalised device xy (..., 2), depth (...)), as VTK.

    ``aspect`` is the viewport's width / height. x_ndc and y_ndc are in [-1, 1] across
    the viewport (y up); ``depth`` is the distance in front of the camera along its
    direction of view (positive for visible points; sort by it, farthest first, to paint
    back to front). VTK's frustum with a vertical view angle a gives
    x_ndc = x_v / (d tan(a/2) aspect), y_ndc = y_v / (d tan(a/2)), d = -z_v.
    """
    aspect = check_real("aspect", aspect, gt=0.0)
    p = np.asarray(points, dtype=float)
    if p.shape[-1:] != (3,):
        raise EyevizError(f"points must have shape (..., 3), got {p.shape}")
    right, up, back = basis(cam)
    rel = p - np.asarray(cam.position, dtype=float)
    xv = rel @ right
    yv = rel @ up
    depth = -(rel @ back)
    t = math.tan(math.radians(cam.view_angle) / 2.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        x = xv / (depth * t * aspect)
        y = yv / (depth * t)
    return np.stack([x, y], axis=-1), depth


def to_pixels(xy_ndc: np.ndarray, width: int, height: int) -> np.ndarray:
    """Normalised device xy -> image pixels (column, row), row 0 at the top (a PNG's)."""
    xy = np.asarray(xy_ndc, dtype=float)
    col = (xy[..., 0] + 1.0) * width / 2.0
    row = height - (xy[..., 1] + 1.0) * height / 2.0
    return np.stack([col, row], axis=-1)


def view_side(cam: Camera3D) -> str:
    """Where ``cam`` looks from, in words (the model's axes), and which way round it
    draws the eyes, on two lines: "seen from front, right, above" / "eye A on the right".
    The facet maps
    show each eye from inside (eye A's left on the left), so a view from ahead is their
    mirror image; the 3D view and its figure say so in a corner (issue 32)."""
    d = np.asarray(cam.position, np.float64) - np.asarray(cam.focal_point, np.float64)
    d /= np.linalg.norm(d)
    words = []
    for v, pos, neg in (
        (d[1], "front", "behind"),
        (d[0], "right", "left"),
        (d[2], "above", "below"),
    ):
        if abs(v) > 0.25:
            words.append(pos if v > 0 else neg)
    text = "seen from " + (", ".join(words) if words else "the focal point")
    right, _up, _back = basis(cam)
    a_right = float(right[0]) < -0.25  # eye A (at -x) drawn right of eye B
    if a_right or float(right[0]) > 0.25:
        text += f"\neye A on the {'right' if a_right else 'left'}"
    return text


def dolly(cam: Camera3D, factor: float) -> Camera3D:
    """``cam`` moved along its line of sight to ``factor`` times its distance from the
    focal point (same direction, view-up and angle)."""
    foc = np.asarray(cam.focal_point, np.float64)
    pos = foc + (np.asarray(cam.position, np.float64) - foc) * check_real("factor", factor, gt=0.0)
    return Camera3D(tuple(float(c) for c in pos), cam.focal_point, cam.view_up, cam.view_angle)  # type: ignore[arg-type]
