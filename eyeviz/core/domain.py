"""The one parameter record: the eye design (Table 3) and the object ranges (Table 4).

The paper's defaults (h = 40, l = 20, m = 720 of Table 3; r in [1000, 5000], g up to
g_max = 500 of Table 4 and Algorithm 1) come from :mod:`eyeviz.core.paper`. The estimators
(:attr:`Estimator.domain`), the data set generator (:class:`eyeviz.dataset.GenParams`) and
the CLI flags (``--h --l --m --r-min --r-max --g-max``) all read :data:`DEFAULTS`.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import Any

from eyeviz import EyevizError
from eyeviz.core import paper
from eyeviz.core.geometry import EyePair
from eyeviz.core.validation import check_real

__all__ = ["DEFAULTS", "Domain", "PAPER_DOMAIN", "FIELDS"]

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


@dataclass(frozen=True)
class Domain:
    """Model (Table 3) and object (Table 4) parameters: what an estimator answers for and
    what Algorithm 1 samples from."""

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
        r_min = check_real("r_min", self.r_min, gt=0)
        r_max = check_real("r_max", self.r_max, gt=0)
        if r_min >= r_max:
            raise EyevizError(
                f"r_min must be < r_max, got r_min={self.r_min!r}, r_max={self.r_max!r}"
            )
        check_real("g_max", self.g_max, gt=0)

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

    def to_dict(self) -> dict[str, float]:
        return asdict(self)

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> Domain:
        return cls(**{k: d[k] for k in FIELDS if k in d})

    @classmethod
    def from_eyes(cls, eyes: EyePair, **ranges: float) -> Domain:
        return cls(eyes.h, eyes.l, eyes.m, **ranges)


PAPER_DOMAIN = Domain()
