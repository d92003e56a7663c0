"""Add an estimator to eyeviz: subclass Estimator, register an entry, run the check battery.

Run it: ``python examples/add_an_estimator.py``. It registers ``edges``, a tiny estimator
that triangulates the rays through the centres of the two eyes' *first* lit sectors
(L_A and L_B, Prop. 2: each holds a tangent, not the centre) instead of the interval
mid-angles the analytic estimator uses, so it is cruder on purpose; it checks it with
:func:`eyeviz.estimators.checks.check_estimator`, and compares both on 2000 elements of Algorithm 1.
"""

from __future__ import annotations

import math

import numpy as np

from eyeviz import dataset, estimators
from eyeviz.estimators import metrics, registry
from eyeviz.estimators.base import PAPER_DOMAIN, Domain, Estimator, triangulate
from eyeviz.estimators.checks import check_estimator


class EdgeEstimator(Estimator):
    """Rays through the centres of the first lit sectors L_A and L_B (nearest centres)."""

    name = "edges"

    def _predict_intervals(self, LA, RA, LB, RB):
        gamma = 2 * math.pi / self.domain.m
        theta_a = (LA + 0.5) * gamma  # the sector holding eye A's first tangent
        theta_b = (LB + 0.5) * gamma
        return triangulate(theta_a, theta_b, self.domain.h, 0.25 * gamma)


def load(domain: Domain = PAPER_DOMAIN) -> EdgeEstimator:
    return EdgeEstimator(domain, {"n_weights": 0})


def main() -> None:
    registry.register(
        registry.Entry(
            "edges",
            "triangulation through the first lit sectors (an example plug-in)",
            load,
            any_design=True,
            design=None,
        ),
        replace=True,
    )
    try:
        assert "edges" in estimators.available()
        est = estimators.load("edges")
        passed = check_estimator(est)
        print(f"edges passed {len(passed)} checks: {', '.join(passed)}")
        ds = dataset.generate(2000, seed=1)
        for name in ("edges", "analytic"):
            p = estimators.load(name).predict(ds.omega_a, ds.omega_b)
            ok = np.asarray(p.valid)
            s = metrics.summary(ds.r[ok], p.r[ok])
            print(f"{name:9s} DD MAPE {s['mape']:.2f} % on {int(ok.sum())} rows")
    finally:
        registry.unregister("edges")


if __name__ == "__main__":
    main()
