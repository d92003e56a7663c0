"""The spherical side's domain, now one module with the planar one.

:class:`Domain3D` and its helpers live in :mod:`eyeviz.core.domain` (one record for every
eye model). This path stays because README.md, docs/spherical.md and users' scripts write
``from eyeviz.core.domain3d import Domain3D`` (docs/contract.md); new code imports
:mod:`eyeviz.core.domain`.
"""

from eyeviz.core.domain import (
    DEFAULT_EL_MAX,
    DEFAULTS3D,
    FIELDS3D,
    MEASURED_EL_MAX,
    PAPER_DOMAIN3D,
    Domain3D,
    facet_spacing,
    measured_ranges,
    pair_spacing,
)

__all__ = [
    "DEFAULTS3D",
    "DEFAULT_EL_MAX",
    "Domain3D",
    "FIELDS3D",
    "MEASURED_EL_MAX",
    "PAPER_DOMAIN3D",
    "facet_spacing",
    "measured_ranges",
    "pair_spacing",
]
