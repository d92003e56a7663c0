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

from eyeviz.estimators.metrics import N_BOOT, bootstrap_se

__all__ = ["N_BOOT", "bootstrap_se", "with_error", "decimals_for"]


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
