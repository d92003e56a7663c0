"""Measuring for the estimators report (:mod:`eyeviz.reports.estimators`), every eye model.

Planar eyes (:func:`measure`): fresh test sets with the paper's parameters (Tables 3 and
4), each estimator's metrics on them, its batched and single-sample inference time, and
Table 5 of the paper quoted. Eyes that see lit sets, the spherical (HEALPix) and the
measured ones (:func:`measure_lit`): one data set of (r, azimuth, elevation) rows, each
estimator's error in the three coordinates with bootstrap standard errors, the rows it
flagged, and its time per row. Both give :class:`Result`.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from eyeviz.reports.common import accuracy_metrics, try_load
from eyeviz.reports.errors import bootstrap_se

if TYPE_CHECKING:
    from eyeviz.estimators.base import Estimator, Prediction


TEST_SEED = 20_231_122  # not a training seed of any shipped estimator
TEST_SETS = ("single", "multi")
TARGETS = (("ad", "phi"), ("dd", "r"))

# Table 5 of the paper, quoted. Its R^2 is Eq. 35 (spread of the predictions).
PAPER_TABLE5: dict[str, Any] = {
    "ad": {
        "mape": 0.832,
        "r2": 0.998,
        "train_seconds": 2 * 3600 + 3 * 60 + 49,
        "setup": "RMSProp, batch 64, lr 0.004",
    },
    "dd": {
        "mape": 7.713,
        "r2": 0.899,
        "train_seconds": 48 * 60 + 53,
        "setup": "SGD, batch 32, lr 0.001",
    },
    "n_weights": 60_671_521 + 32_674_321,  # Appendix A + B layer sizes
    "hardware": "nVidia Tesla P4 (Google Colab)",
}


#: estimators of lit sets measured on the subset only (milliseconds per row)
SLOW = ("limit3d",)
#: the figures of an estimator of lit sets: DD, AD (MAPE %), elevation MAPE % and MAE deg
LIT_KEYS = ("dd", "ad", "el_mape", "el_mae_deg")


@dataclass
class Result:
    """One estimator's figures, for every eye model; ``status`` is "ok" or the reason it is
    unavailable.

    ``metrics``: planar eyes, per test set ("single", "multi") ``{"n", "n_valid", "ad",
    "dd"}`` with MAPE, MAE and R^2 of each; eyes that see lit sets, per part ("subset":
    the rows every estimator is scored on, "all": every row) the :data:`LIT_KEYS` figures
    of the three coordinates, ``errors`` their bootstrap standard errors and ``flagged``
    the rows answered by a fallback, of ``rows`` scored.
    """

    name: str
    status: str = "ok"
    label: str = ""
    n_weights: int | None = None
    train_seconds: float | None = None
    batched_us: float | None = None  # per sample (row), batched
    single_ms: float | None = None  # one sample alone (planar: the median)
    metrics: dict = field(default_factory=dict)
    errors: dict[str, dict[str, float]] = field(default_factory=dict)
    flagged: dict[str, int] = field(default_factory=dict)
    rows: int = 0
    table_keys: int | None = None  # lookup-table estimators (bayes): stored keys

    @property
    def ok(self) -> bool:
        return self.status == "ok"

    def label_short(self) -> str:
        if self.n_weights:
            return f"{self.name} ({_fmt_weights(self.n_weights)} weights)"
        if self.table_keys:
            return f"{self.name} (table of {_fmt_weights(self.table_keys)} keys)"
        return f"{self.name} (no weights)"


def _fmt_weights(n) -> str:
    if n is None:
        return "–"
    return f"{n / 1e6:.1f} M" if n >= 1e6 else f"{n:,}"


def _limit(results: list[Result]) -> Result | None:
    for r in results:
        if r.name == "bayes" and r.ok:
            return r
    return None


def make_test_sets(n: int, seed: int = TEST_SEED) -> dict:
    """Fresh single- and multi-pass test sets with the paper's parameters (Tables 3, 4)."""
    from eyeviz.core.domain import PAPER_DOMAIN
    from eyeviz.dataset import kinds

    return {
        mode: kinds.sample(n, PAPER_DOMAIN, mode=mode, seed=seed + i)
        for i, mode in enumerate(TEST_SETS)
    }


def _time_batched(est: Estimator, oa: np.ndarray, ob: np.ndarray) -> tuple[Prediction, float]:
    t = time.perf_counter()
    pred = est.predict(oa, ob)
    best = time.perf_counter() - t
    if best < 1.0:  # fast estimators: best of three
        for _ in range(2):
            t = time.perf_counter()
            est.predict(oa, ob)
            best = min(best, time.perf_counter() - t)
    return pred, best


def _time_single(est, oa, ob, max_calls: int = 300, max_seconds: float = 3.0) -> float:
    est.predict(oa[0], ob[0])  # warm-up
    times = []
    t_end = time.perf_counter() + max_seconds
    for i in range(min(max_calls, len(oa))):
        t = time.perf_counter()
        est.predict(oa[i], ob[i])
        times.append(time.perf_counter() - t)
        if time.perf_counter() > t_end and len(times) >= 5:
            break
    return float(np.median(times))


def measure_one(name: str, est, test_sets: dict) -> Result:
    """Score and time a loaded estimator on every test set."""
    md = getattr(est, "metadata", {}) or {}
    label = str(md.get("label", ""))
    if not label and "sample_size" in md:  # the bayes table
        label = (
            f"{md.get('target', '')} posterior per interval key from "
            f"{int(md['sample_size']):,} samples ({int(md.get('keys', 0)):,} keys)"
        )
    res = Result(
        name=name,
        label=label,
        n_weights=int(est.n_weights),
        train_seconds=md.get("train_seconds"),
        table_keys=int(md["keys"]) if "keys" in md else None,
    )
    for mode, data in test_sets.items():
        pred, secs = _time_batched(est, data.omega_a, data.omega_b)
        r_hat, phi_hat = pred
        valid = np.asarray(getattr(pred, "valid", np.isfinite(r_hat)))
        entry: dict[str, Any] = {"n": int(len(data.r)), "n_valid": int(valid.sum())}
        for key, col in TARGETS:
            truth = data.phi if col == "phi" else data.r
            entry[key] = accuracy_metrics(truth, phi_hat if col == "phi" else r_hat)
        res.metrics[mode] = entry
        if mode == TEST_SETS[0]:
            res.batched_us = 1e6 * secs / max(1, len(data.r))
            res.single_ms = 1e3 * _time_single(est, data.omega_a, data.omega_b)
    return res


def measure(names: list[str], n_test: int, seed: int = TEST_SEED, progress=None) -> list[Result]:
    test_sets = make_test_sets(n_test, seed)
    out = []
    for name in names:
        est, why = try_load(name)
        out.append(
            measure_one(name, est, test_sets) if est is not None else Result(name=name, status=why)
        )
        if progress is not None:
            progress(name)
    return out


def _terms(ds, rows: np.ndarray, r, az, el) -> dict[str, np.ndarray]:
    """Each figure's per-row terms: its value is their mean (MAPE, Eq. 34; MAE)."""
    if np.any(ds.r[rows] == 0) or np.any(ds.azimuth[rows] == 0) or np.any(ds.elevation[rows] == 0):
        raise ValueError("MAPE is undefined where the true value is 0")
    return {
        "dd": 100.0 * np.abs((r - ds.r[rows]) / ds.r[rows]),
        "ad": 100.0 * np.abs((az - ds.azimuth[rows]) / ds.azimuth[rows]),
        "el_mape": 100.0 * np.abs((el - ds.elevation[rows]) / ds.elevation[rows]),
        "el_mae_deg": np.degrees(np.abs(el - ds.elevation[rows])),
    }


def _metrics(ds, rows: np.ndarray, r, az, el) -> tuple[dict[str, float], dict[str, float]]:
    """The figures on ``rows`` and their bootstrap standard errors (eyeviz.reports.errors)."""
    terms = _terms(ds, rows, r, az, el)
    values = {k: float(np.mean(t)) for k, t in terms.items()}
    return values, {k: bootstrap_se(t) for k, t in terms.items()}


def measure_lit(ds, names: list[str], limit_rows: int = 1000, progress=None) -> list[Result]:
    """Score each estimator ``names`` of lit sets (registry kind "spherical", for the
    spherical or measured eyes) on the lit-set data set ``ds`` (a Dataset3D)."""
    from eyeviz.estimators.base import take_rows

    n = len(ds)
    step = max(1, math.ceil(n / max(1, limit_rows)))
    subset = np.arange(0, n, step)
    out = []
    for name in names:
        res = Result(name)
        est, why = try_load(name, domain=ds.domain)
        if est is None:
            res.status = why
            out.append(res)
            continue
        res.n_weights = int(getattr(est, "n_weights", 0))
        rows = subset if name in SLOW else np.arange(n)
        la = take_rows(ds.indptr_a, ds.indices_a, rows)
        lb = take_rows(ds.indptr_b, ds.indices_b, rows)
        t0 = time.perf_counter()
        p = est.predict(la, lb)
        res.batched_us = (time.perf_counter() - t0) / max(1, rows.size) * 1e6
        valid = np.asarray(p.valid, bool)
        if not valid.all():
            res.status = f"no answer for {int((~valid).sum())} of {rows.size} rows"
            out.append(res)
            continue
        res.rows = int(rows.size)
        flagged = np.asarray(getattr(p, "flagged", np.zeros(rows.size, bool)), bool)
        at = np.searchsorted(rows, subset)
        r, az, el = (np.asarray(v, float) for v in (p[0], p[1], p[2]))
        res.metrics["subset"], res.errors["subset"] = _metrics(ds, subset, r[at], az[at], el[at])
        res.flagged["subset"] = int(flagged[at].sum())
        if name not in SLOW:
            res.metrics["all"], res.errors["all"] = _metrics(ds, rows, r, az, el)
            res.flagged["all"] = int(flagged.sum())
        one_a = take_rows(ds.indptr_a, ds.indices_a, subset[:1])
        one_b = take_rows(ds.indptr_b, ds.indices_b, subset[:1])
        t0 = time.perf_counter()
        est.predict(one_a, one_b)
        res.single_ms = (time.perf_counter() - t0) * 1e3
        out.append(res)
        if progress is not None:
            progress(name)
    return out
