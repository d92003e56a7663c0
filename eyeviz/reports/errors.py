"""Standard errors of the reports' accuracy figures, and numbers printed to the precision
their error allows.

An accuracy figure of a report (a MAPE, Eq. 34, or a mean absolute error) is the mean of
one term per test row, so its sampling error is that of a mean. :func:`bootstrap_se`
estimates it by resampling the rows (a fixed seed: a report is reproducible);
:func:`with_error` prints ``value ± se`` with the standard error to two significant
digits and the value to the same decimal place.

>>> with_error(0.77512, 0.02634)
'0.775 ± 0.026'
>>> with_error(1.5, 0.0)
'1.5 ± 0'
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["bootstrap_se", "with_error", "decimals_for"]

#: resamples per standard error: the bootstrap's own relative error is about
#: 1 / sqrt(2 * 1000) = 2 %, below the second significant digit printed
N_BOOT = 1000


def bootstrap_se(terms, n_boot: int = N_BOOT, seed: int = 0) -> float:
    """The bootstrap standard error of ``mean(terms)``: the standard deviation of the
    means of ``n_boot`` resamples of the rows with replacement. NaN for fewer than two
    rows (one row says nothing about its spread)."""
    t = np.asarray(terms, float).ravel()
    if t.size < 2:
        return math.nan
    rng = np.random.default_rng(seed)
    means = np.empty(n_boot)
    chunk = max(1, 2_000_000 // t.size)  # bounded memory for large test sets
    for lo in range(0, n_boot, chunk):
        k = min(chunk, n_boot - lo)
        means[lo : lo + k] = t[rng.integers(0, t.size, size=(k, t.size))].mean(axis=1)
    return float(means.std(ddof=1))


def decimals_for(se: float, digits: int = 2) -> int:
    """Decimal places that show ``se`` to ``digits`` significant digits (at least 0)."""
    if not math.isfinite(se) or se <= 0:
        return -1
    return max(0, digits - 1 - math.floor(math.log10(se)))


def with_error(value: float, se: float, digits: int = 2) -> str:
    """``value ± se``, both to the decimal place of ``se``'s ``digits``-th significant
    digit; a zero or unknown error prints the value in ``%g`` and the error as given."""
    d = decimals_for(se, digits)
    if d < 0:
        return f"{value:g} ± {se:g}" if math.isfinite(se) else f"{value:g}"
    return f"{value:.{d}f} ± {se:.{d}f}"
