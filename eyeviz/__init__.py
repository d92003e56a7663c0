"""eyeviz: visualiser and toolkit for binocular compound-eye vision.

The model is the paper's, "Building 2D Model of Compound Eye Vision for Machine Learning"
(``docs/model.md`` summarises it): two circular eyes of m ommatidia each, centred at
A = (-h, 0) and B = (h, 0), looking at circular features in the plane; and its spherical
generalisation (``docs/spherical.md``).
"""

__version__ = "0.1.0"


class EyevizError(ValueError):
    """A user-facing error: its message is one line that names the problem."""
