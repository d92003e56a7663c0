"""Figure export (PNG, true-vector SVG/PDF): stable public path ``eyeviz.export``.

The implementation lives in :mod:`eyeviz.render.mpl.export`;
this module only re-exports its public names.
"""

from eyeviz.render.mpl.export import *  # noqa: F403
from eyeviz.render.mpl.export import __all__ as __all__
