"""eyeviz: visualiser and toolkit for the planar binocular compound-eye model.

The model is the paper's (``shared/paper.md``): two circular eyes of m ommatidia each,
centred at A = (-h, 0) and B = (h, 0), looking at circular features in the plane.
"""

__version__ = "0.1.0"


class EyevizError(ValueError):
    """A user-facing error: its message is one line that names the problem."""
