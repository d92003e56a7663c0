"""Estimators of distance r and azimuth phi from the two bitmaps (docs/contract.md).

>>> from eyeviz import dataset, estimators
>>> estimators.available()
['analytic', 'bayes', 'compact', 'limit', 'paper']
>>> ds = dataset.generate(200, seed=1)              # Algorithm 1, the paper's design
>>> est = estimators.load("analytic")
>>> r, phi = est.predict(ds.omega_a, ds.omega_b)    # Omega bitmaps, (N, m/2) each
>>> r.shape
(200,)

Every estimator is an entry of :mod:`eyeviz.estimators.registry` (name, help, design,
load, fit, command-line options); its module is imported only when loaded: importing
this package and calling :func:`available` does not import torch. :mod:`.checks` holds
the battery every estimator passes (:func:`check_estimator`).
"""

from __future__ import annotations

from eyeviz.core.domain import PAPER_DOMAIN, Domain
from eyeviz.estimators import registry
from eyeviz.estimators.base import Estimator, Prediction

__all__ = [
    "available",
    "load",
    "fit",
    "registry",
    "Estimator",
    "Prediction",
    "Domain",
    "PAPER_DOMAIN",
]


def available() -> list[str]:
    """Names accepted by :func:`load` (the installed registry entries)."""
    return registry.available()


def load(name: str, **kw) -> Estimator:
    """The estimator called ``name``; ValueError (EyevizError) for an unknown name or
    missing weights, naming the command that makes them.

    Keyword arguments go to the estimator's ``load`` (for instance ``domain=``, or
    ``path=`` for a weights file or directory).
    """
    return registry.load(name, **kw)


def fit(name: str, data=None, out_dir=None, **options):
    """Train estimator ``name`` into ``out_dir`` (default the user models directory);
    returns the path to give ``load(name, path=...)``."""
    return registry.fit(name, data, out_dir, **options)
