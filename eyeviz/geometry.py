"""The geometry core (Propositions 1-5): stable public path ``eyeviz.geometry``.

The implementation lives in :mod:`eyeviz.core.geometry`;
this module only re-exports its public names.
"""

from eyeviz.core.geometry import *  # noqa: F403
from eyeviz.core.geometry import __all__ as __all__
