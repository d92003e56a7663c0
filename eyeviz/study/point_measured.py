"""The study over measured eyes (issue 33.5): a real pair with fewer facets or a wider head.

A point takes a shipped eye pair (``eye``, a file name of eyeviz/assets/eyes) and reshapes
it (:func:`reshape_pair`):

- ``facets`` in (0, 1]: each eye keeps that fraction of its ommatidia, a fixed random
  subset (seed 0), with its acceptance angle widened by 1 / sqrt(facets) (capped below
  pi) so the kept cones still cover the eye's field: the eye resampled coarser (a random
  subset thins unevenly: the median nearest-neighbour angle of the honeybee grows by 1.15
  and 1.5 at a half and a quarter of the facets, not 1.41 and 2);
- ``widen`` >= 1/4: the two eyes moved apart along the line of their lens centroids so the
  baseline b = 2h becomes ``widen`` times the real one (each eye as it is, translated).

Its test set is the 3D Algorithm 1 on the reshaped pair's domain with the object ranges
r_min, r_max, g_max (mm; the study command defaults them to the *real* pair's ranges, so
every reshaped pair is tested at the same distances) and el_max, and the error of the
estimator (``analytic3d``, or ``limit3d`` where it answers for measured eyes) is measured
by :func:`eyeviz.study.point.evaluate3d`, whose rows this point's table holds
(:data:`TABLE_MEASURED`, :class:`StudyTableMeasured`). The runner distributes these
points as it does the others (:mod:`eyeviz.study.kinds`).
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from functools import lru_cache

import numpy as np

from eyeviz import EyevizError
from eyeviz.core.validation import check_choice, check_int, check_real
from eyeviz.study.point import COLUMNS3D, EL_BINS
from eyeviz.study.table import StudyTable, TableFormat

__all__ = [
    "COLUMNS_MEASURED",
    "DesignPointMeasured",
    "StudyTableMeasured",
    "TABLE_MEASURED",
    "reshape_pair",
]

#: 2: the sampling errors dd_se and el_se (the 3D table's version 2)
VERSION = 2
#: The measured study's columns: the 3D study's with the eye, facets and widen in place
#: of nside.
COLUMNS_MEASURED = (
    "version", "eye", "facets", "widen",
    *(c for c in COLUMNS3D if c not in ("version", "nside")),
)  # fmt: skip
_MAX_NAME = 64


@lru_cache(maxsize=8)
def _shipped(eye: str):
    from eyeviz.files.eye_io import load_eyes, shipped_eye

    return load_eyes(shipped_eye(eye))


def reshape_pair(pair, facets: float, widen: float):
    """``pair`` with a fraction ``facets`` of each eye's ommatidia (acceptance widened by
    1 / sqrt(facets)) and its baseline times ``widen`` (module docstring)."""
    from eyeviz.core.measured import MeasuredEye, MeasuredEyePair

    kept = []
    for eye in (pair.eye_a, pair.eye_b):
        keep = max(2, round(facets * eye.n))
        idx = np.sort(np.random.default_rng(0).permutation(eye.n)[:keep])
        acc = np.minimum(eye.acceptance[idx] / math.sqrt(facets), 0.9 * math.pi)
        kept.append((eye, idx, acc))
    ca, cb = (e.positions[idx].mean(axis=0) for e, idx, _ in kept)
    shift = (widen - 1.0) * (cb - ca) / 2.0  # the kept lenses' centroids move apart
    eyes = [
        MeasuredEye(e.positions[idx] + sign * shift, e.axes[idx], acc, None, name=e.name)
        for (e, idx, acc), sign in zip(kept, (-1.0, 1.0), strict=True)
    ]
    name = f"{pair.name} x{facets:g} facets, x{widen:g} baseline"
    return MeasuredEyePair(eyes[0], eyes[1], name=name, source=pair.source)


@lru_cache(maxsize=16)
def _reshaped(eye: str, facets: float, widen: float):
    return reshape_pair(_shipped(eye), facets, widen)


@dataclass(frozen=True)
class DesignPointMeasured:
    """A shipped eye pair reshaped (facets, widen), its test set and the estimator."""

    eye: str = "AM_60185-real.eye"
    facets: float = 1.0
    widen: float = 1.0
    r_min: float = 16.0
    r_max: float = 80.0
    g_max: float = 8.0
    el_max: float = math.pi / 2
    prior: str = "single"
    n: int = 300
    seed: int = 0
    estimator: str = "analytic3d"

    VERSION = VERSION
    COLUMNS = COLUMNS_MEASURED

    def __post_init__(self) -> None:
        from eyeviz.dataset.algorithm1_3d import make_params3d

        e = self.eye
        if not (isinstance(e, str) and 0 < len(e) <= _MAX_NAME and "/" not in e):
            raise EyevizError(f"eye must be a shipped eye's file name, got {str(e)[:_MAX_NAME]!r}")
        check_real("facets", self.facets, gt=0, le=1)
        check_real("widen", self.widen, ge=0.25, le=100)
        check_choice("prior", self.prior, ("single", "multi"))
        check_int("n", self.n, ge=1)
        check_int("seed", self.seed, ge=0)
        est = self.estimator
        if not (isinstance(est, str) and 0 < len(est) <= 40 and est.isidentifier()):
            raise EyevizError(f"estimator must be an estimator's name, got {est!r}")
        make_params3d(self.domain, self.prior, self.seed)  # named messages: no ball fits

    @property
    def pair(self):
        return _reshaped(self.eye, float(self.facets), float(self.widen))

    @property
    def domain(self):
        from eyeviz.core.domain import domain_for

        return domain_for(
            self.pair, r_min=self.r_min, r_max=self.r_max, g_max=self.g_max, el_max=self.el_max
        )

    @property
    def h(self) -> float:
        return float(self.pair.h)

    @property
    def l(self) -> float:  # noqa: E743  (the seam's name)
        return float(self.pair.l)

    @property
    def m(self) -> int:
        """Facets of eye A (the table's resolution column)."""
        return int(self.pair.facet_counts[0])

    @property
    def gamma(self) -> float:
        """The reshaped pair's interommatidial angle (radians)."""
        from eyeviz.core.domain import pair_spacing

        return float(pair_spacing(self.pair))

    @property
    def key(self) -> tuple:
        return (self.eye, float(self.facets), float(self.widen), float(self.r_min),
                float(self.r_max), float(self.g_max), float(self.el_max), self.prior,
                int(self.n), int(self.seed), self.estimator)  # fmt: skip

    def to_dict(self) -> dict:
        return asdict(self)


#: The measured study's table.
TABLE_MEASURED = TableFormat(
    name="measured study table",
    study="measured study",
    columns=COLUMNS_MEASURED,
    version=VERSION,
    point=DesignPointMeasured,
    resolution="m",
    ints=frozenset({"version", "m", "n", "seed", "count", "flagged"}),
    strs=frozenset({"eye", "prior", "estimator", "bin"}),
    errors=("dd_mape", "ad_mape", "el_mae_deg", "az_mae_deg"),
    r2=("dd_r2", "ad_r2", "el_r2"),
    bounds=("lo", "hi"),
    r_bin="r",
    el_bins=EL_BINS,
    ses=("dd_se", "el_se"),
)


class StudyTableMeasured(StudyTable):
    """The measured study's table on disk (the study table with :data:`TABLE_MEASURED`)."""

    fmt = TABLE_MEASURED


def is_table_measured(path) -> bool:
    """Whether the file at ``path`` starts with the measured study table's columns."""
    try:
        with open(path, "rb") as f:
            first = f.read(64)
    except OSError:
        return False
    return first.startswith(",".join(COLUMNS_MEASURED[:4]).encode("ascii"))


def measured_grid(eye: str, facets, widen, **common) -> list[DesignPointMeasured]:
    """Every (facets, widen) of the lists for the shipped ``eye``, the object ranges
    defaulting to the real pair's (:func:`eyeviz.core.domain.measured_ranges`)."""
    from eyeviz.core.domain import measured_ranges
    from eyeviz.study.grid import parse_list

    base = measured_ranges(_shipped(eye))
    for k in ("r_min", "r_max", "g_max", "el_max"):
        if common.get(k) is None:
            common[k] = base[k]
    fs, ws = parse_list("facets", facets), parse_list("widen", widen)
    return [DesignPointMeasured(eye, float(f), float(w), **common)
            for f in dict.fromkeys(fs) for w in dict.fromkeys(ws)]  # fmt: skip
