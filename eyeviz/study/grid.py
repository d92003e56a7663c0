"""The design grids of the eye-design studies: every (h, l, m) or (h, l, nside) with l < h.

The paper closes with the question of how azimuth and distance accuracy depend on the
eye position h (eyes 2h apart), the eye radius l and the ommatidia per eye m (Table 3;
Section 8). A grid is the product of lists of h, l and the resolution, keeping the
designs whose eyes do not overlap (l < h), each with the same object ranges (Table 4),
prior, n and seed: :func:`design_grid` for the planar eyes (m), :func:`design_grid3d`
for the spherical ones (nside: the HEALPix resolution of each eye, 12 nside^2 facets,
4 nside on the equator; docs/spherical.md), whose points also share the elevation band
|el| <= el_max and the estimator (:class:`~eyeviz.study.point.DesignPoint3D`). Both
read their axes through :func:`grid_axes`.

Bad input ends in one :class:`eyeviz.EyevizError` naming it: ``parse_list("m", "180,x")``
-> "m: 'x' is not a number"; a grid with no design where l < h; m odd or < 4;
``design_grid3d(nside="7")`` -> "nside must be an even integer ..."; n < 1; a 3D design
where no ball can be visible (the 3D generator's checks, naming the design).
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass

from eyeviz import EyevizError
from eyeviz.core import paper
from eyeviz.core.bounds import MAX_BINS, check_m, check_nside, check_r_min
from eyeviz.core.domain import DEFAULT_EL_MAX, DEFAULTS
from eyeviz.core.validation import check_choice, check_int, check_real, num
from eyeviz.estimators.limit import PRIORS
from eyeviz.files.limits import MAX_ROWS
from eyeviz.study.point import BIN_WIDTH, DEFAULT_ESTIMATOR, DesignPoint, DesignPoint3D

__all__ = [
    "DEFAULT_H",
    "DEFAULT_L",
    "DEFAULT_M",
    "DEFAULT_N3D",
    "DEFAULT_NSIDE",
    "MAX_GRID_POINTS",
    "GridAxes",
    "design_grid",
    "design_grid3d",
    "grid_axes",
    "grid_pairs",
    "parse_list",
]

#: The issue's default grid: the paper's design (h=40, l=20, m=720) by factors of 4 each way:
#: h 10 ... 160, l 5 ... 20, m 180 ... 2880.
DEFAULT_H = tuple(paper.H * f for f in (0.25, 0.5, 1, 2, 4))
DEFAULT_L = tuple(paper.L * f for f in (0.25, 0.5, 1))
DEFAULT_M = tuple(int(paper.M * f) for f in (0.25, 0.5, 1, 2, 4))
#: Most design points in one study (a typo such as "--m 1,2,...,99999" is refused).
MAX_GRID_POINTS = 100_000
#: Longest list text accepted by :func:`parse_list`.
MAX_LIST_CHARS = 10_000
#: Largest seed: the study tables hold integers of at most 19 digits (their one parser,
#: :mod:`eyeviz.study.table_format`), so a larger one would be refused after its point.
MAX_SEED = 10**19 - 1


def parse_list(name: str, text: str | Iterable) -> list[float]:
    """``"10,20,40"`` -> ``[10.0, 20.0, 40.0]``; a list or tuple passes through checked,
    one number is a list of one.

    Blanks around items are ignored; an empty list, an empty item or a non-number
    raises a one-line :class:`EyevizError` naming ``name`` and the item.
    """
    if isinstance(text, str):
        if len(text) > MAX_LIST_CHARS:
            raise EyevizError(f"{name}: list longer than {MAX_LIST_CHARS} characters")
        items: list = [s.strip() for s in text.split(",")]
        if items == [""]:
            raise EyevizError(f"{name}: empty list (give numbers separated by commas)")
    elif isinstance(text, numbers.Real):  # one value, as a list of one
        items = [text]
    else:
        try:
            items = list(text)
        except TypeError:
            raise EyevizError(
                f"{name} must be numbers separated by commas or a list of numbers, "
                f"got {type(text).__name__}"
            ) from None
        if not items:
            raise EyevizError(f"{name}: empty list")
    out = []
    for item in items:
        if isinstance(item, str) and not item:
            raise EyevizError(f"{name}: empty item in {text!r}")
        try:
            v = float(item)
        except (TypeError, ValueError, OverflowError):
            raise EyevizError(f"{name}: {item!r} is not a number") from None
        if isinstance(item, bool) or not math.isfinite(v):
            raise EyevizError(f"{name}: {item!r} is not a finite number")
        out.append(v)
    return out


def _unique(values: Iterable) -> list:
    seen: dict = {}
    for v in values:
        seen.setdefault(v, None)
    return list(seen)


@dataclass(frozen=True)
class GridAxes:
    """A grid's checked lists (duplicates dropped) and the settings all its points share."""

    h: list[float]
    l: list[float]  # noqa: E741  (the paper's name)
    resolution: list[int]  # m (planar) or nside (3D)
    n: int
    seed: int
    r_min: float
    r_max: float


def grid_axes(
    h: str | Iterable,
    l: str | Iterable,  # noqa: E741  (the paper's name)
    resolution: tuple[str, str | Iterable, Callable[..., int]],
    *,
    r_min: float,
    r_max: float,
    prior: str,
    priors: Sequence[str],
    n: int,
    seed: int,
) -> GridAxes:
    """The lists of h, l and the resolution (``(name, list, checker of one value)``:
    m and :func:`~eyeviz.core.bounds.check_m`, or nside and
    :func:`~eyeviz.core.bounds.check_nside`) and what every point shares, each checked
    with a one-line error naming it; for :func:`design_grid` and
    :func:`design_grid3d`."""
    name, values, check = resolution
    hs = _unique(parse_list("h", h))
    ls = _unique(parse_list("l", l))
    # the one bound of each (eyeviz.core.bounds); a list's 720.0 is shown as 720
    rs = _unique(check(int(v) if v.is_integer() else v) for v in parse_list(name, values))
    for what, vals in (("h", hs), ("l", ls)):
        for v in vals:
            check_real(what, v, gt=0)
    n = check_int("n", n, ge=1, le=MAX_ROWS)
    seed = check_int("seed", seed, ge=0, le=MAX_SEED)
    check_choice("prior", prior, tuple(priors))
    r_lo = check_real("r_min", r_min, gt=0)
    r_hi = check_real("r_max", r_max, gt=r_lo)
    return GridAxes(hs, ls, rs, int(n), seed, r_lo, r_hi)


def grid_pairs(axes: GridAxes) -> list[tuple[float, float]]:
    """The (h, l) of the grid with l < h, in order; refused in one line: r_min too near
    the eyes, too many distance bins, no design with l < h, too many points."""
    hs, ls = axes.h, axes.l
    check_r_min(axes.r_min, max(hs))
    if (axes.r_max - axes.r_min) / BIN_WIDTH > MAX_BINS:
        raise EyevizError(
            f"r_max - r_min = {axes.r_max - axes.r_min:g} gives more than {MAX_BINS} distance "
            f"bins of {BIN_WIDTH:g}"
        )
    pairs = [(hv, lv) for hv in hs for lv in ls if lv < hv]
    if not pairs:
        raise EyevizError(
            f"no design in the grid has l < h (h: {', '.join(f'{v:g}' for v in hs)}; "
            f"l: {', '.join(f'{v:g}' for v in ls)})"
        )
    if len(pairs) * len(axes.resolution) > MAX_GRID_POINTS:
        raise EyevizError(
            f"the grid has {len(pairs) * len(axes.resolution)} design points, more than "
            f"{MAX_GRID_POINTS}"
        )
    return pairs


def design_grid(
    h: str | Iterable = DEFAULT_H,
    l: str | Iterable = DEFAULT_L,  # noqa: E741  (the paper's name)
    m: str | Iterable = DEFAULT_M,
    *,
    r_min: float = DEFAULTS["r_min"],
    r_max: float = DEFAULTS["r_max"],
    g_max: float = DEFAULTS["g_max"],
    prior: str = "single",
    n: int = 100_000,
    seed: int = 0,
) -> list[DesignPoint]:
    """The study's design points: every (h, l, m) of the lists with l < h, in the order
    h, then l, then m (duplicates dropped). Lists may be texts such as ``"10,20,40"``.

    Raises a one-line :class:`EyevizError` for a non-number, m odd or < 4, n < 1 (or
    beyond :data:`~eyeviz.files.limits.MAX_ROWS`), a bad range or prior, or a grid where
    no design has l < h.
    """
    axes = grid_axes(
        h,
        l,
        ("m", m, check_m),
        r_min=r_min,
        r_max=r_max,
        prior=prior,
        priors=PRIORS,
        n=n,
        seed=seed,
    )
    return [
        DesignPoint(hv, lv, mv, r_min, r_max, g_max, prior, axes.n, axes.seed)
        for hv, lv in grid_pairs(axes)
        for mv in axes.resolution
    ]


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
