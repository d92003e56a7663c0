"""The one argument checker: scikit-learn style one-line messages.

>>> check_int("m", 7, ge=4, even=True)
Traceback (most recent call last):
eyeviz.EyevizError: m must be an even integer >= 4, got 7

Every function returns the checked value converted (``float`` / ``int``) and raises
:class:`eyeviz.EyevizError` (a ValueError) naming the parameter, the rule and the value.
A forbidden value is refused, never clamped. The bounds of the model (the largest m,
nside, ...) live beside these checkers in :mod:`eyeviz.core.bounds`; the limits of files
(bytes, rows, declared shapes) in :mod:`eyeviz.files.limits`.

The integer rule, for every integer the package takes (API, CLI, scene and data files):
an integer is a Python or numpy integer, or a float holding a whole number. JSON, TOML
and numpy arrays hand numbers over as floats, so ``720.0`` is accepted as ``720``;
``720.5``, NaN, inf, bools, strings and None are refused:

>>> check_int("m", 720.0, ge=4, even=True)
720
>>> check_int("m", 720.5, ge=4, even=True)
Traceback (most recent call last):
eyeviz.EyevizError: m must be an even integer >= 4, got 720.5
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from numbers import Integral, Real

from eyeviz import EyevizError

__all__ = ["check_real", "check_positive", "check_int", "check_choice", "num", "shown"]


def num(v: float) -> str:
    """``v`` as short as it reads back exactly: ``40`` for 40.0, ``39.999999`` (never
    ``40``, which ``:g`` printed for it: issue 36), ``1e+300`` for 1e300."""
    if isinstance(v, Integral):
        return str(int(v))
    v = float(v)
    short = f"{v:g}"
    return short if float(short) == v or not math.isfinite(v) else repr(v)


def _num(v: float) -> str:  # a rule's bound, short: "< 1.5708" for pi/2
    return str(v) if isinstance(v, int) else f"{v:g}"


def _rule(gt: float | None, ge: float | None, lt: float | None, le: float | None) -> str:
    parts = []
    for op, bound in ((">", gt), (">=", ge), ("<", lt), ("<=", le)):
        if bound is not None:
            parts.append(f"{op} {_num(bound)}")
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
    msg = f"{name} must be {what}{' ' + rule if rule else ''}, got {shown(value)}"
    if isinstance(value, bool) or not isinstance(value, Real | str):
        try:
            v = float(value)  # numpy 0-d arrays and the like
        except (TypeError, ValueError, OverflowError):
            raise EyevizError(msg) from None
    else:
        try:
            v = float(value)
        except (TypeError, ValueError, OverflowError):
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


def shown(value) -> str:
    """``repr(value)`` cut to one short line (an int of 10**5000 digits has no repr)."""
    try:
        text = repr(value)
    except ValueError:  # an int beyond Python's int-to-str digit limit
        return f"an integer of about {int(value.bit_length() * 0.30103) + 1} digits"
    return text if len(text) <= 40 else f"{text[:20]}...({len(text)} characters)"


def _as_int(value) -> int | None:
    """``value`` as an int under the integer rule (module docstring); None if it is none."""
    if isinstance(value, bool):
        return None
    if isinstance(value, Integral):
        return int(value)
    if isinstance(value, Real):  # float, numpy floating, Fraction
        try:
            v = float(value)
        except (OverflowError, ValueError):
            return None
        if math.isfinite(v) and v == value and v.is_integer():
            return int(v)
    return None


def check_int(
    name: str,
    value,
    *,
    ge: int | None = None,
    le: int | None = None,
    even: bool = False,
) -> int:
    """``value`` as an int: an integer, or a float holding a whole number (the integer
    rule of the module docstring); anything else, or a value outside the bounds, is
    refused: "m must be an even integer >= 4 and <= 1048576, got 7"."""
    v = _as_int(value)
    if v is None or (ge is not None and v < ge) or (le is not None and v > le) or (even and v % 2):
        rule = _rule(None, ge, None, le)
        what = "an even integer" if even else "an integer"
        raise EyevizError(f"{name} must be {what}{' ' + rule if rule else ''}, got {shown(value)}")
    return v


def check_choice(name: str, value, choices: Iterable[str]) -> str:
    """One of ``choices``: "mode must be one of 'single', 'multi', got 'x'"."""
    choices = tuple(choices)
    if value not in choices:
        listed = ", ".join(repr(c) for c in choices)
        raise EyevizError(f"{name} must be one of {listed}, got {value!r}")
    return value
