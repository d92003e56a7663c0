"""One warning for every character the figure's font cannot draw.

matplotlib warns once per missing glyph and per renderer pass ("Glyph 128029
(\\N{HONEYBEE}) missing from font(s) DejaVu Sans.", plus the source line): a feature name
of three emoji printed three such pairs, at every export. :func:`one_glyph_warning`
gathers them and prints one line naming the characters; other warnings pass unchanged.
"""

from __future__ import annotations

import re
import sys
import warnings
from collections.abc import Iterator
from contextlib import contextmanager

__all__ = ["glyph_message", "one_glyph_warning"]

_GLYPH = re.compile(r"^Glyph (\d+) .*missing from (?:current )?font")
_SHOWN = 12  # characters listed in the line at most


def glyph_message(codes: list[int]) -> str:
    """The line for the missing characters ``codes`` (code points, in order of first use)."""
    shown = " ".join(f"{chr(c)} (U+{c:04X})" for c in codes[:_SHOWN])
    more = f" and {len(codes) - _SHOWN} more" if len(codes) > _SHOWN else ""
    n = len(codes)
    return (
        f"eyeviz: warning: {n} character{'s' if n != 1 else ''} not in the figure's font "
        f"(DejaVu Sans) drawn as boxes: {shown}{more}"
    )


@contextmanager
def one_glyph_warning(stream=None) -> Iterator[None]:
    """Collect matplotlib's missing-glyph warnings raised inside; at the end print one line
    to ``stream`` (default stderr) naming each missing character once."""
    codes: list[int] = []
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            yield
        finally:
            others = []
            for w in caught:
                m = _GLYPH.match(str(w.message))
                if m is None:
                    others.append(w)
                elif int(m.group(1)) not in codes:
                    codes.append(int(m.group(1)))
    for w in others:  # outside the recording: shown (or filtered) as they would have been
        warnings.warn_explicit(w.message, w.category, w.filename, w.lineno, source=w.source)
    if codes:
        print(glyph_message(codes), file=sys.stderr if stream is None else stream)
