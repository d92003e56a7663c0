"""Estimators of distance r and azimuth phi from the two bitmaps (DESIGN.md §3).

>>> from eyeviz import estimators
>>> estimators.available()
['analytic', 'bayes', 'compact', 'limit', 'paper']
>>> est = estimators.load("analytic")
>>> r, phi = est.predict(omega_a, omega_b)

Each estimator lives in ``eyeviz.estimators.<name>`` with a ``load(**kw)`` function and
is imported only when loaded: importing this package and calling :func:`available`
does not import torch.
"""

from __future__ import annotations

import importlib

from eyeviz.estimators.base import PAPER_DOMAIN, Domain, Estimator, Prediction

__all__ = ["available", "load", "Estimator", "Prediction", "Domain", "PAPER_DOMAIN"]

_NAMES = ("analytic", "bayes", "compact", "limit", "paper")


def available() -> list[str]:
    """Names accepted by :func:`load`."""
    return list(_NAMES)


def load(name: str, **kw) -> Estimator:
    """The estimator called ``name``; ValueError for an unknown name or missing weights.

    Keyword arguments go to the estimator's module-level ``load`` (for instance
    ``domain=``, or ``path=`` for a weights file).
    """
    if name not in _NAMES:
        raise ValueError(f"unknown estimator {name!r}; available: {', '.join(_NAMES)}")
    module = importlib.import_module(f"eyeviz.estimators.{name}")
    return module.load(**kw)
