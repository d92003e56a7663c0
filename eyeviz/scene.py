"""Scene files (TOML) and the scene model: stable public path ``eyeviz.scene``.

The implementation lives in :mod:`eyeviz.model.scene`;
this module only re-exports its public names.
"""

from eyeviz.model.scene import *  # noqa: F403
from eyeviz.model.scene import __all__ as __all__
