"""Measuring for the trajectories report (:mod:`eyeviz.reports.trajectories`).

The trajectories of Section 6 and the features placed on them, the accuracy (100 % - MAPE)
of every estimator along each, and what the text of Section 6 states for the paper's nets.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from eyeviz.core import paper
from eyeviz.reports.common import try_load

G_VALUES = (5.0, 50.0, 500.0)
DISTANCES = tuple(float(r) for r in range(1000, 10001, 1000))
KINDS = ("horizontal", "circular", "vertical")
#: Most features per trajectory (--min-count, --max-count).
MAX_COUNT = 100_000
TRAIN_R = (1000.0, 5000.0)
LIMIT_DOMAIN_KW = dict(r_min=1000.0, r_max=10000.0)  # the limit's prior covers every trajectory

# What the text of Section 6 states for the paper's nets: {(kind, target, g): [(r, acc)]}
PAPER_TEXT = {
    ("horizontal", "dd", 500.0): [(1000, 98.0), (5000, 74.0), (10000, 38.0)],
    ("horizontal", "dd", 50.0): [(1000, 94.0), (5000, 71.0), (10000, 36.0)],
    ("horizontal", "dd", 5.0): [(1000, 90.0), (5000, 50.0), (10000, 25.0)],
}
# Levels the text states as "about" / "more than" / "not below": {(kind, target, g): %}
PAPER_LEVELS = {
    ("horizontal", "ad", 5.0): 95.0,
    ("horizontal", "ad", 50.0): 99.0,
    ("horizontal", "ad", 500.0): 99.0,
    ("circular", "ad", 5.0): 97.0,
    ("circular", "ad", 50.0): 99.0,
    ("circular", "ad", 500.0): 99.0,
    ("vertical", "dd", 5.0): 70.0,
    ("vertical", "dd", 50.0): 70.0,
    ("vertical", "dd", 500.0): 70.0,
}
PAPER_TEXT_SUMMARY = [
    "Figure 15a (horizontal, AD): about 99 % for g = 50 and 500, more than 95 % for g = 5.",
    "Figure 15b (horizontal, DD): from 98 % to 74 % (g = 500), 94 % to 71 % (g = 50) and "
    "90 % to 50 % (g = 5) as r grows from 1000 to 5000; 38 %, 36 %, 25 % at r = 10000.",
    "Figure 16 (circular, AD): more than 99 % for g = 50 and 500, more than 97 % for g = 5.",
    "Figure 17 (vertical, DD): not below 70 % anywhere in (1000, 10000).",
]


@dataclass
class Point:
    kind: str
    g: float
    r: float  # trajectory distance (horizontal, circular) or segment centre (vertical)
    estimator: str
    n: int
    n_valid: int
    ad_accuracy: float
    dd_accuracy: float
    n_flagged: int = 0  # limit only: rows whose key the prior cannot produce (triangulated)


def trajectory_points(kind: str, g: float, lo: int, hi: int):
    """[(r, x, y)] for one kind and g: the features Section 6 places on each trajectory."""
    from eyeviz.model import trajectories as T

    out = []
    if kind == "vertical":
        n = T.paper_count("vertical", g, lo=lo * 9, hi=hi * 9)
        x, y = T.vertical(g, n, 1000.0, 10000.0)
        seg = np.clip(np.floor(y / 1000.0), 1, 9)
        for s in range(1, 10):
            sel = seg == s
            if sel.any():
                out.append((1000.0 * s + 500.0, x[sel], y[sel]))
        return out
    fn = T.horizontal if kind == "horizontal" else T.circular
    for r in DISTANCES:
        n = T.paper_count(kind, g, r, lo=lo, hi=hi)
        x, y = fn(r, g, n)
        out.append((r, x, y))
    return out


def _accuracy(truth: np.ndarray, pred: np.ndarray) -> float:
    ok = np.isfinite(pred)
    if not ok.any():
        return math.nan
    return 100.0 - 100.0 * float(np.mean(np.abs((pred[ok] - truth[ok]) / truth[ok])))


def measure(
    names: list[str], lo: int = 30, hi: int = 2000, kinds=KINDS, g_values=G_VALUES, progress=None
) -> tuple[list[Point], dict[str, str]]:
    """Accuracy per (kind, g, r, estimator); also {name: reason} of unavailable estimators."""
    from eyeviz.core.geometry import EyePair, intervals_to_bitmap

    eyes = EyePair(paper.H, paper.L, paper.M)
    loaded, missing = {}, {}
    for name in names:
        if name == "limit":
            from eyeviz.estimators import load
            from eyeviz.estimators.base import Domain

            loaded[name] = load("limit", domain=Domain.from_dict(LIMIT_DOMAIN_KW), prior="single")
            continue
        est, why = try_load(name)
        if est is None:
            missing[name] = why
        else:
            loaded[name] = est
    points: list[Point] = []
    for kind in kinds:
        for g in g_values:
            for r, x, y in trajectory_points(kind, g, lo, hi):
                LA, RA, LB, RB = eyes.intervals(x, y, g)
                oa = intervals_to_bitmap(LA, RA, paper.M, paper.M // 2)
                ob = intervals_to_bitmap(LB, RB, paper.M, paper.M // 2)
                r_true, phi_true = np.hypot(x, y), np.arctan2(y, x)
                for name, est in loaded.items():
                    pred = est.predict(oa, ob)
                    r_hat, phi_hat = (np.asarray(v, np.float64) for v in pred)
                    flagged = getattr(est, "last_flagged", None)
                    n_flagged = int(np.sum(flagged)) if flagged is not None else 0
                    points.append(
                        Point(
                            kind,
                            g,
                            r,
                            name,
                            int(len(x)),
                            int(np.isfinite(r_hat).sum()),
                            _accuracy(phi_true, phi_hat),
                            _accuracy(r_true, r_hat),
                            n_flagged,
                        )
                    )
            if progress is not None:
                progress(f"{kind} g={g:g}")
    return points, missing
