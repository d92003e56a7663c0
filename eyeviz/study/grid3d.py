"""The design grid of the 3D design study: every (h, l, nside) with l < h.

The 3D form of :mod:`eyeviz.study.grid`: the product of lists of h, l and nside (the
HEALPix resolution of each spherical eye, 12 nside^2 facets, 4 nside on the equator;
docs/spherical.md), keeping the designs whose eyes do not overlap (l < h), each with the
same object ranges (r, g and the elevation band |el| <= el_max), prior, n, seed and
estimator (:class:`~eyeviz.study.point3d.DesignPoint3D`).

Bad input ends in one :class:`eyeviz.EyevizError` naming it: ``design_grid3d(nside="7")``
-> "nside must be an even integer ..."; a grid with no design where l < h; n < 1; a design
where no ball can be visible (the 3D generator's checks, naming the design).
"""

from __future__ import annotations

import math
from collections.abc import Iterable

from eyeviz import EyevizError
from eyeviz.core.bounds import check_nside
from eyeviz.core.domain import DEFAULT_EL_MAX, DEFAULTS
from eyeviz.core.validation import check_real, num
from eyeviz.study.grid import DEFAULT_H, DEFAULT_L, grid_axes, grid_pairs
from eyeviz.study.point3d import DEFAULT_ESTIMATOR, DesignPoint3D

__all__ = ["DEFAULT_NSIDE", "DEFAULT_N3D", "design_grid3d"]

#: The default resolutions: m = 4 nside = 64, 128, 256 on the equator (the planar study's
#: m = 180 ... 2880 span nside 45 ... 720; 3D lit sets grow as nside^2, so the default stays
#: small; the paper's m = 720 is nside 180).
DEFAULT_NSIDE = (16, 32, 64)
#: Test elements per 3D design point by default.
DEFAULT_N3D = 20_000


def design_grid3d(
    h: str | Iterable = DEFAULT_H,
    l: str | Iterable = DEFAULT_L,  # noqa: E741  (the paper's name)
    nside: str | Iterable = DEFAULT_NSIDE,
    *,
    r_min: float = DEFAULTS["r_min"],
    r_max: float = DEFAULTS["r_max"],
    g_max: float = DEFAULTS["g_max"],
    el_max: float = DEFAULT_EL_MAX,
    prior: str = "single",
    n: int = DEFAULT_N3D,
    seed: int = 0,
    estimator: str = DEFAULT_ESTIMATOR,
) -> list[DesignPoint3D]:
    """The 3D study's design points: every (h, l, nside) of the lists with l < h, in the
    order h, then l, then nside (duplicates dropped). Lists may be texts ("16,32,64").

    Raises a one-line :class:`EyevizError` for a non-number, an odd nside or one < 2, n < 1
    (or beyond :data:`~eyeviz.files.limits.MAX_ROWS`), a bad range, el_max outside
    (0, pi/2), a bad prior, an estimator the registry does not list for the spherical
    eyes, a grid where no design has l < h, or a
    design where no ball can be visible in the binocular field.
    """
    axes = grid_axes(
        h,
        l,
        ("nside", nside, check_nside),
        r_min=r_min,
        r_max=r_max,
        prior=prior,
        priors=("single", "multi"),
        n=n,
        seed=seed,
    )
    check_real("g_max", g_max, gt=0)
    check_real("el_max", el_max, gt=0, lt=math.pi / 2)
    from eyeviz.estimators import registry

    have = registry.available("spherical")
    if estimator not in have:
        raise EyevizError(
            f"estimator must be an estimator of the spherical eyes ({', '.join(have)}), "
            f"got {estimator!r}"
        )
    pairs = grid_pairs(axes)
    out = []
    r_lo, r_hi, n, seed = axes.r_min, axes.r_max, axes.n, axes.seed
    for hv, lv in pairs:
        for nv in axes.resolution:
            try:
                p = DesignPoint3D(hv, lv, nv, r_lo, r_hi, g_max, el_max, prior, n, seed, estimator)
            except EyevizError as exc:
                raise EyevizError(f"design h={num(hv)}, l={num(lv)}, nside={nv}: {exc}") from None
            out.append(p)
    return out
