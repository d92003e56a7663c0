"""The one argument checker: scikit-learn style one-line messages.

>>> check_int("m", 7, ge=4, even=True)
Traceback (most recent call last):
eyeviz.EyevizError: m must be an even integer >= 4, got 7

Every function returns the checked value converted (``float`` / ``int``) and raises
:class:`eyeviz.EyevizError` (a ValueError) naming the parameter, the rule and the value.
A forbidden value is refused, never clamped.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from numbers import Integral, Real

from eyeviz import EyevizError

__all__ = ["check_real", "check_positive", "check_int", "check_choice"]


def _rule(gt: float | None, ge: float | None, lt: float | None, le: float | None) -> str:
    parts = []
    if gt is not None:
        parts.append(f"> {gt:g}")
    if ge is not None:
        parts.append(f">= {ge:g}")
    if lt is not None:
        parts.append(f"< {lt:g}")
    if le is not None:
        parts.append(f"<= {le:g}")
    return " and ".join(parts)


def check_real(
    name: str,
    value,
    *,
    gt: float | None = None,
    ge: float | None = None,
    lt: float | None = None,
    le: float | None = None,
    finite: bool = True,
) -> float:
    """``value`` as a float; refuses non-numbers, bools, NaN, inf (unless ``finite=False``)
    and values outside the bounds: "g_max must be a finite number > 0, got nan"."""
    rule = _rule(gt, ge, lt, le)
    what = "a finite number" if finite else "a number"
    msg = f"{name} must be {what}{' ' + rule if rule else ''}, got {value!r}"
    if isinstance(value, bool) or not isinstance(value, Real | str):
        try:
            v = float(value)  # numpy 0-d arrays and the like
        except (TypeError, ValueError):
            raise EyevizError(msg) from None
    else:
        try:
            v = float(value)
        except (TypeError, ValueError):
            raise EyevizError(msg) from None
    if isinstance(value, bool) or math.isnan(v) or (finite and math.isinf(v)):
        raise EyevizError(msg)
    if (
        (gt is not None and not v > gt)
        or (ge is not None and not v >= ge)
        or (lt is not None and not v < lt)
        or (le is not None and not v <= le)
    ):
        raise EyevizError(msg)
    return v


def check_positive(name: str, value) -> float:
    """A finite number > 0."""
    return check_real(name, value, gt=0)


def check_int(
    name: str,
    value,
    *,
    ge: int | None = None,
    le: int | None = None,
    even: bool = False,
) -> int:
    """``value`` as an int (bools and non-integral floats refused):
    "m must be an even integer >= 4, got 7"."""
    rule = _rule(None, ge, None, le)
    msg = f"{name} must be {'an even' if even else 'an'} integer{' ' + rule if rule else ''}"
    msg += f", got {value!r}"
    if isinstance(value, bool) or not isinstance(value, Integral):
        raise EyevizError(msg)
    v = int(value)
    if (ge is not None and v < ge) or (le is not None and v > le) or (even and v % 2):
        raise EyevizError(msg)
    return v


def check_choice(name: str, value, choices: Iterable[str]) -> str:
    """One of ``choices``: "mode must be one of 'single', 'multi', got 'x'"."""
    choices = tuple(choices)
    if value not in choices:
        listed = ", ".join(repr(c) for c in choices)
        raise EyevizError(f"{name} must be one of {listed}, got {value!r}")
    return value
