"""The spherical eyes (docs/spherical.md): stable public path ``eyeviz.geometry3d``.

The implementation lives in :mod:`eyeviz.core.geometry3d`;
this module only re-exports its public names.
"""

from eyeviz.core.geometry3d import *  # noqa: F403
from eyeviz.core.geometry3d import __all__ as __all__
