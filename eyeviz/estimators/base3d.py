"""The spherical side's estimator base, now one module with the planar one.

:class:`Estimator3D` and :class:`Prediction3D` live in :mod:`eyeviz.estimators.base` (one
base for every eye model), the CSR input in :mod:`eyeviz.estimators.lit_csr`. This path
stays because docs written before the merge, and plug-ins following them, subclass
``eyeviz.estimators.base3d.Estimator3D``; new code imports :mod:`eyeviz.estimators.base`.
"""

from eyeviz.estimators.base import Estimator3D, LitCSR, Prediction3D, as_csr, take_rows

__all__ = ["Estimator3D", "LitCSR", "Prediction3D", "as_csr", "take_rows"]
