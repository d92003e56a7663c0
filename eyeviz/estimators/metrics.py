"""Error metrics of Section 5: MAE (Eq. 33), MAPE (Eq. 34) and R^2 (Eq. 35).

R^2 is the standard coefficient of determination, 1 - SS_res / SS_tot with SS_tot the
spread of the TRUE values (as scikit-learn's ``r2_score``); the paper's Eq. 35-36 divide
by the spread of the predictions, which docs/conventions.md lists as an erratum.
NaN predictions are refused: filter them with the estimator's ``valid`` mask first.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["N_BOOT", "bootstrap_se", "mae", "mape", "r2", "summary", "RunningSummary"]


def _pair(y_true, y_pred) -> tuple[np.ndarray, np.ndarray]:
    t = np.asarray(y_true, np.float64).ravel()
    p = np.asarray(y_pred, np.float64).ravel()
    if t.shape != p.shape:
        raise ValueError(f"y_true and y_pred differ in length: {t.size} and {p.size}")
    if t.size == 0:
        raise ValueError("metrics need at least one value")
    if not (np.isfinite(t).all() and np.isfinite(p).all()):
        raise ValueError("metrics need finite values; drop rows where the prediction is NaN")
    return t, p


def mae(y_true, y_pred) -> float:
    """Mean absolute error (Eq. 33)."""
    t, p = _pair(y_true, y_pred)
    return float(np.mean(np.abs(p - t)))


def mape(y_true, y_pred) -> float:
    """Mean absolute percentage error in percent (Eq. 34); y_true must be non-zero."""
    t, p = _pair(y_true, y_pred)
    if np.any(t == 0):
        raise ValueError("MAPE is undefined where the true value is 0")
    return float(100.0 * np.mean(np.abs((p - t) / t)))


def r2(y_true, y_pred) -> float:
    """Standard coefficient of determination (Eq. 35 with the true values' mean)."""
    t, p = _pair(y_true, y_pred)
    ss_tot = float(np.sum((t - t.mean()) ** 2))
    if ss_tot == 0:
        raise ValueError("R^2 is undefined when all true values are equal")
    return 1.0 - float(np.sum((p - t) ** 2)) / ss_tot


def summary(y_true, y_pred) -> dict[str, float]:
    """{"mape": %, "mae": ..., "r2": ...} of one target."""
    return {"mape": mape(y_true, y_pred), "mae": mae(y_true, y_pred), "r2": r2(y_true, y_pred)}


class RunningSummary:
    """:func:`summary` accumulated block by block in O(1) memory (for streamed data sets).

    Sums of |e| and |e/t| and e^2, and the true values' mean and spread merged per block
    (Chan et al.'s parallel variance), so the result equals :func:`summary` on the whole
    arrays up to rounding.
    """

    def __init__(self) -> None:
        self.n = 0
        self._abs = 0.0
        self._rel = 0.0
        self._sq = 0.0
        self._mean = 0.0
        self._m2 = 0.0
        self._zero = False

    def update(self, y_true, y_pred) -> None:
        if np.size(y_true) == 0:
            return
        t, p = _pair(y_true, y_pred)
        e = p - t
        self._zero |= bool(np.any(t == 0))
        self._abs += float(np.sum(np.abs(e)))
        with np.errstate(divide="ignore", invalid="ignore"):
            self._rel += float(np.sum(np.abs(e / t)))
        self._sq += float(np.sum(e * e))
        k = t.size
        mean_b = float(t.mean())
        m2_b = float(np.sum((t - mean_b) ** 2))
        n = self.n + k
        delta = mean_b - self._mean
        self._mean += delta * k / n
        self._m2 += m2_b + delta * delta * self.n * k / n
        self.n = n

    def result(self) -> dict[str, float]:
        if self.n == 0:
            raise ValueError("metrics need at least one value")
        if self._zero:
            raise ValueError("MAPE is undefined where the true value is 0")
        if self._m2 == 0:
            raise ValueError("R^2 is undefined when all true values are equal")
        return {
            "mape": 100.0 * self._rel / self.n,
            "mae": self._abs / self.n,
            "r2": 1.0 - self._sq / self._m2,
        }


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
