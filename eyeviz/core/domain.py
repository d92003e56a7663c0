"""The one parameter record of every eye model: an eye pair and the object ranges.

A domain is what an estimator answers for and what Algorithm 1 samples from: the eye pair
(``eyes``, any model of :mod:`eyeviz.core.eyes`) and the ranges of the features'
distance r and radius g (Table 4), in space also the elevation band. Every domain has
``eyes``, ``kind``, ``facet_counts``, ``design`` (what a data set must match), ``origin``
(where r and the angles are measured from), ``to_dict`` and ``from_dict``, and
:func:`domain_for` makes the domain of any pair from its eyes and ranges (the models'
default ranges where none are given). Two records hold the models' own fields:

- :class:`Domain`, the planar eyes: ``Domain(h, l, m, r_min, r_max, g_max)``, the
  paper's Table 3 and 4 (h = 40, l = 20, m = 720; r in [1000, 5000], g up to g_max = 500),
  read from :mod:`eyeviz.core.paper` into :data:`DEFAULTS`. The estimators, the data set
  generator (:class:`eyeviz.dataset.GenParams`) and the CLI flags (``--h --l --m --r-min
  --r-max --g-max``) all read :data:`DEFAULTS`.
- :class:`Domain3D`, the eyes in space: ``Domain3D(h, l, nside, r_min, r_max, g_max,
  el_max)`` is the HEALPix pair (docs/spherical.md), h, l and the ranges the paper's and
  nside 180 its m = 720 (m = 4 nside, so the z = 0 slice is the planar eye of Table 3);
  the one new number is the elevation bound (:data:`DEFAULT_EL_MAX`). A measured pair
  (:class:`eyeviz.core.measured.MeasuredEyePair`, docs/measured.md) enters through
  :meth:`Domain3D.for_eyes` with ranges at the animal's scale (:func:`measured_ranges`);
  its h and l are the pair's own and it has no nside.

Which record holds which kind of eyes is the table :data:`RECORDS`; a record states its
kinds (``kinds``) and builds itself from a pair (``_of_eyes``), so a new model adds a row
and a hook, not a branch in the callers.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field
from typing import TYPE_CHECKING, Any, ClassVar, overload

import numpy as np

from eyeviz import EyevizError
from eyeviz.core import paper
from eyeviz.core.bounds import check_nside
from eyeviz.core.eyes import design_kind
from eyeviz.core.geometry import EyePair
from eyeviz.core.geometry3d import EyePair3D
from eyeviz.core.validation import check_real

if TYPE_CHECKING:
    from eyeviz.core.measured import MeasuredEyePair

__all__ = [
    "DEFAULTS",
    "DEFAULTS3D",
    "DEFAULT_EL_MAX",
    "Domain",
    "Domain3D",
    "FIELDS",
    "FIELDS3D",
    "PAPER_DOMAIN",
    "PAPER_DOMAIN3D",
    "RECORDS",
    "domain_for",
    "domain_from_dict",
    "facet_spacing",
    "measured_ranges",
    "pair_spacing",
]

#: Tables 3 and 4 of the paper (eyeviz.core.paper).
DEFAULTS: dict[str, float | int] = {
    "h": paper.H,
    "l": paper.L,
    "m": paper.M,
    "r_min": paper.R_MIN,
    "r_max": paper.R_MAX,
    "g_max": paper.G_MAX,
}
FIELDS = tuple(DEFAULTS)

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


def _check_ranges(r_min: Any, r_max: Any, g_max: Any) -> tuple[float, float, float]:
    """0 < r_min < r_max and g_max > 0, each refused in one line naming it; converted."""
    lo = check_real("r_min", r_min, gt=0)
    hi = check_real("r_max", r_max, gt=0)
    if not lo < hi:
        raise EyevizError(f"r_min must be < r_max, got r_min={lo!r}, r_max={hi!r}")
    return lo, hi, check_real("g_max", g_max, gt=0)


class _Record:
    """What every domain has, whatever its eyes: the members above the model's fields."""

    #: the eye models (``eyes.kind``) the record holds
    kinds: ClassVar[tuple[str, ...]] = ()
    #: the ranges :meth:`for_eyes` takes
    ranges: ClassVar[tuple[str, ...]] = ("r_min", "r_max", "g_max")
    #: how the record names itself in a refusal
    what: ClassVar[str] = "a domain"
    eyes: Any

    @classmethod
    def for_eyes(cls, eyes: Any, **ranges: Any) -> Any:
        """The domain of the pair ``eyes`` with the given ranges (None or absent: the
        model's default). A record takes only its own kinds (one line naming them)."""
        kind = getattr(eyes, "kind", None)
        record = RECORDS.get(kind) if isinstance(kind, str) else None
        if record is None or not issubclass(record, cls):
            *more, last = [k for k, r in RECORDS.items() if issubclass(r, cls)]
            takes = f"{', '.join(more)} or {last}" if more else last
            raise EyevizError(f"{cls.what} takes {takes} eyes, got {kind!r}")
        unknown = sorted(set(ranges) - set(record.ranges))
        if unknown:
            raise EyevizError(f"unknown range {unknown[0]!r} ({', '.join(record.ranges)})")
        return record._of_eyes(eyes, {k: v for k, v in ranges.items() if v is not None})

    @classmethod
    def _of_eyes(cls, eyes: Any, given: dict[str, Any]) -> Any:  # the model's hook
        raise NotImplementedError

    @property
    def kind(self) -> str:
        """The eye model: ``"planar"``, ``"spherical"`` (HEALPix) or ``"measured"``."""
        return str(self.eyes.kind)

    @property
    def facet_counts(self) -> tuple[int, int]:
        """(n_A, n_B): facets per eye (m each for planar eyes, 12 nside^2 for HEALPix)."""
        a, b = self.eyes.facet_counts
        return int(a), int(b)

    @property
    def origin(self) -> tuple[float, ...]:
        """Where r and the angles are measured from: the midpoint of the two eye centres
        (the origin for the paper's and the HEALPix eyes; the lens centroids' midpoint
        for a measured pair)."""
        a, b = self.eyes.centers
        return tuple(0.5 * (float(p) + float(q)) for p, q in zip(a, b, strict=True))


@dataclass(frozen=True)
class Domain(_Record):
    """Planar eyes (Table 3) and object ranges (Table 4): what an estimator answers for
    and what Algorithm 1 samples from."""

    kinds: ClassVar[tuple[str, ...]] = ("planar",)
    what: ClassVar[str] = "a planar domain"

    h: float = DEFAULTS["h"]
    l: float = DEFAULTS["l"]  # noqa: E741  (the paper's name)
    m: int = int(DEFAULTS["m"])
    r_min: float = DEFAULTS["r_min"]
    r_max: float = DEFAULTS["r_max"]
    g_max: float = DEFAULTS["g_max"]

    def __post_init__(self) -> None:
        try:  # validates h, l, m with named messages
            EyePair(self.h, self.l, self.m)
        except ValueError as exc:  # the geometry's own ValueError, as the boundary's error
            raise EyevizError(str(exc)) from None
        _check_ranges(self.r_min, self.r_max, self.g_max)

    @classmethod
    def _of_eyes(cls, eyes: Any, given: dict[str, Any]) -> Domain:
        return cls(eyes.h, eyes.l, eyes.m, **given)

    @property
    def eyes(self) -> EyePair:
        return EyePair(self.h, self.l, self.m)

    @property
    def width(self) -> int:
        """Bitmap length per eye, m/2 (Section 4)."""
        return self.m // 2

    @property
    def design(self) -> tuple[float, float, int]:
        """(h, l, m): the eye design, the part a data set must match."""
        return (float(self.h), float(self.l), int(self.m))

    @property
    def design_names(self) -> tuple[str, ...]:
        """The names of :attr:`design`'s entries: ("h", "l", "m")."""
        return ("h", "l", "m")

    def to_dict(self) -> dict[str, float]:
        return asdict(self)

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> Domain:
        return cls(**{k: d[k] for k in FIELDS if k in d})

    @classmethod
    def from_eyes(cls, eyes: EyePair, **ranges: float) -> Domain:
        """:meth:`for_eyes`, the name the planar side has always used."""
        return cls.for_eyes(eyes, **ranges)


PAPER_DOMAIN = Domain()
#: Facets per eye sampled for :func:`facet_spacing` (evenly spaced indices; enough for a
#: median to two digits, and a bounded cost at a million facets).
_SPACING_SAMPLE = 512


def facet_spacing(unit_axes: np.ndarray) -> float:
    """The eye's interommatidial angle (radians): the median, over up to
    :data:`_SPACING_SAMPLE` evenly spaced facets, of the angle between a facet's axis and
    its nearest neighbour's. ``unit_axes`` (n, 3), unit rows, n >= 2."""
    u = np.asarray(unit_axes, dtype=np.float64)
    n = u.shape[0]
    if n < 2:
        raise EyevizError(f"an eye needs at least 2 facets for a facet spacing, got {n}")
    pick = np.unique(np.linspace(0, n - 1, min(n, _SPACING_SAMPLE)).astype(np.int64))
    best = np.full(pick.size, -2.0)
    for lo in range(0, n, 1 << 16):  # (sample, block) cosines stay small
        c = u[pick] @ u[lo : lo + (1 << 16)].T
        own = (pick >= lo) & (pick < lo + c.shape[1])
        c[np.flatnonzero(own), pick[own] - lo] = -2.0
        np.maximum(best, c.max(axis=1), out=best)
    return float(np.median(np.arccos(np.clip(best, -1.0, 1.0))))


_SPACINGS: dict[str, float] = {}


def pair_spacing(eyes: Any) -> float:
    """The median of both eyes' :func:`facet_spacing` (radians), kept per fingerprint."""
    key = str(eyes.fingerprint)
    if key not in _SPACINGS:
        if len(_SPACINGS) > 16:
            _SPACINGS.clear()
        both = [facet_spacing(e.unit_axes) for e in (eyes.eye_a, eyes.eye_b)]
        _SPACINGS[key] = float(np.median(both))
    return _SPACINGS[key]


#: The measured defaults' elevation bound: the whole front hemisphere (pi/2). A measured
#: pair's binocular field may lie at any elevation (the shipped honeybee's lies below the
#: horizon, in the frame of its file), so no band narrower than the hemisphere is safe.
MEASURED_EL_MAX = math.pi / 2


def measured_ranges(eyes: Any) -> dict[str, float]:
    """Default ranges of a measured pair, at the animal's scale, in its units (mm).

    With dphi the interommatidial angle (:func:`facet_spacing`, the median of both eyes)
    and h half the distance between the eyes' lens centroids:

    - ``r_max = h / dphi``: where the eyes' disparity 2h/r is two facets. The paper's
      r_max = 5000 is this distance at its eyes (40 / (2 pi / 720) = 4584) to 10 %;
    - ``r_min = r_max / 5`` and ``g_max = r_min / 2``: the paper's ratios (Table 4: r in
      [1000, 5000], g up to 500);
    - ``el_max`` = :data:`MEASURED_EL_MAX`.

    For the shipped honeybee (h = 1.58 mm, dphi = 1.14 degrees) that is r in [15.9,
    79.6] mm and g up to 7.96 mm.
    """
    dphi = pair_spacing(eyes)
    if not dphi > 0:
        raise EyevizError("the eyes' facet axes coincide: no interommatidial angle")
    r_max = float(eyes.h) / dphi
    return {"r_min": r_max / 5, "r_max": r_max, "g_max": r_max / 10, "el_max": MEASURED_EL_MAX}


@dataclass(frozen=True)
class Domain3D(_Record):
    """Eye pair (h, l, nside, or a measured pair) and object ranges (r, g, elevation).

    ``Domain3D(h, l, nside, r_min, r_max, g_max, el_max)`` is the HEALPix pair;
    :meth:`for_eyes` takes any spherical-side pair (``eyes``), a measured one with ranges
    at its own scale. Every field is checked on construction (one-line
    :class:`eyeviz.EyevizError` naming it): h, l finite with 0 < l < h (a measured pair:
    its own h and l, any l); nside an even integer in [2, MAX_NSIDE] (the bound of
    :mod:`eyeviz.core.bounds`; None for a measured pair); 0 < r_min < r_max; g_max > 0;
    0 < el_max < pi/2 (radians; <= pi/2 for a measured pair, whose band may be the whole
    front hemisphere).
    """

    kinds: ClassVar[tuple[str, ...]] = ("spherical", "measured")
    ranges: ClassVar[tuple[str, ...]] = ("r_min", "r_max", "g_max", "el_max")
    what: ClassVar[str] = "a 3D domain"

    h: float = DEFAULTS3D["h"]
    l: float = DEFAULTS3D["l"]  # noqa: E741  (the paper's name)
    nside: int = int(DEFAULTS3D["nside"])
    r_min: float = DEFAULTS3D["r_min"]
    r_max: float = DEFAULTS3D["r_max"]
    g_max: float = DEFAULTS3D["g_max"]
    el_max: float = DEFAULTS3D["el_max"]
    #: the eye pair: built from (h, l, nside) when not given; a measured pair via for_eyes
    eyes: Any = field(default=None, compare=False, repr=False)

    def __post_init__(self) -> None:
        measured = self.eyes is not None and getattr(self.eyes, "kind", None) == "measured"
        h = check_real("h", self.h, gt=0)
        l_ = check_real("l", self.l, gt=0)
        if measured:
            if (h, l_) != (float(self.eyes.h), float(self.eyes.l)) or self.nside is not None:
                raise EyevizError(
                    "a measured pair's domain takes h and l from the eyes and has no nside: "
                    "make it with Domain3D.for_eyes(pair, r_min=..., ...)"
                )
            nside = None
        else:
            if not l_ < h:
                raise EyevizError(f"l must be < h (the eyes may not touch), got l={l_!r}, h={h!r}")
            nside = check_nside(self.nside)
        r_min, r_max, g_max = _check_ranges(self.r_min, self.r_max, self.g_max)
        if measured:
            el_max = check_real("el_max", self.el_max, gt=0, le=math.pi / 2)
        else:
            el_max = check_real("el_max", self.el_max, gt=0, lt=math.pi / 2)
        for name, v in (("h", h), ("l", l_), ("nside", nside), ("r_min", r_min)):
            object.__setattr__(self, name, v)
        for name, v in (("r_max", r_max), ("g_max", g_max), ("el_max", el_max)):
            object.__setattr__(self, name, v)
        if self.eyes is None:
            object.__setattr__(self, "eyes", EyePair3D(h, l_, nside))
        elif not measured and self.eyes.design != {"h": h, "l": l_, "nside": nside}:
            raise EyevizError(f"eyes {self.eyes.design} are not the design h, l, nside given")

    @classmethod
    def _of_eyes(cls, eyes: Any, given: dict[str, Any]) -> Domain3D:
        """An :class:`EyePair3D` (ranges default to the paper's) or a measured pair
        (ranges default to :func:`measured_ranges`)."""
        if eyes.kind == "spherical":
            return cls(eyes.h, eyes.l, eyes.nside, **given, eyes=eyes)
        return cls(float(eyes.h), float(eyes.l), None, **{**measured_ranges(eyes), **given},  # type: ignore[arg-type]
                   eyes=eyes)  # fmt: skip

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Domain3D):
            return NotImplemented
        return self._key() == other._key()

    def _key(self) -> tuple:
        return (*self.design, self.r_min, self.r_max, self.g_max, self.el_max)

    def _healpix(self, what: str) -> None:
        if self.nside is None:
            raise EyevizError(
                f"{what} is a property of HEALPix eyes; a measured domain has facet_counts"
            )

    @property
    def m(self) -> int:
        """Facets on the equator, 4 nside: the planar eye's m of the z = 0 slice."""
        self._healpix("m")
        return 4 * self.nside

    @property
    def npix(self) -> int:
        """Facets per eye, 12 nside^2 (HEALPix)."""
        self._healpix("npix")
        return 12 * self.nside * self.nside

    @property
    def gamma(self) -> float:
        """Facet width: 2 pi / m on the HEALPix equator (the planar Eq. 6 at m = 4 nside);
        a measured pair's interommatidial angle (:func:`facet_spacing`, median of both)."""
        if self.nside is None:
            return pair_spacing(self.eyes)
        return 2.0 * math.pi / self.m

    @property
    def psi(self) -> float:
        """Half-angle of the tangent cones from the origin, asin(l/h) (the planar Eq. 15)."""
        self._healpix("psi")
        return math.asin(self.l / self.h)

    @property
    def design(self) -> tuple:
        """(h, l, nside), or (h, l, the eyes' fingerprint) for a measured pair: the eye
        design, the part a data set must match."""
        if self.nside is None:
            return (float(self.h), float(self.l), str(self.eyes.fingerprint))
        return (float(self.h), float(self.l), int(self.nside))

    @property
    def design_names(self) -> tuple[str, ...]:
        """The names of :attr:`design`'s entries: ("h", "l", "nside"), or ("h", "l",
        "fingerprint") for a measured pair."""
        return ("h", "l", "nside" if self.nside is not None else "fingerprint")

    @property
    def design_text(self) -> str:
        """The design in words: (h, l, nside), or h, l and the measured pair's fingerprint."""
        if self.nside is None:
            return f"h={self.h:g} l={self.l:g} measured pair {str(self.eyes.fingerprint)[:12]}"
        return f"({', '.join(self.design_names)}) = {self.design}"

    def to_dict(self) -> dict[str, Any]:
        """The fields (a measured pair: ``eye`` (its fingerprint), ``n_a``, ``n_b`` in place
        of nside; the arrays travel apart, e.g. embedded in a data set)."""
        d: dict[str, Any] = {k: getattr(self, k) for k in FIELDS3D}
        if self.nside is None:
            del d["nside"]
            d.update(self.eyes.design)
        return d

    @classmethod
    def from_dict(cls, d: dict[str, Any], eyes: Any = None) -> Domain3D:
        """The record of ``d``'s known keys (missing ones take the defaults). A measured
        design (key ``eye``) needs its pair as ``eyes``, whose fingerprint must match."""
        if not isinstance(d, dict):
            raise EyevizError(f"a 3D domain must be a dict, got {type(d).__name__}")
        if "eye" in d or (eyes is not None and eyes.kind == "measured"):
            if eyes is None or eyes.kind != "measured":
                raise EyevizError("a measured domain (key 'eye') needs its eye pair")
            if d.get("eye") != eyes.fingerprint:
                raise EyevizError(
                    f"the eyes' fingerprint {eyes.fingerprint[:12]}... is not the design's "
                    f"{str(d.get('eye'))[:12]}..."
                )
            ranges = ("r_min", "r_max", "g_max", "el_max")
            return cls.for_eyes(eyes, **{k: d[k] for k in ranges if k in d})
        return cls(**{k: d[k] for k in FIELDS3D if k in d})


PAPER_DOMAIN3D = Domain3D()


#: The record that holds each kind of eyes (``eyes.kind``): the one table a new model
#: adds a row to, with its record's ``_of_eyes``.
RECORDS: dict[str, type[_Record]] = {
    "planar": Domain,
    "spherical": Domain3D,
    "measured": Domain3D,
}


@overload
def domain_for(eyes: EyePair, **ranges: Any) -> Domain: ...
@overload
def domain_for(eyes: EyePair3D | MeasuredEyePair, **ranges: Any) -> Domain3D: ...
@overload
def domain_for(eyes: Any, **ranges: Any) -> Domain | Domain3D: ...
def domain_for(eyes: Any, **ranges: Any) -> Domain | Domain3D:
    """The domain of any pair of eyes: ``eyes`` and the ranges given (r_min, r_max,
    g_max, in space el_max; None or absent: the model's default)."""
    return _Record.for_eyes(eyes, **ranges)


def domain_from_dict(d: dict[str, Any], eyes: Any = None) -> Domain | Domain3D:
    """The domain a dict names, of the kind its design key says (``m``, ``nside`` or
    ``eye``, :func:`eyeviz.core.eyes.design_kind`); a measured one needs its ``eyes``."""
    if not isinstance(d, dict):
        raise EyevizError(f"a domain must be a dict, got {type(d).__name__}")
    if design_kind(d) == "planar":
        return Domain.from_dict(d)
    return Domain3D.from_dict(d, eyes=eyes)
