"""Centres that give the same bitmaps: stable public path ``eyeviz.ambiguity``.

The implementation lives in :mod:`eyeviz.core.ambiguity`;
this module only re-exports its public names.
"""

from eyeviz.core.ambiguity import *  # noqa: F403
from eyeviz.core.ambiguity import __all__ as __all__
