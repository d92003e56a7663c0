"""The bounds of the model and of a run: one named constant each, checked in one place.

Every limit that is a property of the *model* lives here (issue 20): the largest eye
(m ommatidia, nside of the spherical eye), the smallest r_min relative to h, the largest
r, g and |phi| a data set row may hold. The bounds of a run's options (threads, learning
rate, Algorithm 1 segments, histogram bins) live here too. Limits about *files* (bytes,
rows, declared array shapes) are :mod:`eyeviz.files.limits`.

m has one bound, :data:`MAX_M`, and every entry point applies it through :func:`check_m`:
the API (:class:`eyeviz.core.geometry.EyePair`, and so :class:`eyeviz.core.domain.Domain`),
the CLI (``--m``), scene files and Save, data set and model files, the app's Eyes panel.
A scene the window draws can therefore always be saved, generated and predicted.

>>> check_m(720)
720
>>> check_m(MAX_M + 2)
Traceback (most recent call last):
eyeviz.EyevizError: m must be an even integer >= 4 and <= 1048576, got 1048578
"""

from __future__ import annotations

from eyeviz import EyevizError
from eyeviz.core.validation import check_int

__all__ = [
    "MAX_BINS",
    "MAX_DATA_PHI",
    "MAX_DATA_R",
    "MAX_LR",
    "MAX_M",
    "MAX_NSIDE",
    "MAX_SEGMENTS",
    "MAX_THREADS",
    "MIN_R_OVER_H",
    "check_bins",
    "check_m",
    "check_nside",
    "check_r_min",
    "check_segments",
]

# --- the model -------------------------------------------------------------------------

#: Ommatidia per eye, m (Eq. 6). The interval formulas stay exact far beyond it (to 2^53,
#: issue 13), but everything that holds a whole eye does not: a data set row carries m/2
#: bits per eye (a CSV line of 2m bytes), the app draws m cells per eye (at 2^20 a change
#: of m redraws in about 0.4 s and an edit in about 40 ms) and the bitmap panel m/2.
MAX_M = 1 << 20
#: HEALPix nside of the spherical eye (an even integer >= 2; 12 nside^2 facets per eye).
#: Its equatorial ring is the planar eye EyePair(h, l, 4 nside): that holds as an EyePair
#: for nside <= MAX_M / 4.
MAX_NSIDE = 1 << 20
#: Smallest r_min of a generated data set, relative to the eye pair's h (below it the
#: exact path works with numbers so far apart that it takes hours).
MIN_R_OVER_H = 1e-6
#: Largest r and g of a data set row, and |phi| (radians): beyond these no bitmap can
#: describe the row and the metrics' sums of squares overflow (r = 1e308 in a CSV).
MAX_DATA_R = 1e15
MAX_DATA_PHI = 8.0

# --- the options of a run --------------------------------------------------------------

#: Threads of one process (``--threads``; torch overflows on larger counts).
MAX_THREADS = 1024
#: Largest learning rate a training option takes (beyond it the nets only diverge, and
#: above 3.4e38 torch cannot even hold it as a float32).
MAX_LR = 10.0
#: Multi-pass segments of Algorithm 1 (``--segments``) and histogram bins (``--bins``).
MAX_SEGMENTS = 10**5
MAX_BINS = 10**5


def check_m(m, name: str = "m") -> int:
    """Ommatidia per eye: an even integer in [4, MAX_M] (Eq. 6, 7)."""
    return check_int(name, m, ge=4, le=MAX_M, even=True)


def check_nside(nside, name: str = "nside") -> int:
    """HEALPix nside of a spherical eye: an even integer in [2, MAX_NSIDE]."""
    return check_int(name, nside, ge=2, le=MAX_NSIDE, even=True)


def check_r_min(r_min: float, h: float) -> float:
    """r_min must be >= MIN_R_OVER_H * h (near 1e-300 the exact path takes hours)."""
    if not r_min >= MIN_R_OVER_H * h:
        bound = MIN_R_OVER_H * h
        raise EyevizError(f"r_min = {r_min!r} is below {MIN_R_OVER_H:g} * h = {bound:g}")
    return r_min


def check_segments(k, name: str = "segments") -> int:
    return check_int(name, k, ge=1, le=MAX_SEGMENTS)


def check_bins(k, name: str = "bins") -> int:
    return check_int(name, k, ge=1, le=MAX_BINS)
