"""The one parameter record of the spherical (3D) model: eye design and object ranges.

:class:`Domain3D` is :class:`eyeviz.core.domain.Domain` for two spherical eyes with
HEALPix facets (docs/spherical.md): h, l and the ranges of r and g are the paper's
(Tables 3 and 4, read from :data:`eyeviz.core.domain.DEFAULTS`, never rewritten here);
the facet count is set by ``nside`` (12 nside^2 facets per eye, 4 nside on the equator),
whose default 180 is the paper's m = 720 (m = 4 nside, so the z = 0 slice is the planar
eye of Table 3). The one new number is the elevation bound ``el_max``: see
:data:`DEFAULT_EL_MAX`.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import TYPE_CHECKING, Any

from eyeviz import EyevizError
from eyeviz.core.bounds import check_nside
from eyeviz.core.domain import DEFAULTS
from eyeviz.core.validation import check_real

if TYPE_CHECKING:
    from eyeviz.core.geometry3d import EyePair3D

__all__ = ["DEFAULTS3D", "DEFAULT_EL_MAX", "Domain3D", "FIELDS3D", "PAPER_DOMAIN3D"]

#: Default elevation bound (radians), pi/6 = 30 degrees: features are drawn in the band
#: |el| <= el_max about the horizon z = 0, the plane of the paper's model. A bound is
#: needed: outside both tangent cones from the origin (the 3D binocular field) lie all
#: directions at |el| >= psi = asin(l/h), so the field has no top. Below |el| = psi the
#: cones bound the azimuth away from the eyes' axis, as the paper's wedge does in the
#: plane; at the paper's eyes psi = asin(20/40) = pi/6, so the default band is exactly the
#: part of the field shaped like the planar one, where binocular overlap is there at
#: every distance of Table 4.
DEFAULT_EL_MAX = math.pi / 6

#: Defaults of the 3D record: the paper's (Tables 3, 4) and the elevation band.
DEFAULTS3D: dict[str, float | int] = {
    "h": DEFAULTS["h"],
    "l": DEFAULTS["l"],
    "nside": int(DEFAULTS["m"]) // 4,
    "r_min": DEFAULTS["r_min"],
    "r_max": DEFAULTS["r_max"],
    "g_max": DEFAULTS["g_max"],
    "el_max": DEFAULT_EL_MAX,
}
FIELDS3D = tuple(DEFAULTS3D)


@dataclass(frozen=True)
class Domain3D:
    """Eye design (h, l, nside) and object ranges (r, g, elevation) of the 3D model.

    Every field is checked on construction (one-line :class:`eyeviz.EyevizError` naming
    it): h, l finite with 0 < l < h; nside an even integer in [2, MAX_NSIDE] (the
    bound of :mod:`eyeviz.core.bounds`);
    0 < r_min < r_max; g_max > 0; 0 < el_max < pi/2 (radians).
    """

    h: float = DEFAULTS3D["h"]
    l: float = DEFAULTS3D["l"]  # noqa: E741  (the paper's name)
    nside: int = int(DEFAULTS3D["nside"])
    r_min: float = DEFAULTS3D["r_min"]
    r_max: float = DEFAULTS3D["r_max"]
    g_max: float = DEFAULTS3D["g_max"]
    el_max: float = DEFAULTS3D["el_max"]

    def __post_init__(self) -> None:
        h = check_real("h", self.h, gt=0)
        l_ = check_real("l", self.l, gt=0)
        if not l_ < h:
            raise EyevizError(f"l must be < h (the eyes may not touch), got l={l_!r}, h={h!r}")
        nside = check_nside(self.nside)
        r_min = check_real("r_min", self.r_min, gt=0)
        r_max = check_real("r_max", self.r_max, gt=0)
        if not r_min < r_max:
            raise EyevizError(f"r_min must be < r_max, got r_min={r_min!r}, r_max={r_max!r}")
        g_max = check_real("g_max", self.g_max, gt=0)
        el_max = check_real("el_max", self.el_max, gt=0, lt=math.pi / 2)
        for name, v in (("h", h), ("l", l_), ("nside", nside), ("r_min", r_min)):
            object.__setattr__(self, name, v)
        for name, v in (("r_max", r_max), ("g_max", g_max), ("el_max", el_max)):
            object.__setattr__(self, name, v)

    @property
    def m(self) -> int:
        """Facets on the equator, 4 nside: the planar eye's m of the z = 0 slice."""
        return 4 * self.nside

    @property
    def npix(self) -> int:
        """Facets per eye, 12 nside^2 (HEALPix)."""
        return 12 * self.nside * self.nside

    @property
    def gamma(self) -> float:
        """Equatorial facet width 2 pi / m (the planar Eq. 6 at m = 4 nside)."""
        return 2.0 * math.pi / self.m

    @property
    def psi(self) -> float:
        """Half-angle of the tangent cones from the origin, asin(l/h) (the planar Eq. 15)."""
        return math.asin(self.l / self.h)

    @property
    def eyes(self) -> EyePair3D:
        from eyeviz.core.geometry3d import EyePair3D

        return EyePair3D(self.h, self.l, self.nside)

    @property
    def design(self) -> tuple[float, float, int]:
        """(h, l, nside): the eye design, the part a data set must match."""
        return (float(self.h), float(self.l), int(self.nside))

    def to_dict(self) -> dict[str, float | int]:
        return asdict(self)

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> Domain3D:
        """The record of ``d``'s known keys (missing ones take the defaults)."""
        if not isinstance(d, dict):
            raise EyevizError(f"a 3D domain must be a dict, got {type(d).__name__}")
        return cls(**{k: d[k] for k in FIELDS3D if k in d})


PAPER_DOMAIN3D = Domain3D()
