"""The paper's numbers, written here and nowhere else (issue 37).

The eye design of Table 3 (h = 40, l = 20, m = 720 ommatidia per eye) and the object
ranges of Table 4 (r in [1000, 5000], g up to 500). The HEALPix eyes at the paper's
resolution have m = 4 nside facets on the equator, so nside = 180. Everything that
defaults to "the paper's eyes" reads these names (``eyeviz.core.domain.DEFAULTS``, the
eye pairs, the scene's eyes, the commands, the reports); ``tests/test_guardrails.py``
fails on the design written out anywhere else in code.
"""

from __future__ import annotations

__all__ = ["H", "L", "M", "NSIDE", "R_MIN", "R_MAX", "G_MAX"]

H = 40.0  #: distance from the origin to each eye centre (Table 3)
L = 20.0  #: eye radius (Table 3)
M = 720  #: ommatidia per eye (Table 3)
NSIDE = M // 4  #: the HEALPix eyes with the paper's m on the equator: 180
R_MIN = 1000.0  #: the nearest feature distance of Table 4
R_MAX = 5000.0  #: the farthest feature distance of Table 4
G_MAX = 500.0  #: the largest feature radius of Algorithm 1 (Table 4)
