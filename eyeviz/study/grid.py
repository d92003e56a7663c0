"""The design grid of the eye-design study: every (h, l, m) with l < h (Section 8).

The paper closes with the question of how azimuth and distance accuracy depend on the
eye position h (eyes 2h apart), the eye radius l and the ommatidia per eye m (Table 3).
A grid is the product of lists of h, l and m, keeping the designs whose eyes do not
overlap (l < h), each with the same object ranges (Table 4), prior, n and seed.

Bad input ends in one :class:`eyeviz.EyevizError` naming it: ``parse_list("m", "180,x")``
-> "m: 'x' is not a number"; a grid with no design where l < h; m odd or < 4; n < 1.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence

from eyeviz import EyevizError
from eyeviz.core.bounds import MAX_BINS, check_m, check_r_min
from eyeviz.core.domain import DEFAULTS
from eyeviz.core.validation import check_choice, check_int, check_real
from eyeviz.estimators.limit import PRIORS
from eyeviz.files.limits import MAX_ROWS
from eyeviz.study.point import BIN_WIDTH, DesignPoint

__all__ = ["MAX_GRID_POINTS", "design_grid", "parse_list", "DEFAULT_H", "DEFAULT_L", "DEFAULT_M"]

#: The issue's default grid: the paper's design (h=40, l=20, m=720) by factors of 4 each way.
DEFAULT_H = (10.0, 20.0, 40.0, 80.0, 160.0)
DEFAULT_L = (5.0, 10.0, 20.0)
DEFAULT_M = (180, 360, 720, 1440, 2880)
#: Most design points in one study (a typo such as "--m 1,2,...,99999" is refused).
MAX_GRID_POINTS = 100_000
#: Longest list text accepted by :func:`parse_list`.
MAX_LIST_CHARS = 10_000


def parse_list(name: str, text: str | Iterable) -> list[float]:
    """``"10,20,40"`` -> ``[10.0, 20.0, 40.0]``; a list or tuple passes through checked.

    Blanks around items are ignored; an empty list, an empty item or a non-number
    raises a one-line :class:`EyevizError` naming ``name`` and the item.
    """
    if isinstance(text, str):
        if len(text) > MAX_LIST_CHARS:
            raise EyevizError(f"{name}: list longer than {MAX_LIST_CHARS} characters")
        items: list = [s.strip() for s in text.split(",")]
        if items == [""]:
            raise EyevizError(f"{name}: empty list (give numbers separated by commas)")
    else:
        items = list(text)
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


def _check_m(values: Sequence[float]) -> list[int]:
    # the one bound of m (eyeviz.core.bounds.MAX_M); a list's 720.0 is shown as 720
    return [check_m(int(v) if float(v).is_integer() else v) for v in values]


def _unique(values: Iterable) -> list:
    seen: dict = {}
    for v in values:
        seen.setdefault(v, None)
    return list(seen)


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
    hs = _unique(parse_list("h", h))
    ls = _unique(parse_list("l", l))
    ms = _unique(_check_m(parse_list("m", m)))
    for name, vals in (("h", hs), ("l", ls)):
        for v in vals:
            check_real(name, v, gt=0)
    n = check_int("n", n, ge=1, le=MAX_ROWS)
    seed = check_int("seed", seed, ge=0)
    check_choice("prior", prior, PRIORS)
    r_lo = check_real("r_min", r_min, gt=0)
    r_hi = check_real("r_max", r_max, gt=r_lo)
    check_r_min(r_lo, max(hs))
    if (r_hi - r_lo) / BIN_WIDTH > MAX_BINS:
        raise EyevizError(
            f"r_max - r_min = {r_hi - r_lo:g} gives more than {MAX_BINS} distance bins "
            f"of {BIN_WIDTH:g}"
        )
    pairs = [(hv, lv) for hv in hs for lv in ls if lv < hv]
    if not pairs:
        raise EyevizError(
            f"no design in the grid has l < h (h: {', '.join(f'{v:g}' for v in hs)}; "
            f"l: {', '.join(f'{v:g}' for v in ls)})"
        )
    if len(pairs) * len(ms) > MAX_GRID_POINTS:
        raise EyevizError(
            f"the grid has {len(pairs) * len(ms)} design points, more than {MAX_GRID_POINTS}"
        )
    return [
        DesignPoint(hv, lv, mv, r_min, r_max, g_max, prior, int(n), seed)
        for hv, lv in pairs
        for mv in ms
    ]
