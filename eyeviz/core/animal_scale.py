"""The prior at the animal's scale for a measured eye pair: lengths in mm or in baselines.

A measured pair's prior is Algorithm 1 on its :class:`~eyeviz.core.domain.Domain3D`
(docs/measured.md, "Data sets and estimators"): r uniform in [r_min, r_max] (single
pass) or with density r^2 (multi pass), the radius g uniform in [r sin(dphi/2), g_max],
the elevation in the band |el| <= el_max, the azimuth in front, and only the balls of the
binocular field kept (``in_bfv``: the ball lights at least two facets of each eye and
contains no lens). This module states its lengths at the animal's scale:

- the **baseline** b is the distance between the two eyes' lens centroids, 2h
  (:func:`baseline`; 3.16 mm for the shipped honeybee, 3.77 and 2.40 mm for the two
  bumblebees);
- every length of the prior (r_min, r_max, g_max) may be given in millimetres (a number,
  ``"30"`` or ``"30mm"``) or in baselines (``"12b"``): :func:`parse_length`,
  :func:`prior_ranges`;
- the defaults are :func:`eyeviz.core.domain.measured_ranges`, whose reasons are:
  r_max = h / dphi, where the disparity 2h/r of a ball is two interommatidial angles, so
  r_max / b = 1 / (2 dphi) (25 b for the honeybee, dphi = 1.14 degrees: beyond it two
  facets of disparity are all a pair of eyes has); r_min = r_max / 5 (5 b) and
  g_max = r_min / 2, the paper's ratios (Table 4); el_max = pi/2, since a real pair's
  binocular field may lie at any elevation (the honeybee's lies 35 to 48 degrees below
  the horizon).

The field itself is not a parameter: it is the pair's, decided exactly per ball.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from typing import Any

from eyeviz import EyevizError
from eyeviz.core.validation import check_real, num

__all__ = ["Length", "baseline", "describe_prior", "parse_length", "prior_ranges", "to_mm"]

#: The lengths of the prior that may be given in baselines.
LENGTHS = ("r_min", "r_max", "g_max")
_LENGTH = re.compile(r"^\s*(\S+?)\s*(mm|b)?\s*$")


@dataclass(frozen=True)
class Length:
    """A length of the prior: ``value`` in ``unit`` ("mm", or "b": baselines)."""

    value: float
    unit: str = "mm"

    def __post_init__(self) -> None:
        if self.unit not in ("mm", "b"):
            raise EyevizError(f"a length's unit must be 'mm' or 'b', got {self.unit!r}")
        object.__setattr__(self, "value", check_real("length", self.value, gt=0))

    def __str__(self) -> str:
        return f"{num(self.value)}{'b' if self.unit == 'b' else ' mm'}"


def parse_length(text: Any, name: str = "length") -> Length:
    """``"30"``, ``"30mm"`` (millimetres) or ``"12b"`` (baselines) as a :class:`Length`;
    a number is millimetres. One-line :class:`EyevizError` naming ``name`` otherwise."""
    if isinstance(text, Length):
        return text
    if isinstance(text, (int, float)) and not isinstance(text, bool):
        return Length(check_real(name, text, gt=0))
    m = _LENGTH.match(text) if isinstance(text, str) and len(text) < 64 else None
    try:
        value = float(m.group(1)) if m is not None else None
    except ValueError:
        value = None
    if m is None or value is None:
        raise EyevizError(
            f"{name} must be a length such as 30 or 30mm (millimetres) or 12b (baselines), "
            f"got {str(text)[:64]!r}"
        )
    return Length(check_real(name, value, gt=0), m.group(2) or "mm")


def baseline(eyes: Any) -> float:
    """The baseline b of a pair (mm): the distance between its eyes' lens centroids, 2h."""
    b = 2.0 * float(eyes.h)
    if not (math.isfinite(b) and b > 0):
        raise EyevizError("the eyes' lens centroids coincide: the pair has no baseline")
    return b


def to_mm(length: Any, eyes: Any, name: str = "length") -> float:
    """A length (:func:`parse_length`'s forms) in millimetres for ``eyes``."""
    n = parse_length(length, name)
    return n.value * baseline(eyes) if n.unit == "b" else n.value


def prior_ranges(eyes: Any, **given: Any) -> dict[str, float | None]:
    """The Domain3D ranges (r_min, r_max, g_max in mm; el_max in radians) of ``given``,
    each a length in mm or baselines (r_min, r_max, g_max) or None for the default
    (:func:`eyeviz.core.domain.measured_ranges`); pass the result to
    ``Domain3D.for_eyes(eyes, **ranges)``."""
    unknown = sorted(set(given) - {*LENGTHS, "el_max"})
    if unknown:
        raise EyevizError(f"unknown range {unknown[0]!r} (r_min, r_max, g_max, el_max)")
    out: dict[str, float | None] = {}
    for k, v in given.items():
        out[k] = None if v is None else to_mm(v, eyes, k) if k in LENGTHS else v
    return out


def describe_prior(domain: Any) -> dict[str, float]:
    """A measured domain's prior at the animal's scale: b (mm), dphi (degrees), the r
    range in mm and in b, g_max in mm and b, el_max in degrees."""
    b = baseline(domain.eyes)
    return {
        "b_mm": b,
        "dphi_deg": math.degrees(domain.gamma),
        "r_min_mm": domain.r_min,
        "r_max_mm": domain.r_max,
        "r_min_b": domain.r_min / b,
        "r_max_b": domain.r_max / b,
        "g_max_mm": domain.g_max,
        "g_max_b": domain.g_max / b,
        "el_max_deg": math.degrees(domain.el_max),
    }
